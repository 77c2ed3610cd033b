/* vpl.c — owns the many-light integrators of seed 002 (digest 002):
 *  - `vpl`: instant radiosity (Keller 1997). prepare (before every sample index) traces
 *    light paths (lightpath.c: lights by power, Owen-scrambled Sobol, adjoint BSDF
 *    sampling, Russian roulette) until `count` virtual point lights are stored, one at
 *    every surface hit with a non-delta lobe (delta surfaces pass the path on): position,
 *    normal, the direction the light arrived from, flux, and the BSDF and shading frame
 *    there. A camera ray follows delta lobes (counting emission); at its first non-delta
 *    surface x, L = direct light by next-event estimation + sum over the pass's VPLs of
 *    Phi f_v(x <- y) f_x G V, one shadow ray each, both BSDFs evaluated (glossy ends too).
 *    Unbiased without clamping; each pass uses a fresh, independent VPL set.
 *  - clamping: G f_r (f_r the larger channel of f_x) is limited to c = 1 / (clamp R)^2, R
 *    the scene's bounding-sphere radius (clamp is a fraction of the scene's size, as
 *    Mitsuba 0.6's `clamping`): as if no VPL were nearer than clamp R to a surface facing
 *    it. Biased: darkens corners.
 *  - bias compensation (Kollig & Keller 2004): the clamped energy,
 *    int Li f_r cos (1 - w1) dw with w1 = min(1, c / (G f_r)), added back by one BSDF-
 *    sampled ray per camera sample (limited to the distance at which G f_r can exceed c)
 *    whose hit y' reflects radiance estimated by the path tracer (its emission left out:
 *    that is the direct light). With it `vpl` is unbiased again.
 *  - `vsl`: virtual spherical lights (Hasan et al. 2009): each VPL's flux spread over a
 *    sphere of radius r (the distance to its k-th nearest VPL, or the `radius` option):
 *    Lo(x, wo) = V(x <-> p) Phi / (pi r^2) int_cone f_x(l -> wo) cos_x f_v(wi -> -l) cos_p dl
 *    over the cone the sphere subtends at x (the whole sphere of directions when x is
 *    inside), estimated with `cone_samples` directions drawn uniformly in the cone. No
 *    1/d^2 singularity: no splotches on glossy surfaces; consistent as count grows. */
#include "core/streams.h"
#include "integrator/camera_path.h"
#include "integrator/integrator.h"
#include "integrator/lightpath.h"
#include "geometry/pointtree.h"
#include "core/sampling.h"
#include "core/error.h"
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

typedef struct vpl {
  vec3 p, n;        /* position and the shading normal faced to where the light came from */
  vec3 wi;          /* unit direction towards where the light came from */
  rgb power;        /* flux, divided by the paths emitted */
  bsdf b;
  frame fr;
  vec3 ng;          /* geometric normal (faced like n) */
  float radius;     /* vsl: the sphere's radius */
} vpl;

typedef struct vpl_state { vpl *v; uint32_t n; int spherical; float c; uint64_t paths; } vpl_state;

enum { P_COUNT, P_DIRECT, P_CLAMP, P_COMPENSATE, P_SHADOW };
static const integrator_param vpl_params[] = {
    {"count", IPARAM_INT, 1024, 1, 1e6, "virtual point lights per pass (each costs one shadow ray per camera sample)"},
    {"direct", IPARAM_INT, 4, 1, 1024, "next-event samples of direct light per camera sample (cheap beside the lights' shadow rays)"},
    {"clamp", IPARAM_FLOAT, 0.1, 0, 10,
     "clamping distance as a fraction of the scene's bounding-sphere radius R: G f_r is limited to 1 / (clamp R)^2; 0 = no clamping"},
    {"compensate", IPARAM_INT, 0, 0, 1, "1: add back what clamping removed by path tracing (Kollig & Keller 2004): unbiased"},
    {"shadow_rays", IPARAM_INT, 0, 0, 1e6,
     "0: one shadow ray to every light; S > 0: S shadow rays to lights drawn in proportion to their unshadowed contribution"},
    {NULL, IPARAM_INT, 0, 0, 0, NULL}};
enum { S_COUNT, S_DIRECT, S_RADIUS, S_K, S_CONE };
static const integrator_param vsl_params[] = {
    {"count", IPARAM_INT, 1024, 1, 1e6, "virtual spherical lights per pass"},
    {"direct", IPARAM_INT, 4, 1, 1024, "next-event samples of direct light per camera sample"},
    {"radius", IPARAM_FLOAT, 0, 0, 1e30, "sphere radius in scene units; 0 = automatic, the distance to the k-th nearest light"},
    {"k", IPARAM_INT, 10, 1, 256, "which nearest light sets the automatic radius"},
    {"cone_samples", IPARAM_INT, 1, 1, 64, "directions sampled in the cone per light and camera sample"},
    {NULL, IPARAM_INT, 0, 0, 0, NULL}};

