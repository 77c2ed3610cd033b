/* triangle.h — owns the watertight ray–triangle test of Woop, Benthin and Wald (JCGT
 * 2013): per-ray shear constants, then edge functions in the sheared frame, falling back
 * to double precision when an edge function is exactly zero. */
#ifndef VALO_TRIANGLE_H
#define VALO_TRIANGLE_H
#include "core/vec.h"

typedef struct ray_shear { int kx, ky, kz; float sx, sy, sz; vec3 o; } ray_shear;

static inline ray_shear ray_shear_make(vec3 o, vec3 d) {
  ray_shear s;
  vec3 a = v3_abs(d);
  int kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
  int kx = kz + 1 == 3 ? 0 : kz + 1, ky = kx + 1 == 3 ? 0 : kx + 1;
  if (v3_get(d, kz) < 0) { int t = kx; kx = ky; ky = t; }
  s.kx = kx; s.ky = ky; s.kz = kz;
  float dz = v3_get(d, kz);
  s.sx = v3_get(d, kx) / dz;
  s.sy = v3_get(d, ky) / dz;
  s.sz = 1.0f / dz;
  s.o = o;
  return s;
}

/* fmaxf is a libm call (NaN rules); these inputs are finite, so plain compares do. */
static inline float max3_abs(float a, float b, float c) {
  a = fabsf(a); b = fabsf(b); c = fabsf(c);
  float m = a > b ? a : b;
  return m > c ? m : c;
}

/* For hits the float test cannot tell from t <= 0: t and its error bound again in double
 * precision. With large triangles (a ground plane of 10^4 units) float's bound on t
 * reaches 10^-2, so a wall 0.03 away from a point near it was missed (test_kdtree
 * large_triangles_corner); in double the bound is 2^29 times smaller. Whether the ray
 * passes inside stays the float test's decision (redeciding it in double could drop a
 * hit on a shared edge from both triangles: no longer watertight). Returns 1 and sets *t
 * when 0 < t < tmax holds conservatively. */
static inline double tri_gamma_d(int n) { return n * 0x1p-53 / (1 - n * 0x1p-53); }
static inline double max3_abs_d(double a, double b, double c) {
  a = fabs(a); b = fabs(b); c = fabs(c);
  double m = a > b ? a : b;
  return m > c ? m : c;
}
static inline int tri_t_double(const ray_shear *s, const float *v, float tmax, float *t_out) {
  const float *p0 = v, *p1 = v + 3, *p2 = v + 6;
  double o[3] = {s->o.x, s->o.y, s->o.z}, sx = s->sx, sy = s->sy, sz = s->sz;
  double ax = p0[s->kx] - o[s->kx], ay = p0[s->ky] - o[s->ky], az = p0[s->kz] - o[s->kz];
  double bx = p1[s->kx] - o[s->kx], by = p1[s->ky] - o[s->ky], bz = p1[s->kz] - o[s->kz];
  double cx = p2[s->kx] - o[s->kx], cy = p2[s->ky] - o[s->ky], cz = p2[s->kz] - o[s->kz];
  ax -= sx * az; ay -= sy * az;
  bx -= sx * bz; by -= sy * bz;
  cx -= sx * cz; cy -= sy * cz;
  double u = cx * by - cy * bx, w1 = ax * cy - ay * cx, w = bx * ay - by * ax;
  double det = u + w1 + w;
  if (det == 0) return 0;
  az *= sz; bz *= sz; cz *= sz;
  double inv = 1.0 / det, t = (u * az + w1 * bz + w * cz) * inv;
  double max_z = max3_abs_d(az, bz, cz), max_x = max3_abs_d(ax, bx, cx), max_y = max3_abs_d(ay, by, cy);
  double dz = tri_gamma_d(3) * max_z, dx = tri_gamma_d(5) * (max_x + max_z), dy = tri_gamma_d(5) * (max_y + max_z);
  double de = 2 * (tri_gamma_d(2) * max_x * max_y + dy * max_x + dx * max_y);
  double max_e = max3_abs_d(u, w1, w);
  double dt = 3 * (tri_gamma_d(3) * max_e * max_z + de * max_z + dz * max_e) * fabs(inv);
  float tf = (float)t;
  if (!(t > dt) || !(tf > 0) || !(tf < tmax)) return 0;
  *t_out = tf;
  return 1;
}

/* The bound on the float t's error (pbrt-v3 §3.9.6) from the sheared vertices (z scaled),
 * the edge functions and 1/det. */
