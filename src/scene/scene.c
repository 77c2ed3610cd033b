/* scene.c — owns scene construction: growable arrays, commit (bounds, area lights,
 * automatic camera framing) and conductor presets. */
#include "scene/scene.h"
#include "core/error.h"
#include "core/rng.h"
#include "scene/envmap.h"
#include "scene/volume.h"
#include "image/texture.h"
#include "core/grow.h"
#include <stdlib.h>
#include <string.h>
#include <stdio.h>

scene *scene_new(const char *path) {
  scene *s = calloc(1, sizeof *s);
  if (!s) return NULL;
  s->black = material_default();
  s->black.kd = c3(0, 0, 0);
  snprintf(s->black.name, sizeof s->black.name, "black (a black_back material seen from behind)");
  snprintf(s->path, sizeof s->path, "%s", path ? path : "");
  s->cam_medium = MEDIUM_NONE;
  return s;
}

void scene_free(scene *s) {
  if (!s) return;
  free(s->pos); free(s->nrm); free(s->uv); free(s->tan); free(s->tan_file); free(s->col); free(s->idx); free(s->tri_mat); free(s->tri_flags);
  free(s->mats); free(s->lights); free(s->tri_light); free(s->light_ov0); free(s->light_ov); free(s->shape_ao); free(s->cam_keys); free(s->nk);
  for (uint32_t i = 0; i < s->nmedia; i++) density_grid_free(s->media[i].grid);
  free(s->media); free(s->shape_media); free(s->tri_media); free(s->spheres);
  envmap_destroy(s->env_map);
  for (uint32_t i = 0; i < s->ntex; i++) texture_free(&s->tex[i]);
  free(s->tex);
  free(s);
}

static int grow(void **p, uint32_t *cap, uint64_t need, size_t elem) {
  if (need <= *cap) return 0;
  if (need > 0xFFFFFFF0u) return -1;
  uint64_t nc = *cap ? *cap : 64;
  while (nc < need) nc *= 2;
  if (nc > 0xFFFFFFF0u) nc = 0xFFFFFFF0u;
  void *q = realloc(*p, (size_t)nc * elem);
  if (!q) return -1;
  *p = q;
  *cap = (uint32_t)nc;
  return 0;
}

int scene_reserve(scene *s, uint32_t more_verts, uint32_t more_tris) {
  uint64_t nv = (uint64_t)s->nverts + more_verts, nt = (uint64_t)s->ntris + more_tris;
  if (nv > 0xFFFFFFF0u || nt > 0xFFFFFFF0u) return -1;
  if (nv > s->cap_verts) {
    uint32_t c = s->cap_verts, c2 = s->cap_verts, c3 = s->cap_verts, c4 = s->cap_verts, c5 = s->cap_verts;
    if (grow((void **)&s->pos, &c, nv, sizeof(vec3)) || grow((void **)&s->nrm, &c2, nv, sizeof(vec3)) ||
        grow((void **)&s->uv, &c3, nv, 2 * sizeof(float)) || (s->tan_file && grow((void **)&s->tan_file, &c4, nv, 4 * sizeof(float))) ||
        (s->col && grow((void **)&s->col, &c5, nv, 3 * sizeof(float))))
      return -1;
    if (s->tan_file) memset(s->tan_file + 4 * (size_t)s->cap_verts, 0, (size_t)(c4 - s->cap_verts) * 4 * sizeof(float)); /* none given */
    for (size_t i = 3 * (size_t)s->cap_verts; s->col && i < 3 * (size_t)c5; i++) s->col[i] = 1; /* none given: white */
    s->cap_verts = c;
  }
  if (nt > s->cap_tris) {
    uint32_t c = s->cap_tris, c2 = s->cap_tris, c3 = s->cap_tris;
    if (grow((void **)&s->idx, &c, nt, 3 * sizeof(uint32_t)) || grow((void **)&s->tri_mat, &c2, nt, sizeof(uint32_t)) ||
        grow((void **)&s->tri_flags, &c3, nt, 1))
      return -1;
    s->cap_tris = c;
  }
  return 0;
}