static void vpl_destroy(void *st) {
  vpl_state *vs = st;
  if (!vs) return;
  free(vs->v);
  free(vs);
}

static valo_status create_common(const render_ctx *c, void **out, int spherical, valo_error *err) {
  vpl_state *vs = calloc(1, sizeof *vs);
  if (!vs) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  vs->spherical = spherical;
  if (!spherical && c->param[P_CLAMP] > 0) {
    float d = (float)c->param[P_CLAMP] * c->s->radius;
    vs->c = 1 / (d * d);
  }
  if (!spherical && c->param[P_COMPENSATE] > 0 && !(vs->c > 0))
    log_note("vpl: compensate=1 without clamping has nothing to compensate");
  *out = vs;
  return VALO_OK;
}
static valo_status vpl_create(const render_ctx *c, void **out, valo_error *err) { return create_common(c, out, 0, err); }
static valo_status vsl_create(const render_ctx *c, void **out, valo_error *err) { return create_common(c, out, 1, err); }

static int visit(void *user, const lp_vertex *v, void *rec) {
  (void)user;
  vpl l;
  memset(&l, 0, sizeof l);
  l.p = v->it->p;
  l.n = v->fr->n;
  l.ng = v3_dot(v->it->ng, v->fr->n) < 0 && !bsdf_transmits(v->b) ? v3_neg(v->it->ng) : v->it->ng;
  l.wi = v3_neg(v->d);
  l.power = v->power;
  l.b = *v->b;
  l.fr = *v->fr;
  memcpy(rec, &l, sizeof l);
  return 1;
}

static valo_status vpl_prepare(void *state, const render_ctx *c, int sample_index, valo_error *err) {
  vpl_state *vs = state;
  free(vs->v);
  vs->v = NULL;
  vs->n = 0;
  uint64_t key = rng_mix64(c->seed * 0x9e3779b97f4a7c15ULL + (uint64_t)sample_index + STREAM_VPL);
  lp_set set;
  if (vs->paths == 0) {
    /* How many paths give `count` lights: measured once on a pilot set of its own (so the
     * number of paths does not depend on the paths used: the estimate stays unbiased). */
    valo_status st = lightpath_shoot_paths(c, rng_mix64(c->seed + STREAM_VPL_PILOT), 16384, sizeof(vpl), visit, NULL, &set, err);
    if (st) return st;
    free(set.rec);
    double per_path = set.emitted ? (double)set.n / (double)set.emitted : 0;
    vs->paths = per_path > 0 ? (uint64_t)ceil(c->param[0] / per_path) : (uint64_t)c->param[0];
    if (vs->paths < 1) vs->paths = 1;
  }
  valo_status st = lightpath_shoot_paths(c, key, vs->paths, sizeof(vpl), visit, NULL, &set, err);
  if (st) return st;
  vs->v = (vpl *)set.rec;
  vs->n = set.n;
  float inv = set.emitted ? 1.0f / (float)set.emitted : 0;
  for (uint32_t i = 0; i < vs->n; i++) vs->v[i].power = c3_scale(vs->v[i].power, inv);
  if (vs->spherical && vs->n) {
    if (c->param[S_RADIUS] > 0) {
      for (uint32_t i = 0; i < vs->n; i++) vs->v[i].radius = (float)c->param[S_RADIUS];
    } else {
      /* the distance to the k-th nearest light of the pass */
      point_tree t;
      if (point_set_build(&t, vs->v, vs->n, sizeof *vs->v, offsetof(vpl, p), NULL)) return err_set(err, VALO_ERR_NOMEM, "out of memory");
      int k = (int)c->param[S_K] + 1; /* the light itself is its own nearest */
      point_near nb[POINT_KNN_MAX];
      for (uint32_t i = 0; i < vs->n; i++) {
        int cnt = point_tree_knn(&t, vs->v[i].p, k, INFINITY, v3(0, 0, 1), 0, nb);
        float r2 = 0;
        for (int q = 0; q < cnt; q++) r2 = fmaxf(r2, nb[q].d2);
        vs->v[i].radius = r2 > 0 ? sqrtf(r2) : 0.01f * c->s->radius;
      }
      point_tree_free(&t);
    }
  }
  return VALO_OK;
}

/* f_v: what VPL l reflects towards direction w (unit, leaving l); 0 when w is on the
 * side the light did not arrive on (opaque BSDFs). */
