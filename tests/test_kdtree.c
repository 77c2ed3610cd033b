/* test_kdtree.c — the SAH kd-tree against brute force: for 100 000 random rays on Cornell
 * boxes and suzanne (30 000 on the Stanford bunny, 100 000 with VALO_TEST_FULL=1), the
 * closest hit (t and triangle) equals an all-triangles loop using the same watertight
 * test, and shadow (any-hit) queries agree.
 * Also axis-aligned rays through vertices and in split planes (axis_rays_kdtree), and the
 * Embree backend against the same brute force, within float tolerance. camera_rays_kdtree
 * sees every real scene with a camera (veach-mis, veach-bidir, torus, Sponza, the Cornell
 * boxes) through it: camera rays, one bounce, rays grazing the largest triangles and rays
 * starting exactly on a surface, kd-tree against brute force exactly (except where a ray
 * grazes brute force's triangle so closely that its t's error bound covers the kd-tree's
 * farther hit) and Embree within tolerance (nearly axis-aligned walls fell out of cells
 * they reach). The same shadow rays in batches (accel_occluded_n, Embree's streams) agree
 * alike. walk_matches_trace checks the instruments of bench_raykernel --bound. */
#include "harness.h"
#include "load/load.h"
#include "scene/scene.h"
#include "geometry/accel.h"
#include "geometry/triangle.h"
#include "geometry/kdtree_internal.h"
#include "geometry/offset.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "core/threadpool.h"
#include <stdlib.h>
#include <string.h>
#include <float.h>

typedef struct bf_job { const scene *s; const ray *rays; hit *hits; int *found; int *occl; float *occl_tmax; } bf_job;

/* The hit filter under test (NULL: none), given to the structure and applied by brute
 * force in the same way: a hit on a flagged triangle counts only if it passes. */
static const accel_filter *g_filter;
static int filter_passes(uint32_t t, float b1, float b2, const ray *r) {
  const accel_filter *f = g_filter;
  return !f || !(f->tri_flags[t] & f->flag_bit) || f->pass(f->user, t, b1, b2, accel_ray_key(r->o, r->d));
}

static void tri_verts(const scene *s, uint32_t t, float v[9]) {
  for (int k = 0; k < 3; k++) memcpy(&v[3 * k], &s->pos[s->idx[3 * t + k]], sizeof(vec3));
}

static void brute(void *user, int64_t i, int thread) {
  (void)thread;
  bf_job *j = user;
  const scene *s = j->s;
  ray r = j->rays[i];
  ray_shear sh = ray_shear_make(r.o, r.d);
  float best = r.tmax;
  int found = 0, occl = 0;
  hit h = {0, 0, 0, 0};
  for (uint32_t t = 0; t < s->ntris; t++) {
    float v[9];
    tri_verts(s, t, v);
    float tt, b1, b2;
    if (tri_intersect(&sh, v, INFINITY, &tt, &b1, &b2) && filter_passes(t, b1, b2, &r)) {
      if (tt < j->occl_tmax[i]) occl = 1;
      if (tt < best) { best = tt; h.t = tt; h.b1 = b1; h.b2 = b2; h.tri = t; found = 1; }
    }
  }
  j->hits[i] = h;
  j->found[i] = found;
  j->occl[i] = occl;
}

/* Axis-aligned rays, the traversal's corner cases: directions along an axis or in an
 * axis plane (zero components, some -0), origins on vertex coordinates, so a ray often
 * lies in a split plane or box face (where t of the plane is NaN). */
static void make_axis_ray(const scene *s, sampler *sm, ray *r) {
  vec3 ext = v3_sub(s->bounds.hi, s->bounds.lo);
  float d[3] = {0, 0, 0}, o[3];
  vec3 p = s->pos[sampler_u32(sm) % s->nverts];
  memcpy(o, &p, sizeof o);
  int a = (int)(sampler_u32(sm) % 3), two = sampler_1d(sm) < 0.5f;
  d[a] = sampler_1d(sm) < 0.5f ? -1.0f : 1.0f;
  if (two) d[(a + 1) % 3] = sampler_1d(sm) * 2 - 1;
  for (int k = 0; k < 3; k++) {
    if (d[k] == 0) { if (sampler_1d(sm) < 0.5f) d[k] = -0.0f; continue; }
    o[k] -= d[k] * v3_get(ext, k) * (0.5f + sampler_1d(sm)); /* back off along the ray only */
  }
  r->o = v3(o[0], o[1], o[2]);
  r->d = v3_norm(v3(d[0], d[1], d[2]));
  r->tmax = INFINITY;
}

/* Random rays: origins in the bounds grown by 20 %, uniform directions; a third start
 * on triangles (like secondary rays) to stress hits near origins. With axis set, every
 * other ray is axis-aligned instead (make_axis_ray). */
static void make_rays(const scene *s, ray *rays, float *shadow_tmax, int n, uint64_t seed, int axis) {
  vec3 lo = s->bounds.lo, hi = s->bounds.hi, ext = v3_sub(hi, lo);
  lo = v3_sub(lo, v3_scale(ext, 0.2f));
  ext = v3_scale(ext, 1.4f);
  for (int i = 0; i < n; i++) {
    sampler sm = sampler_make(seed, (uint64_t)i, 0);
    vec3 o;
    if (i % 3 == 0) {
      uint32_t t = sampler_u32(&sm) % s->ntris;
      float b0, b1;
      sample_uniform_triangle(sampler_1d(&sm), sampler_1d(&sm), &b0, &b1);
      const uint32_t *ix = &s->idx[3 * t];
      o = v3_add(v3_add(v3_scale(s->pos[ix[0]], b0), v3_scale(s->pos[ix[1]], b1)), v3_scale(s->pos[ix[2]], 1 - b0 - b1));
      vec3 ng = v3_norm(scene_tri_ng(s, t));
      o = v3_add(o, v3_scale(ng, 1e-4f * v3_len(ext)));
    } else {
      o = v3_add(lo, v3_mul(ext, v3(sampler_1d(&sm), sampler_1d(&sm), sampler_1d(&sm))));
    }
    rays[i].o = o;
    rays[i].d = sample_uniform_sphere(sampler_1d(&sm), sampler_1d(&sm));
    rays[i].tmax = INFINITY;
    if (axis && i % 2) make_axis_ray(s, &sm, &rays[i]);
    shadow_tmax[i] = sampler_1d(&sm) * v3_len(ext);
  }
}

