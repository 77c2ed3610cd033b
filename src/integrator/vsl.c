/* vsl.c — owns `vsl` (digest 002; the light shooting and gathering it shares with vpl are
 * in vpl_common.c):
 *  - virtual spherical lights (Hasan et al. 2009): each VPL's flux spread over a
 *    sphere of radius r (the distance to its k-th nearest VPL, or the `radius` option):
 *    Lo(x, wo) = V(x <-> p) Phi / (pi r^2) int_cone f_x(l -> wo) cos_x f_v(wi -> -l) cos_p dl
 *    over the cone the sphere subtends at x (the whole sphere of directions when x is
 *    inside), estimated with `cone_samples` directions drawn uniformly in the cone. No
 *    1/d^2 singularity: no splotches on glossy surfaces; consistent as count grows. */
#include "integrator/vpl_common.h"
#include "geometry/pointtree.h"
#include "core/streams.h"
#include "core/sampling.h"
#include "core/error.h"
#include <math.h>
#include <stddef.h>
#include <stdlib.h>

typedef struct vsl_state { vlight_set set; } vsl_state;

enum { S_COUNT, S_DIRECT, S_RADIUS, S_K, S_CONE, S_SHADOW };
static const integrator_param vsl_params[] = {
    {"count", IPARAM_INT, 2048, 1, 1e6, "virtual spherical lights per pass"},
    {"direct", IPARAM_INT, 4, 1, 1024, "next-event samples of direct light per camera sample"},
    {"radius", IPARAM_FLOAT, 0, 0, 1e30, "sphere radius in scene units; 0 = automatic, the distance to the k-th nearest light"},
    {"k", IPARAM_INT, 2, 1, 256, "which nearest light sets the automatic radius"},
    {"cone_samples", IPARAM_INT, 1, 1, 64, "directions sampled in the cone per light and camera sample"},
    {"shadow_rays", IPARAM_INT, 64, 0, 1e6,
     "0: every light, a shadow ray each; S > 0: S lights drawn in proportion to power / max(d^2, r^2)"},
    {NULL, IPARAM_INT, 0, 0, 0, NULL}};

static void vsl_destroy(void *st) {
  vsl_state *vs = st;
  if (!vs) return;
  vlight_free(&vs->set);
  free(vs);
}

static valo_status vsl_create(const render_ctx *c, void **out, valo_error *err) {
  (void)c;
  vsl_state *vs = calloc(1, sizeof *vs);
  if (!vs) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  *out = vs;
  return VALO_OK;
}

/* The pass's lights, each with its sphere's radius: the `radius` option, or the distance
 * to its k-th nearest light of the pass. */
static valo_status vsl_prepare(void *state, const render_ctx *c, int sample_index, valo_error *err) {
  vsl_state *vs = state;
  vlight_set *s = &vs->set;
  valo_status st = vlight_shoot(s, c, sample_index, c->param[S_COUNT], err);
  if (st || !s->n) return st;
  if (c->param[S_RADIUS] > 0) {
    for (uint32_t i = 0; i < s->n; i++) s->v[i].radius = (float)c->param[S_RADIUS];
    return VALO_OK;
  }
  point_tree t;
  if (point_set_build(&t, s->v, s->n, sizeof *s->v, offsetof(vpl, p), NULL)) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  int k = (int)c->param[S_K] + 1; /* the light itself is its own nearest */
  point_near nb[POINT_KNN_MAX];
  for (uint32_t i = 0; i < s->n; i++) {
    int cnt = point_tree_knn(&t, s->v[i].p, k, INFINITY, v3(0, 0, 1), 0, nb);
    float r2 = 0;
    for (int q = 0; q < cnt; q++) r2 = fmaxf(r2, nb[q].d2);
    s->v[i].radius = r2 > 0 ? sqrtf(r2) : 0.01f * c->s->radius;
  }
  point_tree_free(&t);
  return VALO_OK;
}

/* Unshadowed contribution of spherical light i at x: the cone the sphere subtends at x
 * (every direction from inside it), cone_samples directions drawn uniformly in it. */
