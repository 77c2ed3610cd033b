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
 *    surface through specular ones), in the caustic map, its paths leaving area and point
 *    lights only toward a sphere around every surface that may have a delta lobe (Jensen's
 *    projection maps: a path that misses it cannot be L S+ D). Emission runs in rounds sized
 *    from the rate seen so far until each map holds its target; rounds are split into
 *    fixed chunks whose photons are concatenated in chunk order, so the maps are the same
 *    for any thread count. Both maps live in the shared point kd-tree.
 *  - li: camera rays follow delta lobes (counting emission); at the first surface with a
 *    non-delta lobe, L = direct light by NEE + the caustic map's estimate + indirect
 *    light by final gathering: `gather` BSDF-sampled rays whose hits take the global
 *    map's estimate of outgoing radiance (after up to 4 delta bounces; emission found by
 *    gather rays is left to NEE and the caustic map).
 *  - radiance estimate, progressive (Knaus & Zwicker 2011, probabilistic progressive
 *    photon mapping): pass i (sample index i, 0-based) estimates L = sum f(wo, wp) Phi_p
 *    / (pi r_i^2) over the photons of its own maps within r_i, distance measured in a
 *    disc squeezed along the surface normal (|v|^2 + 16 (v.n)^2) against leaks at
 *    corners and through thin walls; r_i^2 = r_0^2 prod_{j=1..i} (j + alpha) / (j + 1)
 *    shrinks as i^(alpha-1), so the average over passes converges: both the blur (bias)
 *    and the variance go to zero. r_0 per map: `radius` / `caustic_radius`, or the
 *    median distance from a photon of the pass to its k-th nearest neighbour.
 * Biased (blur of the density estimate) at any finite time, consistent: the bias shrinks
 * with the passes. */
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

enum { P_GLOBAL, P_CAUSTIC, P_K, P_RADIUS, P_GATHER, P_CAUSTIC_RADIUS, P_ALPHA, P_AIM };
static const integrator_param photon_params[] = {
    {"global", IPARAM_INT, 100000, 0, 1e8, "photons stored in the global map per pass (pbrt-v2's default count)"},
    {"caustic", IPARAM_INT, 20000, 0, 1e8, "photons stored in the caustic map per pass"},
    {"k", IPARAM_INT, 50, 1, POINT_KNN_MAX, "photons the automatic first-pass radius holds (the median over the map)"},
    {"radius", IPARAM_FLOAT, 0, 0, 1e30, "first pass's search radius, global map; 0 = automatic (k photons, at most 1/10 of the bounding-sphere radius)"},
    {"gather", IPARAM_INT, 32, 0, 4096, "final-gathering rays per camera sample (0: use the global map at the first hit)"},
    {"caustic_radius", IPARAM_FLOAT, 0, 0, 1e30, "first pass's search radius, caustic map; 0 = automatic (k photons, at most 1/40 of the bounding-sphere radius)"},
    {"alpha", IPARAM_FLOAT, 0.7, 0.05, 1, "radius reduction per pass (Knaus & Zwicker's alpha): r_i^2 = r_0^2 prod (j + alpha) / (j + 1); 1 keeps the radius"},
    {"aim", IPARAM_INT, 1, 0, 1, "1: caustic photons leave area and point lights only toward a sphere around the specular surfaces (Jensen's projection maps); 0: in every direction"},
    {NULL, IPARAM_INT, 0, 0, 0, NULL}};

#define SQUEEZE 16.0f

/* A stored photon: 28 bytes. */
typedef struct photon { vec3 p; rgb power; uint32_t dir; } photon; /* dir: octahedral 2x16 bits */

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

/* A map of one pass and the search radius its estimates use (r2: squared). */
typedef struct photon_map { point_tree tree; photon *ph; uint32_t n; float r2; } photon_map;

typedef struct photon_state {
  photon_map global, caustic;
  int has_specular;        /* any delta lobe in the scene: else no caustic map */
  lp_aim aim;              /* a sphere around every triangle with a delta lobe: caustic photons are aimed at it */
  float r2cap_global, r2cap_caustic; /* the automatic first radius's bound */
} photon_state;

static void map_free(photon_map *m) {
  point_tree_free(&m->tree);
  free(m->ph);
  memset(m, 0, sizeof *m);
}

static void photon_destroy(void *st) {
  photon_state *ps = st;
  if (!ps) return;
  map_free(&ps->global);
  map_free(&ps->caustic);
  free(ps);
}

