/* mat34.h — owns the 3x4 affine transform (row-major, the last column the translation)
 * that places meshes: products, points, vectors, the determinant and the normal matrix. */
#ifndef VALO_MAT34_H
#define VALO_MAT34_H
#include "core/vec.h"

typedef struct mat34 { float m[3][4]; } mat34;

static inline mat34 m34_identity(void) {
  mat34 r = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
  return r;
}
/* The transform of 12 floats xf (row-major), or the identity when xf is NULL. */
static inline mat34 m34_from(const float *xf) {
  mat34 r = m34_identity();
  if (xf) memcpy(r.m, xf, sizeof r.m);
  return r;
}
static inline mat34 m34_mul(const mat34 *a, const mat34 *b) {
  mat34 r;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 4; j++) {
      float v = a->m[i][0] * b->m[0][j] + a->m[i][1] * b->m[1][j] + a->m[i][2] * b->m[2][j];
      if (j == 3) v += a->m[i][3];
      r.m[i][j] = v;
    }
  return r;
}
static inline vec3 m34_point(const mat34 *a, vec3 p) {
  return v3(a->m[0][0] * p.x + a->m[0][1] * p.y + a->m[0][2] * p.z + a->m[0][3],
            a->m[1][0] * p.x + a->m[1][1] * p.y + a->m[1][2] * p.z + a->m[1][3],
            a->m[2][0] * p.x + a->m[2][1] * p.y + a->m[2][2] * p.z + a->m[2][3]);
}
static inline vec3 m34_vector(const mat34 *a, vec3 p) {
  return v3(a->m[0][0] * p.x + a->m[0][1] * p.y + a->m[0][2] * p.z, a->m[1][0] * p.x + a->m[1][1] * p.y + a->m[1][2] * p.z,
            a->m[2][0] * p.x + a->m[2][1] * p.y + a->m[2][2] * p.z);
}
static inline float m34_det(const mat34 *a) {
  const float(*m)[4] = a->m;
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}
/* Cofactor matrix = det * inverse transpose: transforms normals (normalised after). */
static inline mat34 m34_normal_matrix(const mat34 *a) {
  const float(*m)[4] = a->m;
  mat34 r = m34_identity();
  r.m[0][0] = m[1][1] * m[2][2] - m[1][2] * m[2][1];
  r.m[0][1] = m[1][2] * m[2][0] - m[1][0] * m[2][2];
  r.m[0][2] = m[1][0] * m[2][1] - m[1][1] * m[2][0];
  r.m[1][0] = m[0][2] * m[2][1] - m[0][1] * m[2][2];
  r.m[1][1] = m[0][0] * m[2][2] - m[0][2] * m[2][0];
  r.m[1][2] = m[0][1] * m[2][0] - m[0][0] * m[2][1];
  r.m[2][0] = m[0][1] * m[1][2] - m[0][2] * m[1][1];
  r.m[2][1] = m[0][2] * m[1][0] - m[0][0] * m[1][2];
  r.m[2][2] = m[0][0] * m[1][1] - m[0][1] * m[1][0];
  return r;
}
#endif