static rgb vsl_contrib(const render_ctx *c, const vlight_set *s, uint32_t i, const isect *it, const bsdf *b, const frame *fr, vec3 wo_l,
                       sampler *smp) {
  const vpl *l = &s->v[i];
  vec3 d = v3_sub(l->p, it->p);
  float d2 = v3_len2(d);
  if (!(d2 > 0)) return c3(0, 0, 0);
  /* Spheres do not reach through surfaces: a light on an opaque surface lights only its
   * own side (x behind that surface, or on the opposite face of the same plane — a wall
   * of no thickness — gets nothing), and an opaque x takes nothing from a light behind
   * its own surface. The shadow ray to the sphere's centre cannot stop these: it starts
   * on x's far side or ends on the shared plane. */
  float eps = 1e-4f * c->s->radius;
  if (!bsdf_transmits(&l->b)) {
    float h = -v3_dot(d, l->ng);
    if (h < -eps || (h < eps && v3_dot(fr->n, l->ng) < 0)) return c3(0, 0, 0);
  }
  if (!bsdf_transmits(b) && v3_dot(d, fr->n) < -eps) return c3(0, 0, 0);
  float dist = sqrtf(d2);
  vec3 w = v3_scale(d, 1 / dist); /* x -> light */
  int cone = (int)c->param[S_CONE];
  float r = l->radius, cos_max = dist > r ? sqrtf(fmaxf(0.0f, 1 - r * r / d2)) : -1;
  float omega = 2 * PI_F * (1 - cos_max);
  frame cf = frame_from_n(w);
  rgb acc = c3(0, 0, 0);
  sampler ls = sampler_child(smp, i, s->n);
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

/* The lights' light at x: every light with a shadow ray each, or (shadow_rays = S > 0,
 * fewer than the lights) S lights drawn by systematic sampling of the distribution
 * proportional to a cheap bound of their reach, luminance of the power over
 * max(d^2, r^2) (never 0, so every light that can contribute can be drawn), each weighted
 * 1 / (S p): the same expectation as the sum over all, for S cone integrals and shadow
 * rays in place of one per light. */
#define VSL_SAMPLED_MAX 4096
static rgb vsl_gather(const render_ctx *c, const vlight_set *s, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                      thread_stats *ts) {
  int S = (int)c->param[S_SHADOW];
  if (!(S > 0 && s->n > (uint32_t)S && s->n <= VSL_SAMPLED_MAX)) return vlight_gather_all(c, s, vsl_contrib, it, b, fr, wo, smp, ts);
  float cdf[VSL_SAMPLED_MAX];
  double total = 0;
  for (uint32_t i = 0; i < s->n; i++) {
    const vpl *l = &s->v[i];
    float d2 = v3_len2(v3_sub(l->p, it->p)), r2 = l->radius * l->radius;
    float w = c3_lum(l->power) / fmaxf(fmaxf(d2, r2), 1e-30f);
    total += isfinite(w) && w > 0 ? w : 0;
    cdf[i] = (float)total;
  }
  rgb sum = c3(0, 0, 0);
  if (total > 0) {
    vec3 wo_l = frame_to_local(fr, wo);
    sampler us = sampler_child(smp, 0, 1);
    sampler_set_dim(&us, CDIM_VSL_SAMPLED);
    float u0 = sampler_1d(&us);
    uint32_t i = 0;
    for (int m = 0; m < S; m++) {
      i = vlight_systematic(cdf, s->n, i, m, S, u0, total);
      float p = (float)((cdf[i] - (i ? cdf[i - 1] : 0)) / total);
      if (!(p > 0)) continue;
      rgb ct = vsl_contrib(c, s, i, it, b, fr, wo_l, smp);
      if (c3_black(ct) || !c3_finite(ct)) continue;
      if (ctx_segment_blocked(c, it, s->v[i].p, s->v[i].ng, ts)) continue;
      sum = c3_add(sum, c3_scale(ct, 1 / ((float)S * p)));
    }
  }
  return sum;
}

static rgb vsl_shade(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, int depth, sampler *smp,
                     thread_stats *ts) {
  const vsl_state *vs = c->state;
  rgb L = vlight_direct(c, (int)c->param[S_DIRECT], it, b, fr, wo, depth, smp, ts);
  return c3_add(L, vsl_gather(c, &vs->set, it, b, fr, wo, smp, ts));
}

static rgb vsl_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) { return li_shade_through_delta(c, r, smp, ts, vsl_shade); }

const integrator_ops integrator_vsl = {
    .name = "vsl",
    .description = "virtual spherical lights (Hasan et al. 2009): each VPL's flux spread over a sphere, integrated over the cone it subtends",
    .kind = INTEGRATOR_RAY,
    .params = vsl_params,
    .li = vsl_li,
    .create = vsl_create,
    .prepare = vsl_prepare,
    .destroy = vsl_destroy,
};
