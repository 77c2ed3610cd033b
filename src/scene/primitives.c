/* primitives.c — owns the shapes a scene file describes by kind rather than by mesh:
 * the tessellated sphere and Mitsuba's unit rectangle, cube, disk and cylinder, placed
 * by a 3x4 transform. */
#include "scene/scene.h"
#include "core/error.h"
#include "core/mat34.h"
#include "core/grow.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The equirectangular texture coordinates of the point in unit direction d from a sphere's
 * centre (scene.h, scene_sphere_uv). */
static void sphere_dir_uv(vec3 d, const float *rot, float *u, float *v, int *pole) {
  if (rot) { /* Mitsuba's: its local frame's z the pole, phi from its x towards its y */
    vec3 l = v3(rot[0] * d.x + rot[3] * d.y + rot[6] * d.z, rot[1] * d.x + rot[4] * d.y + rot[7] * d.z,
                rot[2] * d.x + rot[5] * d.y + rot[8] * d.z);
    float phi = atan2f(l.y, l.x);
    *u = (phi < 0 ? phi + 2 * PI_F : phi) / (2 * PI_F);
    *v = 1 - acosf(clampf(l.z, -1, 1)) / PI_F;
    *pole = fabsf(l.z) > 1 - 1e-6f;
  } else { /* valo's: +y the pole, at the image's top */
    *u = 0.5f + atan2f(d.z, d.x) / (2 * PI_F);
    *v = 1 - acosf(clampf(d.y, -1, 1)) / PI_F;
    *pole = fabsf(d.y) > 1 - 1e-6f;
  }
}

void scene_sphere_point_uv(const sphere_shape *sp, vec3 p, float *u, float *v) {
  int pole;
  vec3 d = v3_sub(p, sp->c);
  float l = v3_len(d);
  sphere_dir_uv(l > 0 ? v3_scale(d, 1 / l) : v3(0, 1, 0), sp->mitsuba_uv ? sp->rot : NULL, u, v, &pole);
}

valo_status scene_sphere_uv(scene *s, uint32_t g, const float *rot) {
  if (g >= s->nspheres) return VALO_ERR_INVALID;
  sphere_shape *sp = &s->spheres[g];
  sp->mitsuba_uv = rot != NULL;
  if (rot) memcpy(sp->rot, rot, sizeof sp->rot);
  for (uint32_t t = sp->first; t < sp->end; t++) {
    const uint32_t *ix = &s->idx[3 * (size_t)t];
    float u[3], v[3];
    int pole[3];
    for (int k = 0; k < 3; k++) sphere_dir_uv(v3_norm(v3_sub(s->pos[ix[k]], sp->c)), rot, &u[k], &v[k], &pole[k]);
    /* across the seam: the u's kept together (the map repeats); at a pole, u is the mean
     * of the other two's */
    float lo = fminf(u[0], fminf(u[1], u[2])), hi = fmaxf(u[0], fmaxf(u[1], u[2]));
    for (int k = 0; k < 3 && hi - lo > 0.5f; k++)
      if (u[k] < 0.5f && !pole[k]) u[k] += 1;
    for (int k = 0; k < 3; k++)
      if (pole[k]) u[k] = 0.5f * (u[(k + 1) % 3] + u[(k + 2) % 3]);
    for (int k = 0; k < 3; k++) {
      s->uv[2 * (size_t)ix[k]] = u[k];
      s->uv[2 * (size_t)ix[k] + 1] = v[k];
    }
  }
  return VALO_OK;
}

void scene_sphere_exact_area(scene *s, uint32_t g) {
  sphere_shape *sp = &s->spheres[g];
  double area = 0;
  for (uint32_t t = sp->first; t < sp->end; t++) {
    const uint32_t *ix = &s->idx[3 * t];
    area += 0.5 * v3_len(v3_cross(v3_sub(s->pos[ix[1]], s->pos[ix[0]]), v3_sub(s->pos[ix[2]], s->pos[ix[0]])));
  }
  if (!(area > 0)) return;
  float k = (float)sqrt(4 * M_PI * (double)sp->r * sp->r / area);
  for (uint32_t t = sp->first; t < sp->end; t++)
    for (int j = 0; j < 3; j++) {
      vec3 *p = &s->pos[s->idx[3 * t + j]];
      *p = v3_add(sp->c, v3_scale(v3_sub(*p, sp->c), k));
    }
  sp->r *= k;
}

/* Icosphere: 12 vertices, 20 faces, each subdivision splits a face in four. Vertices
 * are not shared between faces (flat arrays stay simple); normals are exact. */