material material_default(void) {
  material m;
  memset(&m, 0, sizeof m);
  m.type = MAT_DIFFUSE;
  m.kd = c3(0.8f, 0.8f, 0.8f);
  m.exponent = 1;
  m.ior = 1.5f;
  m.tex_kd = m.tex_ks = m.tex_ke = m.tex_alpha = m.tex_normal = m.tex_bump = -1;
  m.transmittance = c3(1, 1, 1);
  m.f0 = c3(0.04f, 0.04f, 0.04f);
  m.f90 = 1;
  m.bump_scale = 1;
  m.tint = c3(1, 1, 1);
  m.tex_mr = m.tex_ns = m.tex_rough = m.tex_metal = m.tex_cc = m.tex_ccr = m.tex_sheen = -1;
  m.alpha_cutoff = 0.5f;
  m.opacity = 1;
  m.tex_weight = -1;
  snprintf(m.name, sizeof m.name, "default");
  return m;
}

int scene_add_shape_media(scene *s, uint32_t first, int32_t interior, int32_t exterior) {
  shape_media *q = grow_for(s->shape_media, s->nshape_media, sizeof *q);
  if (!q) return -1;
  s->shape_media = q;
  q[s->nshape_media++] = (shape_media){first, s->ntris, interior, exterior};
  return 0;
}

void material_pbr_specular(material *m, float ior, float factor, rgb color) {
  float r = (ior - 1) / (ior + 1), f0 = ior == 1.5f ? 0.04f : r * r; /* 0.04 exactly at 1.5, as the model's default */
  m->f0 = c3(fminf(f0 * color.r, 1) * factor, fminf(f0 * color.g, 1) * factor, fminf(f0 * color.b, 1) * factor);
  m->f90 = factor;
}

uint32_t scene_add_material(scene *s, const material *m) {
  if (grow((void **)&s->mats, &s->cap_mats, (uint64_t)s->nmats + 1, sizeof *m)) return UINT32_MAX;
  s->mats[s->nmats] = *m;
  return s->nmats++;
}

int scene_add_light(scene *s, const light *l) {
  if (grow((void **)&s->lights, &s->cap_lights, (uint64_t)s->nlights + 1, sizeof *l)) return -1;
  s->lights[s->nlights++] = *l;
  return 0;
}

void scene_area_light(const scene *s, uint32_t t, light *l) {
  memset(l, 0, sizeof *l);
  l->type = LIGHT_AREA;
  l->tri = t;
  const uint32_t *ix = &s->idx[3 * t];
  for (int k = 0; k < 3; k++) l->v[k] = s->pos[ix[k]];
  l->ng = scene_tri_ng(s, t);
  l->n = v3_norm(l->ng);
  l->area = 0.5f * v3_len(l->ng);
  l->centroid = v3_scale(v3_add(v3_add(l->v[0], l->v[1]), l->v[2]), 1.0f / 3);
  l->tex_ke = s->mats[s->tri_mat[t]].tex_ke;
}

static int add_texture(scene *s, texture *t, const char *key) {
  snprintf(t->key, sizeof t->key, "%s", key);
  if (grow((void **)&s->tex, &s->cap_tex, (uint64_t)s->ntex + 1, sizeof *t)) { texture_free(t); return -1; }
  s->tex[s->ntex] = *t;
  return (int)s->ntex++;
}
static int find_texture(const scene *s, const char *key) {
  for (uint32_t i = 0; i < s->ntex; i++)
    if (!strcmp(s->tex[i].key, key)) return (int)i;
  return -1;
}

int scene_texture_file(scene *s, const char *path, int srgb, valo_error *to) {
  char key[600];
  snprintf(key, sizeof key, "%s|%d", path, srgb);
  int i = find_texture(s, key);
  if (i >= 0) return i;
  texture t;
  valo_error err;
  if (texture_load_file(&t, path, srgb, to ? to : &err)) {
    if (to) return -1;
    if (err.status == VALO_ERR_NOMEM && !s->tex_fatal.status) { s->tex_fatal = err; return -1; }
    log_warning("%s%s%s (the map is ignored)", s->tex_user, s->tex_user[0] ? ": " : "", err.message);
    return -1;
  }
  return add_texture(s, &t, key);
}