static inline float tri_t_bound(float ax, float ay, float az, float bx, float by, float bz, float cx, float cy, float cz, float u, float w1,
                                float w, float inv) {
  float max_z = max3_abs(az, bz, cz), max_x = max3_abs(ax, bx, cx), max_y = max3_abs(ay, by, cy);
  float dz = fp_gamma(3) * max_z, dx = fp_gamma(5) * (max_x + max_z), dy = fp_gamma(5) * (max_y + max_z);
  float de = 2 * (fp_gamma(2) * max_x * max_y + dy * max_x + dx * max_y);
  float max_e = max3_abs(u, w1, w);
  return 3 * (fp_gamma(3) * max_e * max_z + de * max_z + dz * max_e) * fabsf(inv);
}
/* The conservative t > 0 of pbrt-v3 §3.9.6 (hits within t's rounding error of 0 would
 * re-hit the surface a ray leaves), given the sheared vertices, edge functions and
 * 1/det: returns 0 when t is certainly <= 0; when float cannot tell, t is recomputed in
 * double (tri_t_double). *t is then a function of the ray and the triangle alone, not of
 * the closest hit so far, so the nearest hit does not depend on the order triangles are
 * tested in (kd-tree leaves and brute force agree exactly). */
static inline int tri_resolve_t(const ray_shear *s, const float *v, float ax, float ay, float az, float bx, float by, float bz, float cx,
                                float cy, float cz, float u, float w1, float w, float inv, float *t) {
  float dt = tri_t_bound(ax, ay, az, bx, by, bz, cx, cy, cz, u, w1, w, inv);
  if (*t > dt) return 1;
  if (*t < -dt) return 0;
  return tri_t_double(s, v, INFINITY, t);
}

/* The triangle (v0,v1,v2) in the ray's sheared frame: vertices relative to the origin,
 * sheared (x, y; z not yet scaled), and the edge functions u, w1, w (in double when one
 * is exactly zero in float). */
typedef struct tri_sheared { float ax, ay, az, bx, by, bz, cx, cy, cz, u, w1, w; } tri_sheared;
static inline tri_sheared tri_shear(const ray_shear *s, const float *v) {
  const float *p0 = v, *p1 = v + 3, *p2 = v + 6;
  float o[3] = {s->o.x, s->o.y, s->o.z};
  tri_sheared q;
  float ax = p0[s->kx] - o[s->kx], ay = p0[s->ky] - o[s->ky], az = p0[s->kz] - o[s->kz];
  float bx = p1[s->kx] - o[s->kx], by = p1[s->ky] - o[s->ky], bz = p1[s->kz] - o[s->kz];
  float cx = p2[s->kx] - o[s->kx], cy = p2[s->ky] - o[s->ky], cz = p2[s->kz] - o[s->kz];
  ax -= s->sx * az; ay -= s->sy * az;
  bx -= s->sx * bz; by -= s->sy * bz;
  cx -= s->sx * cz; cy -= s->sy * cz;
  float u = cx * by - cy * bx, w1 = ax * cy - ay * cx, w = bx * ay - by * ax;
  if (u == 0 || w1 == 0 || w == 0) {
    u = (float)((double)cx * by - (double)cy * bx);
    w1 = (float)((double)ax * cy - (double)ay * cx);
    w = (float)((double)bx * ay - (double)by * ax);
  }
  q.ax = ax; q.ay = ay; q.az = az; q.bx = bx; q.by = by; q.bz = bz; q.cx = cx; q.cy = cy; q.cz = cz; q.u = u; q.w1 = w1; q.w = w;
  return q;
}

/* The bound on the error of the t that tri_intersect computes for this ray and triangle
 * (infinite when the ray lies in its plane). A ray within a few 10^-6 rad of a
 * triangle's plane gets a t that may be off by more than the triangle is long, so two
 * triangles' order along such a ray is decided by rounding (test_kdtree). */
static inline float tri_t_error(const ray_shear *s, const float *v) {
  tri_sheared q = tri_shear(s, v);
  float det = q.u + q.w1 + q.w;
  if (det == 0) return INFINITY;
  return tri_t_bound(q.ax, q.ay, q.az * s->sz, q.bx, q.by, q.bz * s->sz, q.cx, q.cy, q.cz * s->sz, q.u, q.w1, q.w, 1.0f / det);
}

/* Returns 1 if the ray hits (v0,v1,v2) at 0 < t < tmax; fills t and weights of v1, v2. */
static inline int tri_intersect(const ray_shear *s, const float *v, float tmax, float *t_out, float *b1_out, float *b2_out) {
  tri_sheared q = tri_shear(s, v);
  float ax = q.ax, ay = q.ay, az = q.az, bx = q.bx, by = q.by, bz = q.bz, cx = q.cx, cy = q.cy, cz = q.cz, u = q.u, w1 = q.w1, w = q.w;
  if ((u < 0 || w1 < 0 || w < 0) && (u > 0 || w1 > 0 || w > 0)) return 0;
  float det = u + w1 + w;
  if (det == 0) return 0;
  az *= s->sz; bz *= s->sz; cz *= s->sz;
  float T = u * az + w1 * bz + w * cz;
  float inv = 1.0f / det;
  float t = T * inv;
  if (!tri_resolve_t(s, v, ax, ay, az, bx, by, bz, cx, cy, cz, u, w1, w, inv, &t) || !(t < tmax)) return 0;
  *t_out = t;
  *b1_out = w1 * inv;
  *b2_out = w * inv;
  return 1;
}
#endif
