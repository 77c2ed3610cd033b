/* photon.c — owns the `photon` integrator: Jensen's photon mapping (digest 003; Jensen
 * 1996/2001, as pbrt-v2's PhotonIntegrator), progressive by passes.
 *  - prepare (before every sample index): photon paths leave the lights, each light
 *    picked in proportion to its power and the flux split evenly among the paths (the
 *    emission sample drawn from an Owen-scrambled Sobol sequence over the path index);
 *    BSDF sampling carries them on (adjoint: no 1/eta^2 radiance scale, Veach's shading-
 *    normal correction), Russian roulette by the throughput's change keeps photon powers
 *    near constant. Every hit on a surface with a non-delta lobe stores a photon
 *    (position, power, incoming direction octahedron-packed: 28 bytes) in the global
 *    map; a second emission keeps only L S+ D photons (those that reached a diffuse
 *    surface through specular ones), in the caustic map. Emission runs in rounds sized
 *    from the rate seen so far until each map holds its target; rounds are split into
 *    fixed chunks whose photons are concatenated in chunk order, so the maps are the same
 *    for any thread count. Both maps live in the shared point kd-tree.
 *  - li: camera rays follow delta lobes (counting emission); at the first surface with a
 *    non-delta lobe, L = direct light by NEE + the caustic map's estimate + indirect
 *    light by final gathering: `gather` BSDF-sampled rays whose hits take the global
 *    map's estimate of outgoing radiance (after up to 4 delta bounces; emission found by
 *    gather rays is left to NEE and the caustic map).
 *  - radiance estimate: L = sum f(wo, wp) Phi_p / (pi r^2) over the k nearest photons
 *    within the maximum radius, distance measured in a disc squeezed along the surface
 *    normal (|v|^2 + 16 (v.n)^2) against leaks at corners and through thin walls.
 * Biased (blur of the density estimate), consistent as the photon counts grow. */
#include "core/streams.h"
#include "integrator/camera_path.h"
#include "integrator/integrator.h"
#include "geometry/pointtree.h"
#include "integrator/lightpath.h"
#include "core/threadpool.h"
#include "core/error.h"
#include "core/sampling.h"
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

enum { P_GLOBAL, P_CAUSTIC, P_K, P_RADIUS, P_GATHER, P_CAUSTIC_RADIUS };
static const integrator_param photon_params[] = {
    {"global", IPARAM_INT, 100000, 0, 1e8, "photons stored in the global map per pass (pbrt-v2's default count)"},
    {"caustic", IPARAM_INT, 20000, 0, 1e8, "photons stored in the caustic map per pass"},
    {"k", IPARAM_INT, 50, 1, POINT_KNN_MAX, "nearest photons per radiance estimate"},
    {"radius", IPARAM_FLOAT, 0, 0, 1e30, "largest search radius, global map; 0 = automatic, 1/10 of the scene's bounding-sphere radius"},
    {"gather", IPARAM_INT, 32, 0, 4096, "final-gathering rays per camera sample (0: use the global map at the first hit)"},
    {"caustic_radius", IPARAM_FLOAT, 0, 0, 1e30, "largest search radius, caustic map; 0 = automatic, 1/40 of the bounding-sphere radius"},
    {NULL, IPARAM_INT, 0, 0, 0, NULL}};

#define SQUEEZE 16.0f

/* A stored photon: 28 bytes that every estimate reads, plus the surface normal and
 * diffuse reflectance where it landed, which only the radiance-photon precomputation
 * reads (kept beside it rather than in a second pass over the scene). */
typedef struct photon { vec3 p; rgb power; uint32_t dir; uint32_t nrm; rgb rho; } photon; /* dir, nrm: octahedral 2x16 bits */

static uint32_t oct_pack(vec3 d) {
  float s = fabsf(d.x) + fabsf(d.y) + fabsf(d.z);
  float x = d.x / s, y = d.y / s;
  if (d.z < 0) {
    float ox = (1 - fabsf(y)) * (x >= 0 ? 1.0f : -1.0f), oy = (1 - fabsf(x)) * (y >= 0 ? 1.0f : -1.0f);
    x = ox; y = oy;
  }
  uint32_t ux = (uint32_t)lrintf((clampf(x, -1, 1) * 0.5f + 0.5f) * 65535.0f);
  uint32_t uy = (uint32_t)lrintf((clampf(y, -1, 1) * 0.5f + 0.5f) * 65535.0f);
  return ux | (uy << 16);
}
static vec3 oct_unpack(uint32_t u) {
  float x = (float)(u & 0xffff) / 65535.0f * 2 - 1, y = (float)(u >> 16) / 65535.0f * 2 - 1;
  float z = 1 - fabsf(x) - fabsf(y);
  if (z < 0) {
    float ox = (1 - fabsf(y)) * (x >= 0 ? 1.0f : -1.0f), oy = (1 - fabsf(x)) * (y >= 0 ? 1.0f : -1.0f);
    x = ox; y = oy;
  }
  return v3_norm(v3(x, y, z));
}