int scene_texture_memory(scene *s, const char *name, const unsigned char *data, size_t len, int srgb) {
  char key[600];
  snprintf(key, sizeof key, "%s|%d", name, srgb);
  int i = find_texture(s, key);
  if (i >= 0) return i;
  texture t;
  valo_error err;
  if (texture_load_memory(&t, data, len, name, srgb, &err)) {
    if (err.status == VALO_ERR_NOMEM && !s->tex_fatal.status) { s->tex_fatal = err; return -1; }
    log_warning("%s%s%s (the map is ignored)", s->tex_user, s->tex_user[0] ? ": " : "", err.message);
    return -1;
  }
  return add_texture(s, &t, key);
}

int scene_texture_sampled(scene *s, int base, const tex_sampling *smp) {
  if (base < 0) return base;
  const texture *b = &s->tex[base];
  const tex_sampling *bs = &b->smp;
  if (bs->wrap == smp->wrap && bs->filter == smp->filter && bs->has_uvm == smp->has_uvm && (!smp->has_uvm || !memcmp(bs->uvm, smp->uvm, sizeof bs->uvm)))
    return base;
  char key[600];
  int n = snprintf(key, sizeof key, "%s|w%d|f%d", b->key, (int)smp->wrap, (int)smp->filter);
  for (int k = 0; smp->has_uvm && k < 6 && n > 0 && n < (int)sizeof key; k++) n += snprintf(key + n, sizeof key - n, "|%a", smp->uvm[k]);
  int i = find_texture(s, key);
  if (i >= 0) return i;
  texture t = *b;
  t.smp = *smp;
  t.shares_px = 1;
  return add_texture(s, &t, key);
}

int scene_texture_luminance(scene *s, int base) {
  if (base < 0) return base;
  char key[600];
  snprintf(key, sizeof key, "%s|Y", s->tex[base].key);
  int i = find_texture(s, key);
  if (i >= 0) return i;
  texture t = s->tex[base];
  size_t n = (size_t)t.w * (size_t)t.h;
  t.px = malloc(n * 4 * sizeof *t.px);
  if (!t.px) return -1;
  const float *src = s->tex[base].px;
  for (size_t k = 0; k < n; k++) {
    float y = c3_lum_mitsuba(c3(src[4 * k], src[4 * k + 1], src[4 * k + 2]));
    t.px[4 * k] = t.px[4 * k + 1] = t.px[4 * k + 2] = y;
    t.px[4 * k + 3] = 1;
  }
  t.has_alpha = 0;
  t.shares_px = 0;
  return add_texture(s, &t, key);
}

int scene_texture_checkerboard(scene *s, const float c0[3], const float c1[3], valo_error *err) {
  char key[600];
  snprintf(key, sizeof key, "checkerboard|%a,%a,%a|%a,%a,%a", c0[0], c0[1], c0[2], c1[0], c1[1], c1[2]);
  int i = find_texture(s, key);
  if (i >= 0) return i;
  texture t;
  if (texture_checkerboard(&t, c0, c1, err)) return -1;
  return add_texture(s, &t, key);
}

/* The sphere whose triangles hold t (their ranges are in order), or NULL. */
static const sphere_shape *tri_sphere(const scene *s, uint32_t t) {
  uint32_t lo = 0, hi = s->nspheres;
  while (lo < hi) {
    uint32_t mid = lo + (hi - lo) / 2;
    if (s->spheres[mid].end <= t) lo = mid + 1;
    else hi = mid;
  }
  return lo < s->nspheres && s->spheres[lo].first <= t ? &s->spheres[lo] : NULL;
}

