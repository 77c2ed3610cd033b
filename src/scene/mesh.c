/* mesh.c — owns appending a triangle mesh, given in a file's own arrays, to the scene:
 * placed by a transform (normals by its normal matrix, the winding kept facing the same
 * way under a mirroring one), non-finite data refused, degenerate triangles skipped.
 * Where a file gives no normals they may be computed from the faces (Mitsuba's rule);
 * vertex colours are kept when a file gives them.
 * Every mesh loader (Assimp's formats, Mitsuba's serialized meshes) comes through here. */
#include "scene/scene.h"
#include "core/error.h"
#include "core/mat34.h"
#include <stdlib.h>

/* The angle between unit vectors a and b (stable near 0 and pi). */
static float unit_angle(vec3 a, vec3 b) { return 2 * atan2f(v3_len(v3_sub(a, b)), v3_len(v3_add(a, b))); }

/* Vertex normals for a mesh whose file gives none: at each vertex the mean of its faces'
 * unit normals, each weighted by the face's angle there (Thuermer and Wuethrich 1998, as
 * Mitsuba does), over the vertices its faces share; from the placed (and, under a
 * mirroring transform, rewound) triangles, so they face as the triangles do. */
static void smooth_normals(scene *s, const mesh_data *m, uint32_t base, int flip) {
  for (uint32_t f = 0; f < m->ntris; f++) {
    uint32_t i[3] = {m->idx[3 * (size_t)f], m->idx[3 * (size_t)f + 1], m->idx[3 * (size_t)f + 2]};
    if (i[0] >= m->nverts || i[1] >= m->nverts || i[2] >= m->nverts) continue; /* refused below */
    if (flip) { uint32_t t = i[1]; i[1] = i[2]; i[2] = t; }
    vec3 p[3] = {s->pos[base + i[0]], s->pos[base + i[1]], s->pos[base + i[2]]};
    vec3 n = v3_cross(v3_sub(p[1], p[0]), v3_sub(p[2], p[0]));
    float l2 = v3_len2(n);
    if (!(l2 > 0) || !isfinite(l2)) continue;
    n = v3_scale(n, 1 / sqrtf(l2));
    for (int k = 0; k < 3; k++) {
      vec3 a = v3_sub(p[(k + 1) % 3], p[k]), b = v3_sub(p[(k + 2) % 3], p[k]);
      float la = v3_len(a), lb = v3_len(b);
      if (!(la > 0) || !(lb > 0)) continue;
      float w = unit_angle(v3_scale(a, 1 / la), v3_scale(b, 1 / lb));
      s->nrm[base + i[k]] = v3_add(s->nrm[base + i[k]], v3_scale(n, w));
    }
  }
  for (uint32_t v = 0; v < m->nverts; v++) {
    vec3 n = s->nrm[base + v];
    float l2 = v3_len2(n);
    s->nrm[base + v] = l2 > 0 && isfinite(l2) ? v3_scale(n, 1 / sqrtf(l2)) : v3(0, 0, 0);
  }
}