static int check_scene_rays(const char *path, int nrays, const char *kind, int axis) {
  if (!path) return TEST_SKIP;
  if (!strcmp(kind, "embree") && !test_embree()) { fprintf(stderr, "skipped: no embree\n"); return TEST_SKIP; }
  scene *s = scene_new(path);
  valo_error err;
  CHECK(load_mesh(s, path, NULL, UINT32_MAX, 0, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(scene_commit(s, &err) == VALO_OK, "%s", err.message);
  accel *a;
  CHECK(accel_create(kind, s->pos, s->cap_verts, s->idx, s->ntris, 1, g_filter, &a, &err) == VALO_OK, "%s", err.message);
  ray *rays = malloc(nrays * sizeof *rays);
  float *stmax = malloc(nrays * sizeof *stmax);
  hit *bh = malloc(nrays * sizeof *bh);
  int *bf = malloc(nrays * sizeof *bf), *bo = malloc(nrays * sizeof *bo);
  make_rays(s, rays, stmax, nrays, 42, axis);
  bf_job job = {s, rays, bh, bf, bo, stmax};
  parallel_for(threads_available(), nrays, brute, &job);
  int nhit = 0, bad_hit = 0, bad_occl = 0, tie = 0;
  int strict = !strcmp(kind, "kdtree");
  for (int i = 0; i < nrays; i++) {
    hit h;
    int f = accel_intersect(a, &rays[i], &h);
    nhit += bf[i];
    if (f != bf[i]) { if (bad_hit++ < 5) fprintf(stderr, "ray %d: accel found=%d brute=%d (brute t=%g)\n", i, f, bf[i], bh[i].t); continue; }
    if (f) {
      if (strict) {
        /* An axis-aligned ray through a vertex that lies on a split plane hits two
         * triangles whose t round apart by an ulp or so, and the plane's own t may fall
         * between them: the tree then stops at the first. The same point either way. */
        int ulp_tie = axis && fabsf(h.t - bh[i].t) <= 4 * FLT_EPSILON * bh[i].t;
        if (h.t != bh[i].t && !ulp_tie) { if (bad_hit++ < 5) fprintf(stderr, "ray %d: t %.9g vs brute %.9g\n", i, h.t, bh[i].t); }
        else if (h.tri != bh[i].tri) tie++; /* same t on a shared edge: either triangle is right */
      } else if (fabsf(h.t - bh[i].t) > 1e-4f * fmaxf(1, bh[i].t)) {
        if (bad_hit++ < 5) fprintf(stderr, "ray %d: t %.9g vs brute %.9g\n", i, h.t, bh[i].t);
      }
    }
    ray sr = rays[i];
    sr.tmax = stmax[i];
    int o = accel_occluded(a, &sr);
    if (o != bo[i]) {
      /* Embree may differ where a hit lies within float tolerance of tmax. */
      if (strict || fabsf(bh[i].t - stmax[i]) > 1e-4f * stmax[i]) { if (bad_occl++ < 5) fprintf(stderr, "ray %d: occluded %d vs brute %d\n", i, o, bo[i]); }
    }
  }
  /* The same shadow rays in batches of up to 300 (accel_occluded_n: Embree's streams). */
  int bad_occl_n = 0;
  ray *sr_n = malloc(300 * sizeof *sr_n);
  uint8_t blocked[300];
  for (int i0 = 0; i0 < nrays; i0 += 300) {
    int m = nrays - i0 < 300 ? nrays - i0 : 300;
    for (int k = 0; k < m; k++) { sr_n[k] = rays[i0 + k]; sr_n[k].tmax = stmax[i0 + k]; }
    accel_occluded_n(a, sr_n, blocked, m);
    for (int k = 0, i = i0; k < m; k++, i++)
      if (blocked[k] != bo[i] && (strict || fabsf(bh[i].t - stmax[i]) > 1e-4f * stmax[i])) {
        if (bad_occl_n++ < 5) fprintf(stderr, "ray %d in a batch: occluded %d vs brute %d\n", i, blocked[k], bo[i]);
      }
  }
  free(sr_n);
  fprintf(stderr, "%s on %s: %d rays, %d hits, %d ties on shared edges, %d hit mismatches, %d shadow mismatches (%d in batches)\n", kind,
          path, nrays, nhit, tie, bad_hit, bad_occl, bad_occl_n);
  accel_destroy(a);
  free(rays); free(stmax); free(bh); free(bf); free(bo);
  scene_free(s);
  CHECK(nhit > nrays / 10, "too few hits (%d) for the test to mean anything", nhit);
  /* The kd-tree uses the very same triangle test as brute force: exact agreement.
   * Embree's robust mode rounds differently, so a ray grazing an open boundary edge
   * (a Cornell box has many) may be classified differently: at most 1 in 10 000. */
  int allowed = strict ? 0 : nrays / 10000;
  CHECK(bad_hit <= allowed, "%d closest-hit mismatches (allowed %d)", bad_hit, allowed);
  CHECK(bad_occl <= allowed, "%d shadow-query mismatches (allowed %d)", bad_occl, allowed);
  CHECK(bad_occl_n <= allowed, "%d shadow-query mismatches in batches (allowed %d)", bad_occl_n, allowed);
  return 0;
}

static int check_scene(const char *path, int nrays, const char *kind) { return check_scene_rays(path, nrays, kind, 0); }
static int nrays_big(void) { return 100000; }
/* The bunny: 15 000 rays by default (brute force over 69 451 triangles; 10 000 for Embree),
 * 100 000 in the full form. */
static int bunny_kdtree(void) { return check_scene(shared_file("scenes/models/stanford-bunny.obj"), test_full() ? nrays_big() : 15000, "kdtree"); }
static int cornell_kdtree(void) { return check_scene(shared_file("scenes/cornell/CornellBox-Original.obj"), nrays_big(), "kdtree"); }
static int cornell_sphere_kdtree(void) { return check_scene(shared_file("scenes/cornell/CornellBox-Sphere.obj"), nrays_big(), "kdtree"); }
static int suzanne_kdtree(void) { return check_scene(shared_file("scenes/models/suzanne.obj"), nrays_big(), "kdtree"); }
static int axis_rays_kdtree(void) {
  int r = check_scene_rays(shared_file("scenes/cornell/CornellBox-Original.obj"), nrays_big(), "kdtree", 1);
  return r ? r : check_scene_rays(shared_file("scenes/models/suzanne.obj"), nrays_big(), "kdtree", 1);
}
/* An alpha-like hit filter: on every other triangle (flagged), a pattern of holes that
 * depends on where the triangle is hit (16 x 16 cells of barycentric space, a third of them
 * open), as an alpha texture would; on every fourth, a coin tossed from the ray's key and
 * the triangle, as a stochastic opacity of 1/2 is. The kd-tree (exactly) and Embree
 * (within tolerance) must find what brute force finds with the same filter, for closest
 * hits and shadows: both backends must hand the filter the key of the query's ray. */
static int holes(const void *user, uint32_t tri, float b1, float b2, uint64_t key) {
  (void)user;
  if (tri % 4 == 1) return (rng_mix64(key ^ tri) >> 63) != 0;
  uint32_t h = tri * 2654435761u ^ (uint32_t)(b1 * 16) * 40503u ^ (uint32_t)(b2 * 16) * 9973u;
  h ^= h >> 15;
  return h % 3 != 0;
}
static int alpha_filtered(void) {
  const char *path = shared_file("scenes/models/suzanne.obj");
  if (!path) return TEST_SKIP;
  static uint8_t flags[1 << 20];
  for (uint32_t t = 0; t < sizeof flags; t++) flags[t] = (t & 1) ? 4 : 0;
  accel_filter f = {holes, NULL, flags, 4};
  g_filter = &f;
  int r = check_scene_rays(path, nrays_big(), "kdtree", 0);
  if (!r && test_embree()) r = check_scene_rays(path, nrays_big(), "embree", 0);
  g_filter = NULL;
  return r;
}
static int bunny_embree(void) { return check_scene(shared_file("scenes/models/stanford-bunny.obj"), test_full() ? nrays_big() : 10000, "embree"); }
static int cornell_embree(void) { return check_scene(shared_file("scenes/cornell/CornellBox-Original.obj"), nrays_big(), "embree"); }

/* ------------------------------------------------------- real cameras */

/* The cameras of the real scenes (mitsuba-source/scene.xml; the Cornell boxes use the
 * references' camera), at reduced resolution with the same aspect and field of view. */
typedef struct cam_case {
  const char *file;
  float pos[3], look[3], up[3];
  float fov;  /* degrees, along x when fov_x, else vertical */
  int fov_x, w, h;
} cam_case;

static const cam_case cam_cases[] = {
  {"scenes/veach-mis/veach-mis.obj", {28.2792f, 3.5f, 1.23612e-6f}, {27.2792f, 3.5f, 1.23612e-6f}, {0, 1, 0}, 35, 1, 160, 90},
  {"scenes/veach-bidir/veach-bidir.obj", {16.2155f, 4.05167f, 0.0114864f}, {15.215523f, 4.04700f, 0.00646176f},
   {-0.00467005f, 0.999989f, -2.34659e-5f}, 35, 1, 96, 96},
  {"scenes/torus/torus.obj", {-24.173f, -38.184f, 30.0076f}, {-23.7753f, -37.4261f, 29.4905f}, {0.261433f, 0.446628f, 0.855673f},
   34.6222f, 1, 128, 96},
  {"scenes/sponza/sponza.obj", {2.25067f, 8.24132f, -0.0492483f}, {3.15037f, 7.8048f, -0.0501832f},
   {0.436514f, 0.899693f, -0.00291584f}, 96.6708f, 1, 128, 72},
  {"scenes/cornell/CornellBox-Original.obj", {0, 1, 3.4f}, {0, 1, 0}, {0, 1, 0}, 40, 0, 96, 96},
  {"scenes/cornell/CornellBox-Original-White.obj", {0, 1, 3.4f}, {0, 1, 0}, {0, 1, 0}, 40, 0, 64, 64},
  {"scenes/cornell/CornellBox-Mirror.obj", {0, 1, 3.4f}, {0, 1, 0}, {0, 1, 0}, 40, 0, 64, 64},
  {"scenes/cornell/CornellBox-Glass.obj", {0, 1, 3.4f}, {0, 1, 0}, {0, 1, 0}, 40, 0, 64, 64},
  {"scenes/cornell/CornellBox-Glossy.obj", {0, 1, 3.4f}, {0, 1, 0}, {0, 1, 0}, 40, 0, 64, 64},
  {"scenes/cornell/CornellBox-Glossy-Floor.obj", {0, 1, 3.4f}, {0, 1, 0}, {0, 1, 0}, 40, 0, 64, 64},
  {"scenes/cornell/CornellBox-Sphere.obj", {0, 1, 3.4f}, {0, 1, 0}, {0, 1, 0}, 40, 0, 64, 64},
  {"scenes/cornell/CornellBox-Water.obj", {0, 1, 3.4f}, {0, 1, 0}, {0, 1, 0}, 40, 0, 64, 64},
  {"scenes/cornell/CornellBox-Empty-CO.obj", {0, 1, 3.4f}, {0, 1, 0}, {0, 1, 0}, 40, 0, 64, 64},
  {"scenes/cornell/CornellBox-Empty-RG.obj", {0, 1, 3.4f}, {0, 1, 0}, {0, 1, 0}, 40, 0, 64, 64},
  {"scenes/cornell/CornellBox-Empty-Squashed.obj", {0, 1, 3.4f}, {0, 1, 0}, {0, 1, 0}, 40, 0, 64, 64},
  {"scenes/cornell/CornellBox-Empty-White.obj", {0, 1, 3.4f}, {0, 1, 0}, {0, 1, 0}, 40, 0, 64, 64},
};

/* Brute force of one ray (the same watertight test as the kd-tree). */
static int brute_one(const scene *s, const ray *r, hit *h) {
  ray_shear sh = ray_shear_make(r->o, r->d);
  float best = r->tmax;
  int found = 0;
  for (uint32_t t = 0; t < s->ntris; t++) {
    float v[9], tt, b1, b2;
    for (int k = 0; k < 3; k++) memcpy(&v[3 * k], &s->pos[s->idx[3 * t + k]], sizeof(vec3));
    if (tri_intersect(&sh, v, best, &tt, &b1, &b2)) { best = tt; h->t = tt; h->b1 = b1; h->b2 = b2; h->tri = t; found = 1; }
  }
  return found;
}

/* Ray classes: 0 camera, 1 one bounce from the camera hit (robust offset origin, cosine
 * direction on the side the camera ray came from), 2 grazing a large triangle, 3 starting
 * exactly on a surface (no offset). */
enum { RC_CAMERA, RC_BOUNCE, RC_GRAZE, RC_ON_SURFACE, RC_N };
static const char *const rc_names[RC_N] = {"camera", "bounce", "grazing", "on-surface"};
typedef struct cam_job { const scene *s; const cam_case *c; int w, h; ray *rays; int *cls; hit *bh; int *bf; } cam_job;

static vec3 tri_pt(const scene *s, uint32_t t, float b1, float b2, vec3 *err, vec3 *ng) {
  const uint32_t *ix = &s->idx[3 * t];
  *ng = v3_norm(scene_tri_ng(s, t));
  return tri_point(s->pos[ix[0]], s->pos[ix[1]], s->pos[ix[2]], b1, b2, err);
}

/* Pixel i of the camera: its camera ray (in slot 2i) and brute-force hit, then its bounce
 * ray (slot 2i+1) and that one's brute-force hit. */
static void cam_pixel(void *user, int64_t i, int thread) {
  (void)thread;
  cam_job *j = user;
  const cam_case *c = j->c;
  const scene *s = j->s;
  sampler sm = sampler_make(7, (uint64_t)i, 0);
  vec3 pos = v3(c->pos[0], c->pos[1], c->pos[2]);
  vec3 fwd = v3_norm(v3_sub(v3(c->look[0], c->look[1], c->look[2]), pos));
  vec3 right = v3_norm(v3_cross(fwd, v3(c->up[0], c->up[1], c->up[2]))), up = v3_cross(right, fwd);
  float aspect = (float)j->w / (float)j->h, th = tanf(0.5f * c->fov * PI_F / 180.0f);
  if (c->fov_x) th /= aspect;
  int px = (int)(i % j->w), py = (int)(i / j->w);
  float sx = (2.0f * ((float)px + sampler_1d(&sm)) / (float)j->w - 1.0f) * th * aspect;
  float sy = (1.0f - 2.0f * ((float)py + sampler_1d(&sm)) / (float)j->h) * th;
  ray r = {pos, v3_norm(v3_add(fwd, v3_add(v3_scale(right, sx), v3_scale(up, sy)))), INFINITY};
  j->rays[2 * i] = r;
  j->cls[2 * i] = RC_CAMERA;
  j->bf[2 * i] = brute_one(s, &r, &j->bh[2 * i]);
  ray b = {pos, v3(0, 1, 0), INFINITY};
  j->cls[2 * i + 1] = -1; /* no bounce where the camera ray escaped */
  if (j->bf[2 * i]) {
    const hit *h = &j->bh[2 * i];
    vec3 err, ng, p = tri_pt(s, h->tri, h->b1, h->b2, &err, &ng);
    if (v3_dot(ng, r.d) > 0) ng = v3_neg(ng);
    frame f = frame_from_n(ng);
    b.d = frame_to_world(&f, sample_cosine_hemisphere(sampler_1d(&sm), sampler_1d(&sm)));
    b.o = offset_origin(p, err, ng, b.d);
    j->cls[2 * i + 1] = RC_BOUNCE;
    j->bf[2 * i + 1] = brute_one(s, &b, &j->bh[2 * i + 1]);
  }
  j->rays[2 * i + 1] = b;
}

/* Ray i of the grazing and on-surface rays (slots after the camera's). Grazing: a point
 * on one of the largest triangles, a direction within 1e-6..1e-2 rad of its plane, the
 * origin backed off along the ray (to the far side of the scene's bounds). On-surface: a
 * point on a random triangle, exactly as computed, leaving into either hemisphere. */
typedef struct extra_job { const scene *s; const uint32_t *big; uint32_t nbig; int base, n; ray *rays; int *cls; hit *bh; int *bf; } extra_job;
static void extra_ray(void *user, int64_t k, int thread) {
  (void)thread;
  extra_job *j = user;
  const scene *s = j->s;
  sampler sm = sampler_make(11, (uint64_t)k, 0);
  int graze = k < j->n / 2;
  uint32_t t = graze ? j->big[sampler_u32(&sm) % j->nbig] : sampler_u32(&sm) % s->ntris;
  float b0, b1;
  sample_uniform_triangle(sampler_1d(&sm), sampler_1d(&sm), &b0, &b1);
  vec3 err, ng, p = tri_pt(s, t, b1, 1 - b0 - b1, &err, &ng);
  frame f = frame_from_n(ng);
  ray r;
  if (graze) {
    float phi = 2 * PI_F * sampler_1d(&sm), ang = powf(10.0f, -6 + 4 * sampler_1d(&sm));
    if (sampler_1d(&sm) < 0.5f) ang = -ang;
    r.d = v3_norm(frame_to_world(&f, v3(cosf(phi) * cosf(ang), sinf(phi) * cosf(ang), sinf(ang))));
    r.o = v3_sub(p, v3_scale(r.d, 2 * s->radius));
  } else {
    r.d = sample_uniform_sphere(sampler_1d(&sm), sampler_1d(&sm));
    r.o = p;
  }
  r.tmax = INFINITY;
  int64_t slot = j->base + k;
  j->rays[slot] = r;
  j->cls[slot] = graze ? RC_GRAZE : RC_ON_SURFACE;
  j->bf[slot] = brute_one(s, &r, &j->bh[slot]);
}

static int cmp_area_desc(const void *a, const void *b) {
  float x = ((const float *)a)[0], y = ((const float *)b)[0];
  return (x < y) - (x > y);
}

static int check_camera_scene(const cam_case *c, int scale) {
  const char *path = shared_file(c->file);
  if (!path) return TEST_SKIP;
  scene *s = scene_new(path);
  valo_error err;
  CHECK(load_mesh(s, path, NULL, UINT32_MAX, 0, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(scene_commit(s, &err) == VALO_OK, "%s", err.message);
  accel *kd = NULL, *em = NULL;
  CHECK(accel_create("kdtree", s->pos, s->cap_verts, s->idx, s->ntris, 1, NULL, &kd, &err) == VALO_OK, "%s", err.message);
  if (test_embree()) CHECK(accel_create("embree", s->pos, s->cap_verts, s->idx, s->ntris, 1, NULL, &em, &err) == VALO_OK, "%s", err.message);
  int w = c->w * scale, h = c->h * scale, npix = w * h, nextra = 4000 * scale;
  int n = 2 * npix + nextra;
  ray *rays = calloc(n, sizeof *rays);
  hit *bh = calloc(n, sizeof *bh);
  int *bf = calloc(n, sizeof *bf), *cls = calloc(n, sizeof *cls);
  cam_job cj = {s, c, w, h, rays, cls, bh, bf};
  parallel_for(threads_available(), npix, cam_pixel, &cj);
  /* The largest triangles (top 1 %, at least 16): walls, floors, ground planes. */
  float (*area)[2] = malloc(s->ntris * sizeof *area);
  for (uint32_t t = 0; t < s->ntris; t++) { area[t][0] = v3_len(scene_tri_ng(s, t)); memcpy(&area[t][1], &t, 4); }
  qsort(area, s->ntris, sizeof *area, cmp_area_desc);
  uint32_t nbig = s->ntris / 100 > 16 ? s->ntris / 100 : (s->ntris < 16 ? s->ntris : 16);
  uint32_t *big = malloc(nbig * sizeof *big);
  for (uint32_t i = 0; i < nbig; i++) memcpy(&big[i], &area[i][1], 4);
  free(area);
  extra_job ej = {s, big, nbig, 2 * npix, nextra, rays, cls, bh, bf};
  parallel_for(threads_available(), nextra, extra_ray, &ej);
  int count[RC_N] = {0}, hits[RC_N] = {0}, bad_kd[RC_N] = {0}, bad_em[RC_N] = {0}, ties = 0, unsure = 0;
  for (int i = 0; i < n; i++) {
    int k = cls[i];
    if (k < 0) continue;
    count[k]++;
    hits[k] += bf[i];
    hit a;
    int fa = accel_intersect(kd, &rays[i], &a), within = 0;
    if (fa && bf[i] && a.t > bh[i].t && a.tri != bh[i].tri) {
      /* A ray grazing brute force's triangle (a few 10^-6 rad off its plane) gets a t that
       * rounding may put farther from the true one than the triangle is long; no spatial
       * structure can reproduce it, as the ray does not pass there. Then the kd-tree's
       * (farther) hit must lie within that t's error bound. */
      float v[9];
      tri_verts(s, bh[i].tri, v);
      ray_shear sh = ray_shear_make(rays[i].o, rays[i].d);
      within = a.t - bh[i].t <= tri_t_error(&sh, v);
      unsure += within;
    }
    if (!within && (fa != bf[i] || (fa && a.t != bh[i].t))) {
      if (bad_kd[k]++ < 3)
        fprintf(stderr, "  %s ray %d (o %.9g %.9g %.9g, d %.9g %.9g %.9g): kd-tree %s t=%.9g, brute force %s t=%.9g\n", rc_names[k], i,
                rays[i].o.x, rays[i].o.y, rays[i].o.z, rays[i].d.x, rays[i].d.y, rays[i].d.z, fa ? "hit" : "miss", fa ? a.t : 0,
                bf[i] ? "hit" : "miss", bf[i] ? bh[i].t : 0);
    } else if (fa && !within && a.tri != bh[i].tri) ties++;
    /* Embree: camera and bounce rays (its own triangle test rounds differently). */
    if (em && k <= RC_BOUNCE) {
      int fe = accel_intersect(em, &rays[i], &a);
      if (fe != bf[i] || (fe && fabsf(a.t - bh[i].t) > 1e-4f * fmaxf(1, bh[i].t))) bad_em[k]++;
    }
  }
  fprintf(stderr, "%s (%dx%d):", c->file, w, h);
  for (int k = 0; k < RC_N; k++)
    fprintf(stderr, " %s %d rays %d hits, kd-tree/brute mismatches %d%s", rc_names[k], count[k], hits[k], bad_kd[k], k < RC_N - 1 ? ";" : "");
  fprintf(stderr, "; Embree/brute mismatches camera %d bounce %d; %d ties on shared edges; %d farther hits within brute force's t error\n",
          bad_em[0], bad_em[1], ties, unsure);
  accel_destroy(kd);
  accel_destroy(em);
  free(rays); free(bh); free(bf); free(cls); free(big);
  scene_free(s);
  CHECK(hits[RC_CAMERA] > count[RC_CAMERA] / 4, "too few camera hits (%d) for the test to mean anything", hits[RC_CAMERA]);
  for (int k = 0; k < RC_N; k++) CHECK(bad_kd[k] == 0, "%d %s rays where the kd-tree and brute force disagree", bad_kd[k], rc_names[k]);
  CHECK(unsure <= n / 1000, "%d hits farther than brute force's within its t error: too many to be grazing rays", unsure);
  /* Embree rounds its own way: a ray along a shared or open edge may go either way. */
  for (int k = 0; k <= RC_BOUNCE; k++)
    CHECK(bad_em[k] <= count[k] / 2000, "%d %s rays where Embree and brute force disagree", bad_em[k], rc_names[k]);
  return 0;
}

/* Every scene in ../shared/scenes that has a camera, seen through it. */
static int camera_rays_kdtree(void) {
  int scale = test_full() ? 3 : 1, rc = 0, skipped = 0;
  for (size_t i = 0; i < sizeof cam_cases / sizeof cam_cases[0]; i++) {
    int r = check_camera_scene(&cam_cases[i], scale);
    if (r == TEST_SKIP) skipped++;
    else if (r) rc = 1;
  }
  return rc ? 1 : skipped ? TEST_SKIP : 0;
}

/* Large triangles near a corner: a floor and a wall of 2 10^4 units meeting at x = 0;
 * upward rays from floor points 0.005..0.1 from the wall hit the wall iff they head
 * towards it, at t = x / |d.x|. Float's bound on t (10^-2 at these coordinates) used to
 * reject 15 % of those hits as "maybe t <= 0"; the test now decides them in double. */
static int large_triangles_corner(void) {
  const float B = 10000;
  vec3 pos[8] = {{0, 0, -B}, {B, 0, -B}, {B, 0, B}, {0, 0, B}, {0, -B, -B}, {0, -B, B}, {0, B, B}, {0, B, -B}};
  uint32_t idx[12] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
  const char *kinds[2] = {"kdtree", "embree"};
  for (int k = 0; k < 2; k++) {
    accel *a;
    valo_error e;
    if (accel_create(kinds[k], pos, 8, idx, 4, 1, NULL, &a, &e)) {
      CHECK(k == 1 && !test_embree(), "%s", e.message); /* embree is optional outside CI */
      continue;
    }
    int bad = 0, hits = 0;
    for (int i = 0; i < 100000; i++) {
      sampler smp = sampler_make(5, 0, (uint64_t)i);
      float u1, u2, ux = sampler_1d(&smp);
      sampler_2d(&smp, &u1, &u2);
      vec3 d = sample_cosine_hemisphere(u1, u2);
      float x0 = 0.005f + 0.095f * ux;
      ray r = {v3(x0, 1e-3f, 0), v3(d.x, d.z, d.y), INFINITY};
      hit h;
      int f = accel_intersect(a, &r, &h);
      float tw = x0 / fabsf(r.d.x);
      int want = r.d.x < 0 && fabsf(r.o.y + tw * r.d.y) < 0.999f * B && fabsf(tw * r.d.z) < 0.999f * B;
      if (r.d.x < 0 && !want && (fabsf(r.o.y + tw * r.d.y) < 1.001f * B && fabsf(tw * r.d.z) < 1.001f * B)) continue; /* at the rim */
      hits += f;
      /* t itself carries float's error at 10^4 units: 2^-22 10^4 = 2.4e-3 */
      if (f != want || (f && fabsf(h.t - tw) > 5e-3f)) {
        if (bad++ < 5) fprintf(stderr, "%s: ray from x %g dir (%g %g %g): found %d t %g, expected %d t %g\n", kinds[k], x0, r.d.x, r.d.y,
                               r.d.z, f, f ? h.t : 0, want, tw);
      }
    }
    fprintf(stderr, "%s: %d of 100000 rays hit the wall, %d wrong\n", kinds[k], hits, bad);
    accel_destroy(a);
    CHECK(bad == 0, "%s: %d wrong", kinds[k], bad);
  }
  /* No spare vertex after the last (pos[8] is not readable): Embree copies them; one
   * vertex short of what the triangles use is refused, not read past. */
  accel *a;
  valo_error e;
  if (test_embree()) CHECK(accel_create("embree", pos, 7, idx, 4, 1, NULL, &a, &e) == VALO_ERR_INVALID, "a missing vertex accepted");
  return 0;
}


/* Adds t to the m triangles of set unless there or full (5); returns the new count. */
static int set_add(uint32_t set[5], int m, uint32_t t) {
  for (int j = 0; j < m; j++)
    if (set[j] == t) return m;
  if (m < 5) set[m++] = t;
  return m;
}

/* The distinct triangles of the subtree at ni, into set (at most 5 kept; returns how
 * many); counts into *small the splits of subtrees of at most four triangles. */
static int subtree_tris(const kdtree *kd, uint32_t ni, uint32_t set[5], int *small) {
  const kd_node *n = &kd->nodes[ni];
  int m = 0;
  if ((n->flags & 3) == KD_LEAF) {
    for (uint32_t i = 0; i < n->flags >> 2; i++) m = set_add(set, m, kd->ids[4 * (size_t)n->prim_offset + i]);
    return m;
  }
  if ((n->flags & KD_BOX) == KD_BOX) return subtree_tris(kd, ni + KD_BOX_SLOTS, set, small);
  uint32_t other[5];
  m = subtree_tris(kd, ni + 1, set, small);
  int mo = subtree_tris(kd, n->flags >> 4, other, small);
  for (int i = 0; i < mo; i++) m = set_add(set, m, other[i]);
  if (m <= 4) (*small)++;
  return m;
}

/* A mesh of 21 834 triangles (a tessellated sphere, a soup of small random
 * triangles, a large floor and triangles lying in axis planes), so the build's binned
 * top levels (the root's passes in chunks on the thread pool), its parallel subtrees and
 * the join all run without ../shared: the tree
 * must be byte-identical for 1, 2 and 3 build threads (nodes, groups, ids, alpha lanes),
 * and its closest hits and shadow queries equal brute force on 10 000 rays. */
static int filter_odd(const void *user, uint32_t tri, float b1, float b2, uint64_t key) { (void)user; (void)key; return tri % 3 != 0 || b1 < 0.5f + 0.3f * b2; }
static int synthetic_threads(void) {
  enum { SU = 96, SV = 96, SOUP = 3000, PLANAR = 400 };
  uint32_t nt = 2 * SU * SV + SOUP + 2 + PLANAR, nv = (SU + 1) * (SV + 1) + 3 * SOUP + 4 + 3 * PLANAR;
  vec3 *pos = malloc(nv * sizeof *pos);
  uint32_t *idx = malloc(3 * (size_t)nt * sizeof *idx), v = 0, t = 0;
  uint8_t *flags = malloc(nt);
  for (int i = 0; i <= SU; i++)
    for (int j = 0; j <= SV; j++) {
      float th = PI_F * i / SU, ph = 2 * PI_F * j / SV;
      pos[v++] = v3(0.8f * sinf(th) * cosf(ph), 1 + 0.8f * cosf(th), 0.8f * sinf(th) * sinf(ph));
    }
  for (int i = 0; i < SU; i++)
    for (int j = 0; j < SV; j++) {
      uint32_t a = i * (SV + 1) + j, b = a + 1, c = a + SV + 1, d = c + 1;
      idx[3 * t] = a; idx[3 * t + 1] = c; idx[3 * t + 2] = b; t++;
      idx[3 * t] = b; idx[3 * t + 1] = c; idx[3 * t + 2] = d; t++;
    }
  sampler sm = sampler_make(9, 0, 0);
  for (int i = 0; i < SOUP; i++) {
    vec3 c = v3(4 * sampler_1d(&sm) - 2, 3 * sampler_1d(&sm), 4 * sampler_1d(&sm) - 2);
    for (int k = 0; k < 3; k++) {
      idx[3 * t + k] = v;
      pos[v++] = v3_add(c, v3(0.2f * sampler_1d(&sm) - 0.1f, 0.2f * sampler_1d(&sm) - 0.1f, 0.2f * sampler_1d(&sm) - 0.1f));
    }
    t++;
  }
  pos[v] = v3(-5, 0, -5); pos[v + 1] = v3(5, 0, -5); pos[v + 2] = v3(5, 0, 5); pos[v + 3] = v3(-5, 0, 5);
  idx[3 * t] = v; idx[3 * t + 1] = v + 2; idx[3 * t + 2] = v + 1; t++;
  idx[3 * t] = v; idx[3 * t + 1] = v + 3; idx[3 * t + 2] = v + 2; t++;
  v += 4;
  for (int i = 0; i < PLANAR; i++) { /* in the planes z = -1.5 .. 1.5, a tenth apart */
    float z = -1.5f + 0.1f * (i % 31), x = 3 * sampler_1d(&sm) - 1.5f, y = 2.5f * sampler_1d(&sm);
    for (int k = 0; k < 3; k++) { idx[3 * t + k] = v; pos[v++] = v3(x + 0.15f * (k == 1), y + 0.15f * (k == 2), z); }
    t++;
  }
  for (uint32_t i = 0; i < nt; i++) flags[i] = (i % 2) ? 4 : 0;
  accel_filter f = {filter_odd, NULL, flags, 4};
  accel *a[3];
  valo_error err;
  for (int k = 0; k < 3; k++) CHECK(kdtree_create(pos, idx, nt, k + 1, &f, &a[k], &err) == VALO_OK, "%s", err.message);
  const kdtree *k0 = (const kdtree *)a[0];
  for (int k = 1; k < 3; k++) {
    const kdtree *kk = (const kdtree *)a[k];
    CHECK(kk->nnodes == k0->nnodes && kk->nprims == k0->nprims, "%d threads: %u nodes, %llu groups; 1 thread: %u, %llu", k + 1,
          kk->nnodes, (unsigned long long)kk->nprims, k0->nnodes, (unsigned long long)k0->nprims);
    CHECK(!memcmp(kk->nodes, k0->nodes, k0->nnodes * sizeof *k0->nodes), "%d threads: nodes differ", k + 1);
    CHECK(!memcmp(kk->prims, k0->prims, k0->nprims * sizeof *k0->prims), "%d threads: triangle groups differ", k + 1);
    CHECK(!memcmp(kk->ids, k0->ids, 4 * k0->nprims * sizeof *k0->ids), "%d threads: ids differ", k + 1);
    CHECK(!memcmp(kk->gfilt, k0->gfilt, k0->nprims), "%d threads: alpha lanes differ", k + 1);
  }
  kd_stats st;
  kdtree_stats(a[0], &st);
  /* The SAH prices a leaf per group of four: splitting at most four triangles costs a
   * node step more than testing them, so no such split may exist (pbrt's costs, 80 per
   * triangle and three costlier splits allowed, made 4 347 here). */
  uint32_t set[5];
  int small = 0;
  subtree_tris(k0, 0, set, &small);
  CHECK(small == 0, "%d splits of at most four triangles", small);
  g_filter = &f;
  int bad = 0, hits = 0, occluded = 0;
  for (int i = 0; i < 10000; i++) {
    vec3 o = v3(6 * sampler_1d(&sm) - 3, 3.5f * sampler_1d(&sm) - 0.2f, 6 * sampler_1d(&sm) - 3);
    vec3 d = sample_uniform_sphere(sampler_1d(&sm), sampler_1d(&sm));
    if (i % 4 == 0) d = v3(0, 0, d.z < 0 ? -1.0f : 1.0f); /* along z: through the axis-plane triangles */
    ray r = {o, d, i % 3 ? INFINITY : 2.0f};
    ray_shear sh = ray_shear_make(r.o, r.d);
    hit bh = {0, 0, 0, 0}, h;
    int bf = 0, bo = 0;
    for (uint32_t q = 0; q < nt; q++) {
      float tv[9], tt, b1, b2;
      for (int k = 0; k < 3; k++) memcpy(&tv[3 * k], &pos[idx[3 * q + k]], sizeof(vec3));
      if (!tri_intersect(&sh, tv, r.tmax, &tt, &b1, &b2) || !filter_passes(q, b1, b2, &r)) continue;
      bo |= tt < 1.5f;
      if (!bf || tt < bh.t) { bh.t = tt; bh.tri = q; bf = 1; }
    }
    ray sr = r;
    sr.tmax = 1.5f;
    int kf = accel_intersect(a[0], &r, &h), ko = accel_occluded(a[0], &sr);
    hits += bf;
    occluded += bo;
    if (kf != bf || (kf && h.t != bh.t) || ko != bo) {
      if (bad++ < 5) fprintf(stderr, "ray %d: kd found %d t %.9g occluded %d; brute %d t %.9g occluded %d\n", i, kf, kf ? h.t : 0, ko, bf, bh.t, bo);
    }
  }
  g_filter = NULL;
  fprintf(stderr, "%u triangles: %u node slots, %.2f refs per triangle; %d of 10000 rays hit, %d occluded, %d wrong\n", nt, st.nodes,
          (double)st.refs / nt, hits, occluded, bad);
  for (int k = 0; k < 3; k++) accel_destroy(a[k]);
  free(pos); free(idx); free(flags);
  CHECK(hits > 2500 && hits < 9500, "%d hits: the rays do not test the tree", hits);
  CHECK(bad == 0, "%d rays differ from brute force", bad);
  return 0;
}

/* bench_raykernel --bound's instruments: a traced query finds what the query finds; the
 * walk with no triangle tested visits the very nodes and leaves the trace counted and
 * ends as it did; the descent ends at a leaf exactly when the trace reached one. */
static int walk_matches_trace(void) {
  const char *path = shared_file("scenes/models/suzanne.obj");
  if (!path) return TEST_SKIP;
  scene *s = scene_new(path);
  valo_error err;
  CHECK(load_mesh(s, path, NULL, UINT32_MAX, 0, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(scene_commit(s, &err) == VALO_OK, "%s", err.message);
  accel *a;
  CHECK(kdtree_create(s->pos, s->idx, s->ntris, 1, NULL, &a, &err) == VALO_OK, "%s", err.message);
  enum { N = 20000 };
  ray *rays = malloc(N * sizeof *rays);
  float *stmax = malloc(N * sizeof *stmax);
  make_rays(s, rays, stmax, N, 7, 0);
  int bad = 0, hits = 0, blocked = 0;
  uint64_t groups = 0, nodes = 0;
  for (int i = 0; i < N; i++)
    for (int any = 0; any < 2; any++) {
      ray r = rays[i];
      if (any) r.tmax = stmax[i];
      hit h;
      kd_trace tr, w;
      int f = any ? accel_occluded(a, &r) : accel_intersect(a, &r, &h);
      int ft = kdtree_trace(a, &r, any, &tr);
      w = tr;
      int fw = kdtree_walk(a, &r, any, &w, 1);
      int fd = kdtree_walk(a, &r, any, &tr, -1);
      int ok = ft == f && fw == f && w.nodes == tr.nodes && w.leaves == tr.leaves && w.boxes == tr.boxes && tr.descent <= tr.nodes &&
               fd == (tr.leaves > 0) && (!f || tr.end_leaf != UINT32_MAX) && (any || !f || tr.t == h.t);
      if (!ok && bad++ < 5)
        fprintf(stderr, "ray %d any=%d: query %d trace %d walk %d descent %d; nodes %u/%u leaves %u/%u boxes %u/%u descent %u\n", i, any, f, ft,
                fw, fd, tr.nodes, w.nodes, tr.leaves, w.leaves, tr.boxes, w.boxes, tr.descent);
      hits += !any && f;
      blocked += any && f;
      groups += tr.groups;
      nodes += tr.nodes;
    }
  fprintf(stderr, "%d rays: %d hits, %d blocked, %.1f nodes and %.2f groups per query, %d mismatches\n", N, hits, blocked,
          (double)nodes / (2 * N), (double)groups / (2 * N), bad);
  accel_destroy(a);
  free(rays); free(stmax);
  scene_free(s);
  CHECK(hits > N / 10 && blocked > N / 20 && groups > 0, "the rays do not test the tree (%d hits, %d blocked)", hits, blocked);
  CHECK(bad == 0, "%d queries where the walk or the trace differ from the query", bad);
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"bunny_kdtree", bunny_kdtree}, {"cornell_kdtree", cornell_kdtree},
                                    {"cornell_sphere_kdtree", cornell_sphere_kdtree}, {"suzanne_kdtree", suzanne_kdtree},
                                    {"axis_rays_kdtree", axis_rays_kdtree}, {"camera_rays_kdtree", camera_rays_kdtree},
                                    {"bunny_embree", bunny_embree}, {"cornell_embree", cornell_embree},
                                    {"large_triangles_corner", large_triangles_corner}, {"alpha_filtered", alpha_filtered},
                                    {"synthetic_threads", synthetic_threads}, {"walk_matches_trace", walk_matches_trace}, {NULL, NULL}};
  return test_main(argc, argv, cases);
}