void scene_tri_uv(const scene *s, uint32_t t, float b1, float b2, float *u, float *v) {
  const uint32_t *ix = &s->idx[3 * t];
  float b0 = 1 - b1 - b2;
  const sphere_shape *sp = (s->tri_flags[t] & TRI_SPHERE) ? tri_sphere(s, t) : NULL;
  if (sp) {
    vec3 p = v3_add(v3_add(v3_scale(s->pos[ix[0]], b0), v3_scale(s->pos[ix[1]], b1)), v3_scale(s->pos[ix[2]], b2));
    scene_sphere_point_uv(sp, p, u, v);
    return;
  }
  *u = b0 * s->uv[2 * ix[0]] + b1 * s->uv[2 * ix[1]] + b2 * s->uv[2 * ix[2]];
  *v = b0 * s->uv[2 * ix[0] + 1] + b1 * s->uv[2 * ix[1] + 1] + b2 * s->uv[2 * ix[2] + 1];
}

rgb scene_tri_color(const scene *s, uint32_t t, float b1, float b2) {
  if (!s->col) return c3(1, 1, 1);
  const uint32_t *ix = &s->idx[3 * t];
  const float *a = &s->col[3 * (size_t)ix[0]], *b = &s->col[3 * (size_t)ix[1]], *c = &s->col[3 * (size_t)ix[2]];
  float b0 = 1 - b1 - b2;
  return c3(b0 * a[0] + b1 * b[0] + b2 * c[0], b0 * a[1] + b1 * b[1] + b2 * c[1], b0 * a[2] + b1 * b[2] + b2 * c[2]);
}

int material_has_maps(const material *m) {
  return m->tex_kd >= 0 || m->tex_ks >= 0 || m->tex_ke >= 0 || m->tex_alpha >= 0 || m->tex_normal >= 0 || m->tex_ns >= 0 || m->tex_bump >= 0 ||
         m->tex_rough >= 0 || m->tex_metal >= 0 || m->tex_mr >= 0 || m->tex_weight >= 0 ||
         m->tex_cc >= 0 || m->tex_ccr >= 0 || m->tex_sheen >= 0;
}

int scene_alpha_pass(const scene *s, uint32_t t, float b1, float b2, uint64_t key) {
  const material *m = &s->mats[s->tri_mat[t]];
  float a = m->opacity;
  if (m->tex_alpha >= 0 && (s->tri_flags[t] & TRI_HAS_UVS)) {
    float u, v, px[4];
    scene_tri_uv(s, t, b1, b2, &u, &v);
    texture_lookup(&s->tex[m->tex_alpha], u, v, px);
    float x = m->alpha_channel ? px[3] : px[0];
    if (!m->alpha_stochastic) {
      if (!(x >= m->alpha_cutoff)) return 0;
    } else {
      a *= x;
    }
  }
  if (a >= 1) return 1;
  if (!(a > 0)) return 0;
  uint64_t h = rng_mix64(key ^ ((uint64_t)t * 0xD1B54A32D192ED03ull + 0x632BE59BD9B4E019ull));
  return rng_to_float((uint32_t)(h >> 32)) < a;
}

/* Per-vertex tangents: the file's where it gave them (glTF TANGENT), else from UV
 * derivatives (dp/du), accumulated area-weighted over the triangles that share a vertex
 * and made orthogonal to the vertex normal (digest 000); the sign of the bitangent
 * follows the UV handedness. */