static rgb vpl_reflect(const vpl *l, vec3 w) {
  if (!bsdf_transmits(&l->b) && (v3_dot(w, l->n) <= 0 || v3_dot(w, l->ng) <= 0)) return c3(0, 0, 0);
  return bsdf_eval(&l->b, frame_to_local(&l->fr, w), frame_to_local(&l->fr, l->wi));
}

/* Unshadowed contribution of light l at x (0 when it cannot reach x). */
static rgb vpl_contrib(const render_ctx *c, const vpl_state *vs, const vpl *l, uint32_t i, const isect *it, const bsdf *b, const frame *fr,
                       vec3 wo_l, sampler *smp) {
  vec3 d = v3_sub(l->p, it->p);
  float d2 = v3_len2(d);
  if (!(d2 > 0)) return c3(0, 0, 0);
  float dist = sqrtf(d2);
  vec3 w = v3_scale(d, 1 / dist); /* x -> light */
  if (!vs->spherical) {
    float cos_x = fabsf(v3_dot(w, fr->n));
    rgb fx = bsdf_eval(b, wo_l, frame_to_local(fr, w));
    if (c3_black(fx)) return c3(0, 0, 0);
    if (!bsdf_transmits(b) && v3_dot(w, it->ng) <= 0) return c3(0, 0, 0);
    rgb fv = vpl_reflect(l, v3_neg(w));
    if (c3_black(fv)) return c3(0, 0, 0);
    float G = cos_x * fabsf(v3_dot(w, l->n)) / d2;
    float scale = G;
    if (vs->c > 0) {
      float K = G * c3_max(fx);
      if (K > vs->c) scale *= vs->c / K; /* min(c, G f_r) */
    }
    return c3_scale(c3_mul(c3_mul(fx, fv), l->power), scale);
  }
  /* the cone the sphere subtends at x (every direction from inside it) */
  int cone = (int)c->param[S_CONE];
  float r = l->radius, cos_max = dist > r ? sqrtf(fmaxf(0.0f, 1 - r * r / d2)) : -1;
  float omega = 2 * PI_F * (1 - cos_max);
  frame cf = frame_from_n(w);
  rgb acc = c3(0, 0, 0);
  sampler ls = sampler_child(smp, i, vs->n);
  sampler_set_dim(&ls, CDIM_VSL_CONE);
  for (int m = 0; m < cone; m++) {
    float u1, u2;
    sampler_2d(&ls, &u1, &u2);
    vec3 dir = frame_to_world(&cf, sample_uniform_cone(u1, u2, cos_max));
    if (!bsdf_transmits(b) && v3_dot(dir, it->ng) <= 0) continue;
    rgb fx = bsdf_eval(b, wo_l, frame_to_local(fr, dir));
    if (c3_black(fx)) continue;
    rgb fv = vpl_reflect(l, v3_neg(dir));
    if (c3_black(fv)) continue;
    float cc = fabsf(v3_dot(dir, fr->n)) * fabsf(v3_dot(dir, l->n));
    acc = c3_add(acc, c3_scale(c3_mul(fx, fv), cc));
  }
  if (c3_black(acc)) return c3(0, 0, 0);
  return c3_scale(c3_mul(acc, l->power), omega / ((float)cone * PI_F * r * r));
}

/* Indirect light at x from the pass's lights: every light with a shadow ray each, or
 * (vpl, shadow_rays = S > 0) S lights drawn by systematic sampling of the distribution
 * proportional to their unshadowed contributions' channel sum, each weighted 1 / (S p):
 * unbiased for the same sum, and where nearly every light is visible nearly as good as
 * all of them for S shadow rays. */
#define VPL_SAMPLED_MAX 4096
static rgb gather(const render_ctx *c, const vpl_state *vs, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                  thread_stats *ts) {
  rgb sum = c3(0, 0, 0);
  vec3 wo_l = frame_to_local(fr, wo);
  int S = vs->spherical ? 0 : (int)c->param[P_SHADOW];
  if (S > 0 && vs->n > (uint32_t)S && vs->n <= VPL_SAMPLED_MAX) {
    rgb con[VPL_SAMPLED_MAX];
    float cdf[VPL_SAMPLED_MAX];
    double total = 0;
    for (uint32_t i = 0; i < vs->n; i++) {
      con[i] = vpl_contrib(c, vs, &vs->v[i], i, it, b, fr, wo_l, smp);
      float w = c3_finite(con[i]) ? con[i].r + con[i].g + con[i].b : 0;
      total += w > 0 ? w : 0;
      cdf[i] = (float)total;
    }
    if (!(total > 0)) return sum;
    sampler us = sampler_child(smp, 0, 1);
    sampler_set_dim(&us, CDIM_VPL_SAMPLED);
    float u0 = sampler_1d(&us);
    uint32_t i = 0;
    for (int m = 0; m < S; m++) {
      float target = (float)(((float)m + u0) / (float)S * total);
      while (i + 1 < vs->n && cdf[i] <= target) i++;
      float w = con[i].r + con[i].g + con[i].b, p = (float)(w / total);
      if (!(p > 0)) continue;
      if (ctx_segment_blocked(c, it, vs->v[i].p, vs->v[i].ng, ts)) continue;
      sum = c3_add(sum, c3_scale(con[i], 1 / ((float)S * p)));
    }
    return sum;
  }
  for (uint32_t i = 0; i < vs->n; i++) {
    const vpl *l = &vs->v[i];
    rgb contrib = vpl_contrib(c, vs, l, i, it, b, fr, wo_l, smp);
    if (c3_black(contrib) || !c3_finite(contrib)) continue;
    if (ctx_segment_blocked(c, it, l->p, l->ng, ts)) continue;
    sum = c3_add(sum, contrib);
  }
  return sum;
}