valo_status scene_add_sphere(scene *s, vec3 c, float r, int subdiv, int flip, int smooth, uint32_t mat, valo_error *err) {
  if (subdiv < 0 || subdiv > 7) return err_set(err, VALO_ERR_INVALID, "%s: sphere subdivisions must be 0..7", s->path);
  if (!(r > 0) || !isfinite(r)) return err_set(err, VALO_ERR_INVALID, "%s: sphere radius must be positive", s->path);
  const float t = (1.0f + sqrtf(5.0f)) / 2.0f;
  vec3 iv[12] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  static const int f[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                               {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                               {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  uint32_t nf = 20u << (2 * subdiv);
  vec3 *tris = malloc((size_t)nf * 3 * sizeof(vec3)), *tmp = malloc((size_t)nf * 3 * sizeof(vec3));
  sphere_shape *sps = grow_for(s->spheres, s->nspheres, sizeof *sps);
  if (sps) s->spheres = sps;
  if (!sps || !tris || !tmp || scene_reserve(s, nf * 3, nf)) { free(tris); free(tmp); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  sphere_shape sp = {c, r, s->ntris, s->ntris + nf, flip, 0, 0, 0, {0}};
  s->spheres[s->nspheres++] = sp;
  for (int i = 0; i < 20; i++)
    for (int k = 0; k < 3; k++) tris[3 * i + k] = v3_norm(iv[f[i][k]]);
  uint32_t n = 20;
  for (int d = 0; d < subdiv; d++) {
    for (uint32_t i = 0; i < n; i++) {
      vec3 a = tris[3 * i], b = tris[3 * i + 1], cc = tris[3 * i + 2];
      vec3 ab = v3_norm(v3_add(a, b)), bc = v3_norm(v3_add(b, cc)), ca = v3_norm(v3_add(cc, a));
      vec3 *o = &tmp[12 * i];
      o[0] = a; o[1] = ab; o[2] = ca; o[3] = ab; o[4] = b; o[5] = bc;
      o[6] = ca; o[7] = bc; o[8] = cc; o[9] = ab; o[10] = bc; o[11] = ca;
    }
    vec3 *sw = tris; tris = tmp; tmp = sw;
    n *= 4;
  }
  for (uint32_t i = 0; i < n; i++) {
    uint32_t base = s->nverts;
    for (int k = 0; k < 3; k++) {
      int kk = flip ? 2 - k : k;
      vec3 u = tris[3 * i + kk];
      s->pos[base + k] = v3_add(c, v3_scale(u, r));
      s->nrm[base + k] = flip ? v3_neg(u) : u;
    }
    s->nverts += 3;
    uint32_t ti = s->ntris++;
    s->idx[3 * ti] = base; s->idx[3 * ti + 1] = base + 1; s->idx[3 * ti + 2] = base + 2;
    s->tri_mat[ti] = mat;
    s->tri_flags[ti] = (uint8_t)((smooth ? TRI_HAS_NORMALS : 0) | TRI_HAS_UVS | TRI_SPHERE);
  }
  free(tris); free(tmp);
  return scene_sphere_uv(s, s->nspheres - 1, NULL);
}


/* Appends flat triangles (no shading normals) over nv vertices with their UVs. */
static valo_status add_flat(scene *s, const vec3 *p, const float *uv, uint32_t nv, const uint32_t *idx, uint32_t nt, const float *xf,
                            int flip, uint32_t mat, valo_error *err) {
  mat34 m = m34_from(xf);
  float det = m34_det(&m);
  if (!(fabsf(det) > 0) || !isfinite(det)) return err_set(err, VALO_ERR_INVALID, "%s: a shape's transform is singular (it flattens the shape)", s->path);
  if (det < 0) flip = !flip; /* a mirroring transform keeps the front side, as for meshes */
  if (scene_reserve(s, nv, nt)) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  uint32_t base = s->nverts;
  for (uint32_t v = 0; v < nv; v++) {
    s->pos[base + v] = m34_point(&m, p[v]);
    if (!v3_finite(s->pos[base + v])) return err_set(err, VALO_ERR_INVALID, "%s: a shape's vertex is not finite after its transform", s->path);
    s->nrm[base + v] = v3(0, 0, 0);
    s->uv[2 * (base + v)] = uv[2 * v];
    s->uv[2 * (base + v) + 1] = uv[2 * v + 1];
  }
  s->nverts += nv;
  for (uint32_t t = 0; t < nt; t++) {
    uint32_t ti = s->ntris++;
    s->idx[3 * ti] = base + idx[3 * t];
    s->idx[3 * ti + 1] = base + idx[3 * t + (flip ? 2 : 1)];
    s->idx[3 * ti + 2] = base + idx[3 * t + (flip ? 1 : 2)];
    s->tri_mat[ti] = mat;
    s->tri_flags[ti] = TRI_HAS_UVS;
  }
  return VALO_OK;
}

#define DISK_SEGMENTS 256

/* Mitsuba's texture coordinates of a point p on the face of its unit cube facing sgn along
 * axis, in valo's convention (v up the image: 1 - Mitsuba's v, whose images run down).
 * Mitsuba lays each face out so: */
static void cube_uv_mitsuba(int axis, float sgn, vec3 p, float *u, float *v) {
  float mv;
  if (axis == 1 && sgn < 0) { *u = (p.z + 1) / 2; mv = (p.x + 1) / 2; }
  else if (axis == 1) { *u = (1 - p.x) / 2; mv = (1 - p.z) / 2; }
  else if (axis == 0 && sgn > 0) { *u = (p.y + 1) / 2; mv = (1 - p.z) / 2; }
  else if (axis == 2 && sgn > 0) { *u = (p.y + 1) / 2; mv = (p.x + 1) / 2; }
  else if (axis == 0) { *u = (p.y + 1) / 2; mv = (p.z + 1) / 2; }
  else { *u = (1 - p.y) / 2; mv = (p.x + 1) / 2; }
  *v = 1 - mv;
}

#define CYLINDER_SEGMENTS 256

/* Mitsuba's cylinder: the tube of radius 1 around z from z = 0 to 1, no caps, facing out;
 * CYLINDER_SEGMENTS facets whose vertex normals point straight out from the axis, so that
 * their interpolation at a hit on a facet is the true cylinder's normal there (the facet's
 * chord and the normals' blend are the same blend of two radii). u = phi / 2 pi from +x
 * towards +y, v = z (Mitsuba's v, turned up to valo's convention, is 1 - z). */
static valo_status add_cylinder(scene *s, const float *xf, int flip, int mitsuba_uv, uint32_t mat, valo_error *err) {
  enum { NV = 2 * (CYLINDER_SEGMENTS + 1), NT = 2 * CYLINDER_SEGMENTS };
  mat34 m = m34_from(xf);
  float det = m34_det(&m);
  if (!(fabsf(det) > 0) || !isfinite(det)) return err_set(err, VALO_ERR_INVALID, "%s: a shape's transform is singular (it flattens the shape)", s->path);
  float lp[3 * NV], ln[3 * NV], luv[2 * NV];
  uint32_t li[3 * NT];
  for (int k = 0; k <= CYLINDER_SEGMENTS; k++) {
    double phi = 2 * M_PI * k / CYLINDER_SEGMENTS;
    float x = k == CYLINDER_SEGMENTS ? 1 : (float)cos(phi), y = k == CYLINDER_SEGMENTS ? 0 : (float)sin(phi);
    for (int z = 0; z < 2; z++) {
      int v = 2 * k + z;
      lp[3 * v] = x; lp[3 * v + 1] = y; lp[3 * v + 2] = (float)z;
      ln[3 * v] = flip ? -x : x; ln[3 * v + 1] = flip ? -y : y; ln[3 * v + 2] = 0;
      luv[2 * v] = (float)k / CYLINDER_SEGMENTS;
      luv[2 * v + 1] = mitsuba_uv ? 1.0f - (float)z : (float)z;
    }
  }
  for (int k = 0; k < CYLINDER_SEGMENTS; k++) { /* counter-clockwise seen from outside (flipped: from inside) */
    uint32_t a = 2u * (uint32_t)k, q[6] = {a, a + 2, a + 3, a, a + 3, a + 1};
    for (int j = 0; j < 6; j++) li[6 * k + j] = q[flip ? 5 - j : j];
  }
  mesh_data md = {s->path, NV, NT, lp, ln, luv, 2, li, 0, 0, NULL, 0};
  uint64_t added = 0, degenerate = 0;
  return scene_add_mesh(s, &md, xf, mat, &added, &degenerate, err);
}

void scene_cylinder_place(vec3 p0, vec3 p1, float r, float xf[12]) {
  vec3 d = v3_sub(p1, p0);
  float len = v3_len(d);
  vec3 n = v3_scale(d, 1 / len);
  /* the frame around n as Mitsuba builds it (Duff et al. 2017), so phi starts where Mitsuba's does */
  float sign = copysignf(1.0f, n.z), a = -1.0f / (sign + n.z), b = n.x * n.y * a;
  vec3 sx = v3(1 + sign * n.x * n.x * a, sign * b, -sign * n.x), ty = v3(b, sign + n.y * n.y * a, -n.y);
  mat34 l = {{{sx.x * r, ty.x * r, n.x * len, p0.x}, {sx.y * r, ty.y * r, n.y * len, p0.y}, {sx.z * r, ty.z * r, n.z * len, p0.z}}};
  mat34 m = m34_from(xf), out = m34_mul(&m, &l);
  memcpy(xf, &out.m[0][0], 12 * sizeof(float));
}

valo_status scene_add_primitive(scene *s, primitive_kind kind, const float *xf, int flip, int mitsuba_uv, uint32_t mat, valo_error *err) {
  if (kind == PRIM_CYLINDER) return add_cylinder(s, xf, flip, mitsuba_uv, mat, err);
  if (kind == PRIM_RECTANGLE) {
    const vec3 p[4] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    const float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1}, uv_mi[8] = {0, 1, 1, 1, 1, 0, 0, 0};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    return add_flat(s, p, mitsuba_uv ? uv_mi : uv, 4, idx, 2, xf, flip, mat, err);
  }
  if (kind == PRIM_CUBE) {
    /* Six faces of four vertices, each wound counter-clockwise seen from outside. */
    vec3 p[24];
    float uv[48];
    uint32_t idx[36];
    for (int f = 0; f < 6; f++) {
      int axis = f >> 1;
      float sgn = (f & 1) ? -1.0f : 1.0f;
      for (int k = 0; k < 4; k++) {
        float a = (k == 1 || k == 2) ? 1.0f : -1.0f, b = (k >= 2) ? 1.0f : -1.0f;
        float c[3];
        /* (a, b) on the two other axes in cyclic order, so (u, v, n) is right-handed;
         * the -n faces swap u to stay counter-clockwise from outside. */
        c[axis] = sgn;
        c[(axis + 1) % 3] = a * sgn;
        c[(axis + 2) % 3] = b;
        p[4 * f + k] = v3(c[0], c[1], c[2]);
        uv[8 * f + 2 * k] = 0.5f * (a + 1);
        uv[8 * f + 2 * k + 1] = 0.5f * (b + 1);
        if (mitsuba_uv) cube_uv_mitsuba(axis, sgn, p[4 * f + k], &uv[8 * f + 2 * k], &uv[8 * f + 2 * k + 1]);
      }
      const uint32_t q[6] = {0, 1, 2, 0, 2, 3};
      for (int k = 0; k < 6; k++) idx[6 * f + k] = 4u * (uint32_t)f + q[k];
    }
    return add_flat(s, p, uv, 24, idx, 12, xf, flip, mat, err);
  }
  if (mitsuba_uv) {
    /* Mitsuba's disk has polar coordinates, (r, phi / 2 pi) with phi from +x towards +y,
     * in valo's convention (r, 1 - phi / 2 pi): each triangle of the fan has its own
     * centre, at its middle angle, and the last one closes at phi = 2 pi. */
    vec3 p[3 * DISK_SEGMENTS];
    float uv[6 * DISK_SEGMENTS];
    uint32_t idx[3 * DISK_SEGMENTS];
    for (int k = 0; k < DISK_SEGMENTS; k++) {
      double f0 = (double)k / DISK_SEGMENTS, f1 = (double)(k + 1) / DISK_SEGMENTS;
      p[3 * k] = v3(0, 0, 0);
      p[3 * k + 1] = v3((float)cos(2 * M_PI * f0), (float)sin(2 * M_PI * f0), 0);
      p[3 * k + 2] = k + 1 < DISK_SEGMENTS ? v3((float)cos(2 * M_PI * f1), (float)sin(2 * M_PI * f1), 0) : p[1];
      const float w[3][2] = {{0, (float)(1 - 0.5 * (f0 + f1))}, {1, (float)(1 - f0)}, {1, (float)(1 - f1)}};
      for (int j = 0; j < 3; j++) {
        uv[6 * k + 2 * j] = w[j][0];
        uv[6 * k + 2 * j + 1] = w[j][1];
        idx[3 * k + j] = 3u * (uint32_t)k + (uint32_t)j;
      }
    }
    return add_flat(s, p, uv, 3 * DISK_SEGMENTS, idx, DISK_SEGMENTS, xf, flip, mat, err);
  }
  /* PRIM_DISK: a fan of DISK_SEGMENTS triangles around the centre (area within 0.01 % of
   * pi); UVs are the unit square's, (x + 1) / 2 and (y + 1) / 2. */
  vec3 p[DISK_SEGMENTS + 1];
  float uv[2 * (DISK_SEGMENTS + 1)];
  uint32_t idx[3 * DISK_SEGMENTS];
  p[0] = v3(0, 0, 0);
  uv[0] = uv[1] = 0.5f;
  for (int k = 0; k < DISK_SEGMENTS; k++) {
    double phi = 2 * M_PI * k / DISK_SEGMENTS;
    p[k + 1] = v3((float)cos(phi), (float)sin(phi), 0);
    uv[2 * (k + 1)] = 0.5f * (p[k + 1].x + 1);
    uv[2 * (k + 1) + 1] = 0.5f * (p[k + 1].y + 1);
    idx[3 * k] = 0;
    idx[3 * k + 1] = (uint32_t)k + 1;
    idx[3 * k + 2] = (uint32_t)(k + 1) % DISK_SEGMENTS + 1;
  }
  return add_flat(s, p, uv, DISK_SEGMENTS + 1, idx, DISK_SEGMENTS, xf, flip, mat, err);
}