static int compute_tangents(scene *s) {
  float *acc = calloc((size_t)s->nverts * 7, sizeof(float)); /* t xyz, b xyz, count */
  s->tan = malloc((size_t)s->nverts * 4 * sizeof(float));
  if (!acc || !s->tan) { free(acc); free(s->tan); s->tan = NULL; return -1; }
  for (uint32_t t = 0; t < s->ntris; t++) {
    if (!(s->tri_flags[t] & TRI_HAS_UVS) || s->mats[s->tri_mat[t]].tex_normal < 0) continue;
    const uint32_t *ix = &s->idx[3 * t];
    vec3 e1 = v3_sub(s->pos[ix[1]], s->pos[ix[0]]), e2 = v3_sub(s->pos[ix[2]], s->pos[ix[0]]);
    float du1 = s->uv[2 * ix[1]] - s->uv[2 * ix[0]], dv1 = s->uv[2 * ix[1] + 1] - s->uv[2 * ix[0] + 1];
    float du2 = s->uv[2 * ix[2]] - s->uv[2 * ix[0]], dv2 = s->uv[2 * ix[2] + 1] - s->uv[2 * ix[0] + 1];
    float det = du1 * dv2 - du2 * dv1;
    if (!(fabsf(det) > 1e-12f)) continue;
    float r = 1 / det;
    /* Unnormalised dp/du and dp/dv; their length carries the area weighting. */
    vec3 tu = v3_scale(v3_sub(v3_scale(e1, dv2), v3_scale(e2, dv1)), r);
    vec3 tv = v3_scale(v3_sub(v3_scale(e2, du1), v3_scale(e1, du2)), r);
    float area = 0.5f * v3_len(v3_cross(e1, e2));
    tu = v3_scale(v3_norm(tu), area);
    tv = v3_scale(v3_norm(tv), area);
    for (int k = 0; k < 3; k++) {
      float *a = &acc[7 * ix[k]];
      a[0] += tu.x; a[1] += tu.y; a[2] += tu.z; a[3] += tv.x; a[4] += tv.y; a[5] += tv.z; a[6] += 1;
    }
  }
  for (uint32_t v = 0; v < s->nverts; v++) {
    const float *a = &acc[7 * v], *given = s->tan_file ? &s->tan_file[4 * v] : NULL;
    vec3 n = s->nrm[v], t = v3(a[0], a[1], a[2]), b = v3(a[3], a[4], a[5]);
    float *o = &s->tan[4 * v];
    if (given && given[3] != 0 && v3_len2(n) > 0) {
      vec3 g = v3(given[0], given[1], given[2]);
      g = v3_sub(g, v3_scale(n, v3_dot(n, g)));
      if (v3_len2(g) > 1e-12f) {
        g = v3_norm(g);
        o[0] = g.x; o[1] = g.y; o[2] = g.z; o[3] = given[3] < 0 ? -1.0f : 1.0f;
        continue;
      }
    }
    if (!(v3_len2(n) > 0) || !(v3_len2(t) > 0)) { o[0] = o[1] = o[2] = 0; o[3] = 1; continue; }
    t = v3_sub(t, v3_scale(n, v3_dot(n, t)));
    t = v3_norm(t);
    o[0] = t.x; o[1] = t.y; o[2] = t.z;
    o[3] = v3_dot(v3_cross(n, t), b) < 0 ? -1.0f : 1.0f;
  }
  free(acc);
  return 0;
}

/* Per-triangle media from the shapes that bound them; has_media when any medium or null
 * surface is there to render. */
static valo_status commit_media(scene *s, valo_error *err) {
  free(s->tri_media);
  s->tri_media = NULL;
  s->has_media = s->nmedia > 0;
  for (uint32_t m = 0; m < s->nmats && !s->has_media; m++) s->has_media = s->mats[m].type == MAT_NULL;
  if (!s->nshape_media) return VALO_OK;
  s->tri_media = malloc((size_t)s->ntris * 2 * sizeof(int32_t));
  if (!s->tri_media) return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", s->path);
  for (uint32_t t = 0; t < 2 * s->ntris; t++) s->tri_media[t] = MEDIUM_KEEP;
  for (uint32_t i = 0; i < s->nshape_media; i++)
    for (uint32_t t = s->shape_media[i].first; t < s->shape_media[i].end && t < s->ntris; t++) {
      s->tri_media[2 * t] = s->shape_media[i].interior;
      s->tri_media[2 * t + 1] = s->shape_media[i].exterior;
    }
  return VALO_OK;
}