static valo_status photon_create(const render_ctx *c, void **out, valo_error *err) {
  photon_state *ps = calloc(1, sizeof *ps);
  if (!ps) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  const scene *s = c->s;
  unsigned char *spec = calloc(s->nmats ? s->nmats : 1, 1);
  if (!spec) { free(ps); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  for (uint32_t i = 0; i < s->nmats; i++) {
    bsdf b = bsdf_from_material(&s->mats[i]);
    ps->has_specular |= b.type == BSDF_MIRROR || b.type == BSDF_DIELECTRIC || b.type == BSDF_CONDUCTOR || b.type == BSDF_THIN_DIELECTRIC;
    /* inside the aim: every material that may have a delta lobe (all but the purely smooth
     * kinds; a blend may pick a delta material) */
    spec[i] = s->mats[i].type == MAT_BLEND || !(b.type == BSDF_DIFFUSE || b.type == BSDF_PHONG || b.type == BSDF_ROUGH_CONDUCTOR ||
                                                 b.type == BSDF_ROUGH_DIELECTRIC || b.type == BSDF_ROUGH_PLASTIC);
  }
  /* the aim: the bounding box of the triangles with a delta lobe, as a sphere */
  vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
  for (uint32_t t = 0; t < s->ntris; t++) {
    if (!spec[s->tri_mat[t]]) continue;
    for (int k = 0; k < 3; k++) {
      vec3 p = s->pos[s->idx[3 * t + k]];
      lo = v3(fminf(lo.x, p.x), fminf(lo.y, p.y), fminf(lo.z, p.z));
      hi = v3(fmaxf(hi.x, p.x), fmaxf(hi.y, p.y), fmaxf(hi.z, p.z));
    }
  }
  free(spec);
  ps->aim.c = v3_scale(v3_add(lo, hi), 0.5f);
  ps->aim.r = lo.x <= hi.x ? 0.5f * v3_len(v3_sub(hi, lo)) * 1.0001f + 1e-6f * s->radius : INFINITY;
  float rg = 0.1f * c->s->radius, rc = 0.025f * c->s->radius;
  ps->r2cap_global = rg * rg;
  ps->r2cap_caustic = rc * rc;
  *out = ps;
  return VALO_OK;
}

/* ---- shooting (lightpath.c) ---- */
static int visit_global(void *user, const lp_vertex *v, void *rec) {
  (void)user;
  photon ph = {v->it->p, v->power, oct_pack(v->d)};
  memcpy(rec, &ph, sizeof ph);
  return 1;
}
static int visit_caustic(void *user, const lp_vertex *v, void *rec) {
  if (!v->specular_path || v->depth == 0) return 0; /* L S+ D only */
  return visit_global(user, v, rec);
}

/* Shoots map m: `target` photons stored, powers divided by the paths emitted, the kd-tree
 * built and the photons put in tree order. */
static valo_status shoot_map(const render_ctx *c, photon_map *m, int caustic, const lp_aim *aim, uint64_t target, uint64_t key, valo_error *err) {
  map_free(m);
  lp_set set;
  valo_status st = lightpath_shoot(c, key, target, sizeof(photon), caustic, aim, caustic ? visit_caustic : visit_global, NULL, &set, err);
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

/* The radius of pass i: r_0^2 prod_{j=1..i} (j + alpha) / (j + 1) (Knaus & Zwicker),
 * through lgamma: Gamma(i + 1 + alpha) / Gamma(1 + alpha) / (i + 1)!. */
static double radius_shrink(int pass, double alpha) {
  if (pass <= 0 || alpha >= 1) return 1;
  return exp(lgamma(pass + 1 + alpha) - lgamma(1 + alpha) - lgamma(pass + 2.0));
}

/* The automatic first radius: the median over (up to) 511 photons spread through the map
 * of the squared distance to their k-th nearest neighbour, at most r2cap. */
#define RADIUS_PROBES 511
static int cmp_float(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}
static float auto_radius2(const photon_map *m, int k, float r2cap) {
  if (m->n == 0) return r2cap;
  point_near nb[POINT_KNN_MAX];
  float d2[RADIUS_PROBES];
  int np = m->n < RADIUS_PROBES ? (int)m->n : RADIUS_PROBES;
  for (int i = 0; i < np; i++) {
    const photon *p = &m->ph[(uint64_t)i * m->n / (uint64_t)np];
    int cnt = point_tree_knn(&m->tree, p->p, k, r2cap, v3(0, 0, 1), 0, nb);
    float r2 = 0;
    for (int q = 0; q < cnt; q++) r2 = fmaxf(r2, nb[q].d2);
    d2[i] = cnt < k ? r2cap : r2; /* fewer than k within the bound: the bound */
  }
  qsort(d2, (size_t)np, sizeof *d2, cmp_float);
  return d2[np / 2];
}

static valo_status photon_prepare(void *state, const render_ctx *c, int sample_index, valo_error *err) {
  photon_state *ps = state;
  uint64_t key = rng_mix64(c->seed * 0x9e3779b97f4a7c15ULL + (uint64_t)sample_index + STREAM_PHOTON);
  float shrink = (float)radius_shrink(sample_index, c->param[P_ALPHA]);
  int k = (int)c->param[P_K];
  valo_status st = shoot_map(c, &ps->global, 0, NULL, (uint64_t)c->param[P_GLOBAL], key, err);
  if (st) return st;
  float r = (float)c->param[P_RADIUS];
  ps->global.r2 = (r > 0 ? r * r : auto_radius2(&ps->global, k, ps->r2cap_global)) * shrink;
  if (!ps->has_specular) { map_free(&ps->caustic); return VALO_OK; }
  st = shoot_map(c, &ps->caustic, 1, c->param[P_AIM] > 0 ? &ps->aim : NULL, (uint64_t)c->param[P_CAUSTIC], rng_mix64(key + 1), err);
  if (st) return st;
  r = (float)c->param[P_CAUSTIC_RADIUS];
  ps->caustic.r2 = (r > 0 ? r * r : auto_radius2(&ps->caustic, k, ps->r2cap_caustic)) * shrink;
  return VALO_OK;
}

/* ---- radiance estimate ---- */
typedef struct est_q {
  const photon *ph;
  const bsdf *b;
  const frame *fr;
  vec3 q, n, ng, wo_l;
  float r2;
  int transmits;
  rgb sum;
} est_q;
static void est_visit(void *user, uint32_t i, float d2) {
  est_q *e = user;
  const photon *ph = &e->ph[i];
  float dn = v3_dot(v3_sub(ph->p, e->q), e->n);
  if (d2 + SQUEEZE * dn * dn >= e->r2) return; /* outside the squeezed disc */
  vec3 wi = v3_neg(oct_unpack(ph->dir));
  /* photons that arrived at the other side of the (geometric) surface are not ours */
  if (!e->transmits && v3_dot(wi, e->ng) <= 0) return;
  e->sum = c3_add(e->sum, c3_mul(bsdf_eval(e->b, e->wo_l, frame_to_local(e->fr, wi)), ph->power));
}
/* Map m's estimate of the radiance leaving it toward wo: its photons within the pass's
 * radius, over the disc's area. */
static rgb estimate(const photon_map *m, const isect *it, const bsdf *b, const frame *fr, vec3 wo) {
  if (m->n == 0 || !(m->r2 > 0)) return c3(0, 0, 0);
  est_q e = {m->ph, b, fr, it->p, fr->n, it->ng, frame_to_local(fr, wo), m->r2, bsdf_transmits(b), c3(0, 0, 0)};
  point_tree_radius(&m->tree, it->p, m->r2, est_visit, &e);
  return c3_scale(e.sum, 1 / (PI_F * m->r2));
}

/* Outgoing radiance at the first non-delta surface gather ray r reaches (the walk through
 * delta lobes, starting at depth `depth`), from the global map; its emission is direct
 * light, which next-event estimation counts. */
static rgb gather_radiance(const render_ctx *c, const photon_state *ps, ray r, int depth, sampler *smp, thread_stats *ts) {
  delta_walk w;
  delta_walk_start(&w, r, depth);
  if (!delta_walk_next(&w, c, smp, ts)) return c3(0, 0, 0);
  return c3_mul(w.beta, estimate(&ps->global, &w.it, &w.b, &w.fr, w.wo));
}

/* At a camera path's first non-delta surface: direct light by NEE, the caustic map, and
 * final gathering over the radiance photons (or, with gather = 0, the global map). */
static rgb photon_shade(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, int depth, sampler *smp,
                        thread_stats *ts) {
  const photon_state *ps = c->state;
  int n = (int)c->param[P_GATHER];
  /* no gathering (a quick preview): the global map's estimate of everything the surface
   * reflects here, direct light and caustics included */
  if (n == 0) return estimate(&ps->global, it, b, fr, wo);
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
  if (ps->caustic.n) L = c3_add(L, estimate(&ps->caustic, it, b, fr, wo));
  return c3_add(L, c3_scale(G, 1.0f / (float)n));
}

static rgb photon_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) { return li_shade_through_delta(c, r, smp, ts, photon_shade); }

const integrator_ops integrator_photon = {
    .name = "photon",
    .description = "photon mapping (Jensen): NEE for direct light, a caustic map, final gathering over a global map; a fresh photon set per pass, its radius shrinking (progressive, consistent)",
    .kind = INTEGRATOR_RAY,
    .params = photon_params,
    .li = photon_li,
    .create = photon_create,
    .prepare = photon_prepare,
    .destroy = photon_destroy,
};