valo_status scene_add_mesh(scene *s, const mesh_data *m, const float *xf12, uint32_t mat, uint64_t *added, uint64_t *degenerate,
                           valo_error *err) {
  if (scene_reserve(s, m->nverts, m->ntris)) return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", m->where);
  mat34 xf = m34_from(xf12), nm = m34_normal_matrix(&xf);
  int flip = m34_det(&xf) < 0;
  /* Normals go by the inverse transpose: the cofactor matrix over the determinant, whose
   * sign matters (a mirroring transform would otherwise turn them against the faces). */
  for (int i = 0; flip && i < 3; i++)
    for (int j = 0; j < 3; j++) nm.m[i][j] = -nm.m[i][j];
  uint32_t base = s->nverts;
  if (m->col && !s->col) { /* the first file with colours: every vertex so far white */
    if (!(s->col = malloc((size_t)s->cap_verts * 3 * sizeof(float)))) return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", m->where);
    for (size_t i = 0; i < 3 * (size_t)s->cap_verts; i++) s->col[i] = 1;
  }
  for (uint32_t v = 0; v < m->nverts; v++) {
    const float *p = &m->pos[3 * (size_t)v];
    vec3 pv = v3(p[0], p[1], p[2]);
    if (!v3_finite(pv))
      return err_set(err, VALO_ERR_INVALID, "%s vertex %u is not finite (%g %g %g)", m->where, v, (double)p[0], (double)p[1], (double)p[2]);
    pv = m34_point(&xf, pv);
    if (!v3_finite(pv)) return err_set(err, VALO_ERR_INVALID, "%s vertex %u is not finite after the transform", m->where, v);
    s->pos[base + v] = pv;
    vec3 n = v3(0, 0, 0);
    if (m->nrm) {
      const float *q = &m->nrm[3 * (size_t)v];
      n = v3(q[0], q[1], q[2]);
      n = v3_finite(n) ? v3_norm(m34_vector(&nm, n)) : v3(0, 0, 0);
      if (!v3_finite(n)) n = v3(0, 0, 0);
    }
    s->nrm[base + v] = n;
    if (s->tan_file) memset(&s->tan_file[4 * (size_t)(base + v)], 0, 4 * sizeof(float));
    for (int k = 0; s->col && k < 3; k++) { /* a colour the file gave (below 0 read as 0), else white */
      float x = m->col ? m->col[(size_t)m->col_stride * v + k] : 1;
      if (!isfinite(x)) return err_set(err, VALO_ERR_INVALID, "%s vertex %u has a colour that is not finite", m->where, v);
      s->col[3 * (size_t)(base + v) + k] = fmaxf(x, 0);
    }
    float u = 0, w = 0;
    if (m->uv) { u = m->uv[(size_t)m->uv_stride * v]; w = m->uv[(size_t)m->uv_stride * v + 1]; }
    s->uv[2 * (base + v)] = isfinite(u) ? u : 0;
    s->uv[2 * (base + v) + 1] = isfinite(w) ? w : 0;
  }
  s->nverts += m->nverts;
  int computed = !m->nrm && m->smooth && !m->flat;
  if (computed) smooth_normals(s, m, base, flip);
  if (!m->uv && material_has_maps(&s->mats[mat]))
    log_warning("%s has no texture coordinates, so the maps of its material '%s' are ignored", m->where, s->mats[mat].name);
  for (uint32_t f = 0; f < m->ntris; f++) {
    uint32_t i0 = m->idx[3 * (size_t)f], i1 = m->idx[3 * (size_t)f + 1], i2 = m->idx[3 * (size_t)f + 2];
    if (i0 >= m->nverts || i1 >= m->nverts || i2 >= m->nverts)
      return err_set(err, VALO_ERR_INVALID, "%s triangle %u has a vertex index out of range (%u vertices)", m->where, f, m->nverts);
    if (flip) { uint32_t t = i1; i1 = i2; i2 = t; }
    uint32_t ti = s->ntris;
    s->idx[3 * ti] = base + i0; s->idx[3 * ti + 1] = base + i1; s->idx[3 * ti + 2] = base + i2;
    vec3 ng = scene_tri_ng(s, ti);
    float a2 = v3_len2(ng);
    if (!(a2 > 0) || !isfinite(a2)) { (*degenerate)++; continue; }
    uint8_t fl = 0;
    if ((m->nrm || computed) && !m->flat && v3_len2(s->nrm[base + i0]) > 0 && v3_len2(s->nrm[base + i1]) > 0 && v3_len2(s->nrm[base + i2]) > 0)
      fl |= TRI_HAS_NORMALS;
    if (m->uv) fl |= TRI_HAS_UVS;
    s->tri_mat[ti] = mat;
    s->tri_flags[ti] = fl;
    s->ntris++;
    (*added)++;
  }
  return VALO_OK;
}