/* Kollig & Keller's compensation: one BSDF-sampled ray within the distance at which
 * G f_r can exceed c; (1 - w1) of what its hit reflects (path-traced). */
static rgb compensate(const render_ctx *c, const vpl_state *vs, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                      thread_stats *ts) {
  sampler cs = sampler_child(smp, 0, 1);
  sampler_set_dim(&cs, CDIM_VPL_COMPENSATE);
  bsdf_sample bs;
  vec3 wi, wo_l = frame_to_local(fr, wo);
  if (!sample_bsdf_world(it, b, fr, wo, &cs, ts, &bs, &wi) || bs.delta || !(bs.pdf > 0)) return c3(0, 0, 0);
  rgb f = bsdf_eval(b, wo_l, bs.wi);
  float cos_x = fabsf(bs.wi.z), fmax = c3_max(f);
  if (!(fmax > 0)) return c3(0, 0, 0);
  /* G f_r <= f_r / d^2 exceeds c only within d < sqrt(f_r / c) */
  ray r = spawn_ray(it, wi);
  r.tmax = sqrtf(fmax / vs->c);
  hit h;
  if (!ctx_intersect(c, &r, &h, ts)) return c3(0, 0, 0);
  isect y;
  isect_from_hit(c->s, &r, &h, &y);
  float G = cos_x * fabsf(v3_dot(wi, y.ns)) / (h.t * h.t);
  float K = G * fmax;
  if (!(K > vs->c)) return c3(0, 0, 0);
  float w = 1 - vs->c / K;
  ray full = spawn_ray(it, wi);
  rgb Lr = path_radiance(c, full, &cs, ts, 0);
  return c3_scale(c3_mul(bs.weight, Lr), w);
}

/* At a camera path's first non-delta surface: direct light (`direct` NEE samples,
 * stratified together across the pixel's samples), the pass's lights, and compensation. */
static rgb vpl_shade(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, int depth, sampler *smp,
                     thread_stats *ts) {
  const vpl_state *vs = c->state;
  int nd = (int)c->param[P_DIRECT]; /* the same index in both tables */
  rgb L = c3(0, 0, 0);
  for (int k = 0; k < nd; k++) {
    sampler ds = sampler_child(smp, (uint32_t)k, (uint32_t)nd);
    sampler_set_dim(&ds, sdim_bounce(depth, SDIM_LIGHT_PICK));
    L = c3_add(L, estimate_direct_nomis(c, it, b, fr, wo, &ds, ts));
  }
  L = c3_add(c3_scale(L, 1.0f / (float)nd), gather(c, vs, it, b, fr, wo, smp, ts));
  if (!vs->spherical && vs->c > 0 && c->param[P_COMPENSATE] > 0) L = c3_add(L, compensate(c, vs, it, b, fr, wo, smp, ts));
  return L;
}

static rgb vpl_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) { return li_shade_through_delta(c, r, smp, ts, vpl_shade); }

const integrator_ops integrator_vpl = {
    .name = "vpl",
    .description = "instant radiosity (Keller 1997): virtual point lights from light paths, clamping, bias compensation (Kollig & Keller 2004)",
    .kind = INTEGRATOR_RAY,
    .params = vpl_params,
    .li = vpl_li,
    .create = vpl_create,
    .prepare = vpl_prepare,
    .destroy = vpl_destroy,
};
const integrator_ops integrator_vsl = {
    .name = "vsl",
    .description = "virtual spherical lights (Hasan et al. 2009): each VPL's flux spread over a sphere, integrated over the cone it subtends",
    .kind = INTEGRATOR_RAY,
    .params = vsl_params,
    .li = vpl_li,
    .create = vsl_create,
    .prepare = vpl_prepare,
    .destroy = vpl_destroy,
};