typedef struct photon_map { point_tree tree; photon *ph; uint32_t n; } photon_map;
/* Radiance photons (Christensen 1999): every RAD_STRIDE-th global photon with its
 * precomputed outgoing radiance rho E / pi, found by gather rays with one nearest lookup
 * instead of a k-nearest estimate. */
#define RAD_STRIDE 4
typedef struct rad_map { point_tree tree; vec3 *n; rgb *Lo; uint32_t n_pts; } rad_map;

typedef struct photon_state {
  photon_map global, caustic;
  rad_map rad;
  int has_specular;        /* any delta lobe in the scene: else no caustic map */
  float r2_global, r2_caustic;
} photon_state;

static void map_free(photon_map *m) {
  point_tree_free(&m->tree);
  free(m->ph);
  memset(m, 0, sizeof *m);
}

static void rad_free(rad_map *r) {
  point_tree_free(&r->tree);
  free(r->n); free(r->Lo);
  memset(r, 0, sizeof *r);
}

static void photon_destroy(void *st) {
  photon_state *ps = st;
  if (!ps) return;
  rad_free(&ps->rad);
  map_free(&ps->global);
  map_free(&ps->caustic);
  free(ps);
}

static valo_status photon_create(const render_ctx *c, void **out, valo_error *err) {
  photon_state *ps = calloc(1, sizeof *ps);
  if (!ps) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  for (uint32_t i = 0; i < c->s->nmats && !ps->has_specular; i++) {
    bsdf b = bsdf_from_material(&c->s->mats[i]);
    ps->has_specular = b.type == BSDF_MIRROR || b.type == BSDF_DIELECTRIC || b.type == BSDF_CONDUCTOR;
  }
  float rg = c->param[P_RADIUS] > 0 ? (float)c->param[P_RADIUS] : 0.1f * c->s->radius;
  float rc = c->param[P_CAUSTIC_RADIUS] > 0 ? (float)c->param[P_CAUSTIC_RADIUS] : 0.025f * c->s->radius;
  ps->r2_global = rg * rg;
  ps->r2_caustic = rc * rc;
  *out = ps;
  return VALO_OK;
}

/* What the surface reflects of uniform incident light, hemispherical-hemispherical, for
 * the radiance photons' Lo = rho E / pi (pbrt-v2's diffuse approximation): the
 * directional albedo at normal incidence, by the BSDF's own sampling (16 stratified
 * samples; deterministic). */
static rgb diffuse_reflectance(const bsdf *b) {
  rgb sum = c3(0, 0, 0);
  vec3 wo = v3(0, 0, 1);
  for (int i = 0; i < 16; i++) {
    bsdf_sample bs;
    float u1 = ((float)(i % 4) + 0.5f) / 4, u2 = ((float)(i / 4) + 0.5f) / 4;
    if (bsdf_sample_dir(b, wo, ((float)i + 0.5f) / 16, u1, u2, &bs) && !bs.delta && bs.wi.z > 0) sum = c3_add(sum, bs.weight);
  }
  return c3_scale(sum, 1.0f / 16);
}

/* ---- shooting (lightpath.c) ---- */
static int visit_global(void *user, const lp_vertex *v, void *rec) {
  (void)user;
  photon ph = {v->it->p, v->power, oct_pack(v->d), oct_pack(v->fr->n), diffuse_reflectance(v->b)};
  memcpy(rec, &ph, sizeof ph);
  return 1;
}
static int visit_caustic(void *user, const lp_vertex *v, void *rec) {
  if (!v->specular_path || v->depth == 0) return 0; /* L S+ D only */
  return visit_global(user, v, rec);
}

/* Shoots map m: `target` photons stored, powers divided by the paths emitted, the kd-tree
 * built and the photons put in tree order. */
