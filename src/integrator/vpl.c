/* vpl.c — owns `vpl` (digest 002; the light shooting and gathering it shares with vsl are
 * in vpl_common.c):
 *  - instant radiosity (Keller 1997). prepare (before every sample index) traces
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
 *    that is the direct light). With it `vpl` is unbiased again. */
#include "integrator/vpl_common.h"
#include "core/streams.h"
#include "core/sampling.h"
#include "core/error.h"
#include <math.h>
#include <stdlib.h>

typedef struct vpl_state { vlight_set set; float c; } vpl_state;

enum { P_COUNT, P_DIRECT, P_CLAMP, P_COMPENSATE, P_SHADOW };
static const integrator_param vpl_params[] = {
    {"count", IPARAM_INT, 512, 1, 1e6, "virtual point lights per pass"},
    {"direct", IPARAM_INT, 4, 1, 1024, "next-event samples of direct light per camera sample (cheap beside the lights' shadow rays)"},
    {"clamp", IPARAM_FLOAT, 0.2, 0, 10,
     "clamping distance as a fraction of the scene's bounding-sphere radius R: G f_r is limited to 1 / (clamp R)^2; 0 = no clamping"},
    {"compensate", IPARAM_INT, 0, 0, 1, "1: add back what clamping removed by path tracing (Kollig & Keller 2004): unbiased"},
    {"shadow_rays", IPARAM_INT, 32, 0, 1e6,
     "0: one shadow ray to every light; S > 0: S shadow rays to lights drawn in proportion to their unshadowed contribution"},
    {NULL, IPARAM_INT, 0, 0, 0, NULL}};
static void vpl_destroy(void *st) {
  vpl_state *vs = st;
  if (!vs) return;
  vlight_free(&vs->set);
  free(vs);
}

static valo_status vpl_create(const render_ctx *c, void **out, valo_error *err) {
  vpl_state *vs = calloc(1, sizeof *vs);
  if (!vs) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  if (c->param[P_CLAMP] > 0) {
    float d = (float)c->param[P_CLAMP] * c->s->radius;
    vs->c = 1 / (d * d);
  }
  if (c->param[P_COMPENSATE] > 0 && !(vs->c > 0)) log_note("vpl: compensate=1 without clamping has nothing to compensate");
  *out = vs;
  return VALO_OK;
}

static valo_status vpl_prepare(void *state, const render_ctx *c, int sample_index, valo_error *err) {
  vpl_state *vs = state;
  return vlight_shoot(&vs->set, c, sample_index, c->param[P_COUNT], err);
}

/* Unshadowed contribution of point light i at x, G f_r clamped to c. */
static rgb vpl_contrib(const render_ctx *c, const vlight_set *s, uint32_t i, const isect *it, const bsdf *b, const frame *fr, vec3 wo_l,
                       sampler *smp) {
  (void)smp;
  const vpl_state *vs = c->state;
  const vpl *l = &s->v[i];
  vec3 d = v3_sub(l->p, it->p);
  float d2 = v3_len2(d);
  if (!(d2 > 0)) return c3(0, 0, 0);
  float dist = sqrtf(d2);
  vec3 w = v3_scale(d, 1 / dist); /* x -> light */
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

/* Indirect light at x from the pass's lights: every light with a shadow ray each, or
 * (shadow_rays = S > 0) S lights drawn by systematic sampling of the distribution
 * proportional to their unshadowed contributions' channel sum, each weighted 1 / (S p):
 * unbiased for the same sum, and where nearly every light is visible nearly as good as
 * all of them for S shadow rays. */
#define VPL_SAMPLED_MAX 4096
static rgb gather(const render_ctx *c, const vpl_state *vs, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                  thread_stats *ts) {
  const vlight_set *s = &vs->set;
  int S = (int)c->param[P_SHADOW];
  if (!(S > 0 && s->n > (uint32_t)S && s->n <= VPL_SAMPLED_MAX)) return vlight_gather_all(c, s, vpl_contrib, it, b, fr, wo, smp, ts);
  rgb sum = c3(0, 0, 0);
  vec3 wo_l = frame_to_local(fr, wo);
  rgb con[VPL_SAMPLED_MAX];
  float cdf[VPL_SAMPLED_MAX];
  double total = 0;
  for (uint32_t i = 0; i < s->n; i++) {
    con[i] = vpl_contrib(c, s, i, it, b, fr, wo_l, smp);
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
    i = vlight_systematic(cdf, s->n, i, m, S, u0, total);
    float w = con[i].r + con[i].g + con[i].b, p = (float)(w / total);
    if (!(p > 0)) continue;
    if (ctx_segment_blocked(c, it, s->v[i].p, s->v[i].ng, ts)) continue;
    sum = c3_add(sum, c3_scale(con[i], 1 / ((float)S * p)));
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

/* At a camera path's first non-delta surface: direct light, the pass's lights, and
 * compensation. */
static rgb vpl_shade(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, int depth, sampler *smp,
                     thread_stats *ts) {
  const vpl_state *vs = c->state;
  rgb L = vlight_direct(c, (int)c->param[P_DIRECT], it, b, fr, wo, depth, smp, ts);
  L = c3_add(L, gather(c, vs, it, b, fr, wo, smp, ts));
  if (vs->c > 0 && c->param[P_COMPENSATE] > 0) L = c3_add(L, compensate(c, vs, it, b, fr, wo, smp, ts));
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