valo_status scene_commit(scene *s, valo_error *err) {
  if (s->ntris == 0 && s->nlights == 0 && !s->has_env)
    return err_set(err, VALO_ERR_INVALID, "%s: the scene has no geometry and no lights", s->path);
  /* A spare vertex after the last: Embree shares pos and reads each vertex with a 16-byte load. */
  if (scene_reserve(s, 1, 0)) return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", s->path);
  s->pos[s->nverts] = v3(0, 0, 0);
  bbox b = bbox_empty();
  for (uint32_t i = 0; i < s->nverts; i++) b = bbox_add(b, s->pos[i]);
  for (uint32_t i = 0; i < s->nlights; i++)
    if (s->lights[i].type == LIGHT_POINT || s->lights[i].type == LIGHT_SPOT) b = bbox_add(b, s->lights[i].p);
  if (b.lo.x > b.hi.x) b.lo = b.hi = v3(0, 0, 0);
  s->bounds = b;
  s->center = v3_scale(v3_add(b.lo, b.hi), 0.5f);
  s->radius = fmaxf(0.5f * v3_len(v3_sub(b.hi, b.lo)), 1e-3f);

  /* One area light per emissive triangle (emission is never counted twice: the path
   * integrator weights hits on these by MIS against light sampling). */
  free(s->tri_light);
  s->tri_light = malloc((size_t)(s->ntris ? s->ntris : 1) * sizeof(int32_t));
  if (!s->tri_light) return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", s->path);
  for (uint32_t t = 0; t < s->ntris; t++) {
    s->tri_light[t] = -1;
    const material *m = &s->mats[s->tri_mat[t]];
    if ((m->tex_alpha >= 0 && (s->tri_flags[t] & TRI_HAS_UVS)) || m->opacity < 1) s->tri_flags[t] |= TRI_ALPHA;
    if (c3_black(m->emission)) continue;
    light l;
    scene_area_light(s, t, &l);
    l.L = m->emission;
    l.two_sided = m->two_sided;
    if (!(l.area > 0)) continue;
    s->tri_light[t] = (int32_t)s->nlights;
    if (scene_add_light(s, &l)) return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", s->path);
  }
  /* An emitting sphere whose triangles are all lights, in order, is one light source to
   * sampling (light.h, light_sphere_at). */
  for (uint32_t g = 0; g < s->nspheres; g++) {
    sphere_shape *sp = &s->spheres[g];
    sp->l0 = sp->l1 = 0;
    if (sp->flip || sp->end <= sp->first || s->tri_light[sp->first] < 0) continue;
    uint32_t l0 = (uint32_t)s->tri_light[sp->first], t = sp->first;
    while (t < sp->end && s->tri_light[t] == (int32_t)(l0 + (t - sp->first))) t++;
    if (t < sp->end) continue;
    sp->l0 = l0;
    sp->l1 = l0 + (sp->end - sp->first);
    for (uint32_t l = sp->l0; l < sp->l1; l++) s->lights[l].sphere = g + 1;
  }
  if (scene_flag_light_overlaps(s)) return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", s->path);
  valo_status mst = commit_media(s, err);
  if (mst) return mst;
  int any_normal_map = 0;
  for (uint32_t m = 0; m < s->nmats; m++) any_normal_map |= s->mats[m].tex_normal >= 0;
  if (any_normal_map) {
    /* Triangles without vertex normals get their geometric normal at their vertices. */
    for (uint32_t t = 0; t < s->ntris; t++) {
      if (s->tri_flags[t] & TRI_HAS_NORMALS) continue;
      if (s->mats[s->tri_mat[t]].tex_normal < 0) continue;
      vec3 n = v3_norm(scene_tri_ng(s, t));
      for (int k = 0; k < 3; k++) if (!(v3_len2(s->nrm[s->idx[3 * t + k]]) > 0)) s->nrm[s->idx[3 * t + k]] = n;
    }
    free(s->tan);
    s->tan = NULL;
    if (compute_tangents(s)) return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", s->path);
  }
  if (s->has_env) {
    light l;
    memset(&l, 0, sizeof l);
    l.type = LIGHT_ENV;
    l.L = s->env_map ? s->env_map->average : s->env_radiance;
    if (!c3_black(l.L) && scene_add_light(s, &l)) return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", s->path);
  }
  if (!s->has_camera) {
    /* Framed automatically (docs/scene-format.md): a front view, 40 degree vertical fov;
     * scene_camera_fit fits the distance to the bounds for the film's aspect (camera_frame). */
    s->cam.fov_deg = 40;
    s->cam.ortho_height = 0;
    s->cam.look_at = s->center;
    s->cam.up = s->up_z ? v3(0, 0, 1) : v3(0, 1, 0);
    vec3 back = s->up_z ? v3(0, -1, 0) : v3(0, 0, 1);
    s->cam.pos = v3_add(s->center, v3_scale(back, s->radius / sinf(0.5f * 40 * PI_F / 180)));
    s->cam.aperture_radius = 0;
    s->cam.focus_distance = -1;
    s->cam_auto = 1;
    s->has_camera = 1;
  }
  return VALO_OK;
}