static valo_status shoot_map(const render_ctx *c, photon_map *m, int caustic, uint64_t target, uint64_t key, valo_error *err) {
  map_free(m);
  lp_set set;
  valo_status st = lightpath_shoot(c, key, target, sizeof(photon), caustic, caustic ? visit_caustic : visit_global, NULL, &set, err);
  if (st) return st;
  photon *all = (photon *)set.rec;
  uint32_t n = set.n;
  float inv = set.emitted ? 1.0f / (float)set.emitted : 0;
  for (uint32_t i = 0; i < n; i++) all[i].power = c3_scale(all[i].power, inv);
  int rc = point_set_build(&m->tree, all, n, sizeof *all, offsetof(photon, p), (void **)&m->ph);
  free(all);
  if (rc) { map_free(m); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  m->n = n;
  return VALO_OK;
}

/* Irradiance at a radiance photon from its k nearest global photons on the same side. */
typedef struct rad_job { const photon_state *ps; rad_map *rm; const uint32_t *src; int k; float r2max; } rad_job;
static void rad_chunk(void *user, int64_t item, int thread) {
  (void)thread;
  rad_job *j = user;
  const photon_map *m = &j->ps->global;
  uint32_t lo = (uint32_t)item * 256, hi = lo + 256 < j->rm->n_pts ? lo + 256 : j->rm->n_pts;
  point_near nb[POINT_KNN_MAX];
  for (uint32_t i = lo; i < hi; i++) {
    const photon *p = &m->ph[j->src[i]];
    vec3 n = oct_unpack(p->nrm);
    int cnt = point_tree_knn(&m->tree, p->p, j->k, j->r2max, n, SQUEEZE, nb);
    float r2 = 0;
    rgb E = c3(0, 0, 0);
    for (int q = 0; q < cnt; q++) {
      r2 = fmaxf(r2, nb[q].d2);
      const photon *o = &m->ph[nb[q].i];
      if (v3_dot(oct_unpack(o->dir), n) < 0) E = c3_add(E, o->power); /* arrived on the front side */
    }
    if (cnt < j->k) r2 = j->r2max;
    j->rm->Lo[i] = r2 > 0 ? c3_scale(c3_mul(p->rho, E), 1 / (PI_F * PI_F * r2)) : c3(0, 0, 0);
  }
}

static valo_status build_radiance_photons(photon_state *ps, const render_ctx *c, valo_error *err) {
  rad_free(&ps->rad);
  const photon_map *m = &ps->global;
  uint32_t n = (m->n + RAD_STRIDE - 1) / RAD_STRIDE;
  if (n == 0) return VALO_OK;
  rad_map *rm = &ps->rad;
  uint32_t *src = malloc(n * sizeof *src);
  vec3 *pos = malloc(n * sizeof *pos);
  rm->n = malloc(n * sizeof *rm->n);
  rm->Lo = malloc(n * sizeof *rm->Lo);
  if (!src || !pos || !rm->n || !rm->Lo) { free(src); free(pos); rad_free(rm); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  for (uint32_t i = 0; i < n; i++) { src[i] = i * RAD_STRIDE; pos[i] = m->ph[src[i]].p; }
  rm->n_pts = n;
  rad_job j = {ps, rm, src, (int)c->param[P_K], ps->r2_global};
  parallel_for(c->threads, (n + 255) / 256, rad_chunk, &j);
  /* into tree order */
  for (uint32_t i = 0; i < n; i++) rm->n[i] = oct_unpack(m->ph[src[i]].nrm);
  vec3 *nn = NULL;
  rgb *lo = NULL;
  int rc = point_tree_build(&rm->tree, pos, n);
  if (!rc) rc = point_tree_gather(&rm->tree, rm->n, sizeof *rm->n, (void **)&nn);
  if (!rc) rc = point_tree_gather(&rm->tree, rm->Lo, sizeof *rm->Lo, (void **)&lo);
  free(rm->n); free(rm->Lo);
  rm->n = nn; rm->Lo = lo;
  free(src); free(pos);
  if (rc) { rad_free(rm); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  return VALO_OK;
}

/* The radiance photon nearest to p whose normal agrees with n. */
static rgb radiance_lookup(const rad_map *rm, vec3 p, vec3 n, float r2max) {
  if (rm->n_pts == 0) return c3(0, 0, 0);
  point_near nb[8];
  int cnt = point_tree_knn(&rm->tree, p, 8, r2max, n, SQUEEZE, nb);
  int best = -1;
  for (int i = 0; i < cnt; i++)
    if (v3_dot(rm->n[nb[i].i], n) > 0.5f && (best < 0 || nb[i].d2 < nb[best].d2)) best = i;
  return best < 0 ? c3(0, 0, 0) : rm->Lo[nb[best].i];
}

static valo_status photon_prepare(void *state, const render_ctx *c, int sample_index, valo_error *err) {
  photon_state *ps = state;
  uint64_t k = rng_mix64(c->seed * 0x9e3779b97f4a7c15ULL + (uint64_t)sample_index + STREAM_PHOTON);
  valo_status st = shoot_map(c, &ps->global, 0, (uint64_t)c->param[P_GLOBAL], k, err);
  if (st) return st;
  st = build_radiance_photons(ps, c, err);
  if (st) return st;
  if (!ps->has_specular) { map_free(&ps->caustic); return VALO_OK; }
  return shoot_map(c, &ps->caustic, 1, (uint64_t)c->param[P_CAUSTIC], rng_mix64(k + 1), err);
}

/* ---- radiance estimate ---- */
static rgb estimate(const photon_map *m, float r2max, int k, const isect *it, const bsdf *b, const frame *fr, vec3 wo) {
  if (m->n == 0) return c3(0, 0, 0);
  point_near nb[POINT_KNN_MAX];
  int cnt = point_tree_knn(&m->tree, it->p, k, r2max, fr->n, SQUEEZE, nb);
  if (cnt == 0) return c3(0, 0, 0);
  float r2 = 0;
  for (int i = 0; i < cnt; i++) r2 = fmaxf(r2, nb[i].d2);
  if (cnt < k) r2 = r2max; /* fewer than k in the largest disc: its area */
  vec3 wo_l = frame_to_local(fr, wo);
  rgb sum = c3(0, 0, 0);
  for (int i = 0; i < cnt; i++) {
    const photon *ph = &m->ph[nb[i].i];
    vec3 wi = v3_neg(oct_unpack(ph->dir));
    /* photons that arrived at the other side of the (geometric) surface are not ours */
    if (!bsdf_transmits(b) && v3_dot(wi, it->ng) <= 0) continue;
    rgb f = bsdf_eval(b, wo_l, frame_to_local(fr, wi));
    sum = c3_add(sum, c3_mul(f, ph->power));
  }
  return c3_scale(sum, 1 / (PI_F * r2));
}

/* Outgoing radiance at the first non-delta surface gather ray r reaches (the walk through
 * delta lobes, starting at depth `depth`), from the global map; its emission is direct
 * light, which next-event estimation counts. */
static rgb gather_radiance(const render_ctx *c, const photon_state *ps, ray r, int depth, sampler *smp, thread_stats *ts) {
  delta_walk w;
  delta_walk_start(&w, r, depth);
  if (!delta_walk_next(&w, c, smp, ts)) return c3(0, 0, 0);
  return c3_mul(w.beta, radiance_lookup(&ps->rad, w.it.p, w.fr.n, ps->r2_global));
}

/* At a camera path's first non-delta surface: direct light by NEE, the caustic map, and
 * final gathering over the radiance photons (or, with gather = 0, the global map). */
static rgb photon_shade(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, int depth, sampler *smp,
                        thread_stats *ts) {
  const photon_state *ps = c->state;
  int n = (int)c->param[P_GATHER], k = (int)c->param[P_K];
  /* no gathering (a quick preview): the global map's estimate of everything the surface
   * reflects here, direct light and caustics included */
  if (n == 0) return estimate(&ps->global, ps->r2_global, k, it, b, fr, wo);
  rgb G = c3(0, 0, 0);
  for (int g = 0; g < n; g++) {
    /* gather ray g of sample i is point i n + g of one stratified stream */
    sampler gs = sampler_child(smp, (uint32_t)g, (uint32_t)n);
    bsdf_sample bs;
    vec3 wi;
    if (!sample_bsdf_world(it, b, fr, wo, &gs, ts, &bs, &wi) || bs.delta) continue; /* delta lobes: the camera chain */
    G = c3_add(G, c3_mul(bs.weight, gather_radiance(c, ps, spawn_ray(it, wi), depth + 1, &gs, ts)));
  }
  sampler_set_dim(smp, sdim_bounce(depth, SDIM_LIGHT_PICK));
  rgb L = estimate_direct_nomis(c, it, b, fr, wo, smp, ts);
  if (ps->caustic.n) L = c3_add(L, estimate(&ps->caustic, ps->r2_caustic, k, it, b, fr, wo));
  return c3_add(L, c3_scale(G, 1.0f / (float)n));
}

static rgb photon_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) { return li_shade_through_delta(c, r, smp, ts, photon_shade); }

const integrator_ops integrator_photon = {
    .name = "photon",
    .description = "photon mapping (Jensen): NEE for direct light, a caustic map, final gathering over a global map; a fresh photon set per pass",
    .kind = INTEGRATOR_RAY,
    .params = photon_params,
    .li = photon_li,
    .create = photon_create,
    .prepare = photon_prepare,
    .destroy = photon_destroy,
};