/* Moves an automatic camera along its view axis to the nearest distance at which all
 * eight corners of the bounds fit in the frame (2 % margin) for this aspect: a corner q
 * (relative to the look-at point; x right, y up, z away from the camera) projects inside
 * when D + z >= |x| / tan(h) and D + z >= |y| / tan(v). */
camera scene_camera_fit(const scene *s, float aspect) {
  camera cam = s->cam;
  if (!s->cam_auto) return cam;
  camera *c = &cam;
  vec3 f = v3_norm(v3_sub(c->look_at, c->pos)), r = v3_norm(v3_cross(f, c->up)), u = v3_cross(r, f);
  float tv = tanf(0.5f * c->fov_deg * PI_F / 180) * 0.98f, th = tv * aspect;
  float D = 0;
  for (int k = 0; k < 8; k++) {
    vec3 p = v3(k & 1 ? s->bounds.hi.x : s->bounds.lo.x, k & 2 ? s->bounds.hi.y : s->bounds.lo.y, k & 4 ? s->bounds.hi.z : s->bounds.lo.z);
    vec3 q = v3_sub(p, c->look_at);
    float x = fabsf(v3_dot(q, r)), y = fabsf(v3_dot(q, u)), z = v3_dot(q, f);
    float need = fmaxf(x / th, y / tv) - z;
    D = fmaxf(D, need);
    D = fmaxf(D, -z + 1e-3f * s->radius); /* the camera stays outside the bounds */
  }
  if (!(D > 0) || !isfinite(D)) D = s->radius;
  c->pos = v3_sub(c->look_at, v3_scale(f, D));
  c->focus_distance = D;
  return cam;
}

camera scene_camera_at(const scene *s, const camera *still, float f) {
  camera c = *still;
  if (!s->ncam_keys) return c;
  const cam_key *k = s->cam_keys;
  uint32_t n = s->ncam_keys, i = 0;
  if (f <= k[0].frame || n == 1) i = 0;
  else if (f >= k[n - 1].frame) i = n - 1;
  else {
    while (i + 1 < n && k[i + 1].frame <= f) i++;
    float t = (f - k[i].frame) / (k[i + 1].frame - k[i].frame);
    c.pos = v3_add(v3_scale(k[i].pos, 1 - t), v3_scale(k[i + 1].pos, t));
    c.look_at = v3_add(v3_scale(k[i].look_at, 1 - t), v3_scale(k[i + 1].look_at, t));
    c.up = v3_add(v3_scale(k[i].up, 1 - t), v3_scale(k[i + 1].up, t));
    c.fov_deg = k[i].fov_deg * (1 - t) + k[i + 1].fov_deg * t;
    c.ortho_height = k[i].ortho_height * (1 - t) + k[i + 1].ortho_height * t;
    return c;
  }
  c.pos = k[i].pos; c.look_at = k[i].look_at; c.up = k[i].up; c.fov_deg = k[i].fov_deg; c.ortho_height = k[i].ortho_height;
  return c;
}

const shape_ao *scene_shape_ao(const scene *s, uint32_t t) {
  uint32_t lo = 0, hi = s->nshape_ao;
  while (lo < hi) { /* last range with first <= t */
    uint32_t m = (lo + hi) / 2;
    if (s->shape_ao[m].first <= t) lo = m + 1;
    else hi = m;
  }
  if (lo == 0) return NULL;
  const shape_ao *a = &s->shape_ao[lo - 1];
  return t < a->end ? a : NULL;
}

