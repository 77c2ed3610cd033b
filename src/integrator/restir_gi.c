/* restir_gi.c — owns restir-gi (digest 001; Ouyang et al. 2021): its parameters, the GI
 * target, the solid-angle Jacobian, the initial sample points and the merge of GI
 * reservoirs; the frame's stages are in restir_common.c. */
#include "integrator/path_common.h"
#include "integrator/restir_internal.h"
#include "core/threadpool.h"
#include "core/sampling.h"
#include "core/error.h"
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

static const integrator_param restir_gi_params[] = {
    {"candidates", IPARAM_INT, 8, 1, 1024, "M of the direct-light reservoirs (direct=1)"},
    {"temporal", IPARAM_INT, -1, -1, 1, "1: reuse the previous frame's reservoirs at the reprojected pixel; -1: in sequences only"},
    {"history", IPARAM_FLOAT, 20, 0, 1000, "the previous frame's M is capped at this many times the current one's"},
    {"spatial", IPARAM_INT, 3, 0, 64, "k: neighbours merged per spatial round"},
    {"radius", IPARAM_FLOAT, 0, 0, 1000, "spatial neighbours come from a disc of this many pixels; 0: width / 64 (30 at 1920), >= 3"},
    {"iterations", IPARAM_INT, 1, 0, 8, "n: rounds of spatial reuse"},
    {"unbiased", IPARAM_INT, 1, 0, 1, "1: pairwise MIS with visibility (unbiased); 0: 1/M (biased)"},
    {"normal_threshold", IPARAM_FLOAT, 0.9, -1, 1, "reuse only from pixels whose normal has at least this cosine with ours (25 deg)"},
    {"depth_threshold", IPARAM_FLOAT, 0.1, 0, 10, "... and whose depth differs from ours by at most this fraction"},
    {"direct", IPARAM_INT, 1, 0, 1, "direct light at the camera hit: 1 restir-di (direct_spatial, direct_iterations), 0 plain next-event estimation"},
    {"jacobian", IPARAM_INT, 1, 0, 1, "1: reused samples carry the solid-angle Jacobian (0 only to show the bias without it)"},
    {"direct_spatial", IPARAM_INT, 3, 0, 64, "direct=1: k of the direct-light reservoirs' spatial rounds"},
    {"direct_iterations", IPARAM_INT, -1, -1, 8, "direct=1: n, rounds of spatial reuse of the direct-light reservoirs; -1: one in sequences, none in stills"},
    {NULL, IPARAM_INT, 0, 0, 0, NULL}};

/* ---- GI */
/* p^ of GI sample y at pixel g: luminance of f(wo, wi) |cos| L^, wi towards x_s; 0 when
 * g is behind x_s's surface (as seen from the pixel that made y). */
float restir_gi_target(const gpix *g, const gi_res *r, rgb *contrib, vec3 *wi_out) {
  vec3 d = v3_sub(r->xs, g->it.p);
  float d2 = v3_len2(d);
  if (!(d2 > 0) || v3_dot(r->ns, v3_neg(d)) <= 0) return 0;
  vec3 wi = v3_scale(d, 1 / sqrtf(d2));
  vec3 wi_l = frame_to_local(&g->fr, wi), wo_l = frame_to_local(&g->fr, g->wo);
  int refl_l = (wi_l.z > 0) == (wo_l.z > 0), refl_g = (v3_dot(wi, g->it.ng) > 0) == (v3_dot(g->wo, g->it.ng) > 0);
  if (refl_l != refl_g || v3_dot(wi, g->it.ng) == 0) return 0;
  rgb f = bsdf_eval(&g->b, wo_l, wi_l);
  *contrib = c3_scale(c3_mul(f, r->Lo), fabsf(wi_l.z));
  *wi_out = wi;
  float p = c3_lum(*contrib);
  return p > 0 && isfinite(p) ? p : 0;
}

float restir_gi_jacobian(vec3 x_from, vec3 x_to, vec3 xs, vec3 ns) {
  vec3 a = v3_sub(x_from, xs), b = v3_sub(x_to, xs);
  float la2 = v3_len2(a), lb2 = v3_len2(b);
  if (!(la2 > 0) || !(lb2 > 0)) return 0;
  float cos_from = fabsf(v3_dot(ns, a)) / sqrtf(la2), cos_to = fabsf(v3_dot(ns, b)) / sqrtf(lb2);
  if (!(cos_from > 0)) return 0;
  float J = (cos_to / cos_from) * (la2 / lb2);
  return isfinite(J) ? J : 0;
}

static int gi_visible(const render_ctx *c, const gpix *g, const gi_res *r, thread_stats *ts) {
  return !ctx_segment_blocked(c, &g->it, r->xs, r->ns, ts);
}

void restir_stage_gi_initial(void *user, int64_t row, int thread) {
  stage_job *j = user;
  restir_state *s = j->s;
  const render_ctx *c = j->c;
  thread_stats *ts = &j->f->ts[thread];
  for (int x = 0; x < s->width; x++) {
    size_t pix = (size_t)row * s->width + x;
    const gpix *g = &s->g[pix];
    gi_res *r = &s->gr[j->dst][pix];
    memset(r, 0, sizeof *r);
    if (!g->valid) continue;
    r->M = 1;
    sampler smp = sampler_make_kind(c->seed, pix, (uint64_t)j->f->frame, (sampler_kind)c->sampler_kind);
    sampler_set_dim(&smp, SDIM_RESTIR_GI_DIR);
    bsdf_sample bs;
    vec3 wi;
    isect it = g->it;
    if (!sample_bsdf_world(&it, &g->b, &g->fr, g->wo, &smp, ts, &bs, &wi) || bs.delta || !(bs.pdf > 0)) continue;
    ray ry = spawn_ray(&it, wi);
    hit h;
    if (!ctx_intersect(c, &ry, &h, ts)) continue; /* the environment is direct light */
    isect hs;
    isect_from_hit(c->s, &ry, &h, &hs);
    sampler_set_dim(&smp, SDIM_RESTIR_GI_PATH);
    sampler ps = sampler_child(&smp, 0, 1);
    rgb Lo = path_radiance(c, ry, &ps, ts, 0);
    if (!sample_usable(ts, Lo)) continue; /* never kept: it would live on as history */
    r->xs = hs.p;
    r->ns = v3_dot(hs.ng, wi) > 0 ? v3_neg(hs.ng) : hs.ng; /* facing x_v */
    r->Lo = Lo;
    rgb contrib;
    vec3 wi2;
    float phat = restir_gi_target(g, r, &contrib, &wi2);
    if (!(phat > 0)) { r->Lo = c3(0, 0, 0); continue; }
    r->w_sum = phat / bs.pdf;
    r->W = 1 / bs.pdf;
  }
}

/* Area-measure factor at pixel g for GI sample point xs: |cos phi_g| / |x_g - xs|^2 (1
 * when the Jacobian is switched off, to show what leaving it out does). */
static float gi_area(const gpix *g, const gi_res *r, int use_jacobian) {
  if (!use_jacobian) return 1;
  vec3 d = v3_sub(g->it.p, r->xs);
  float d2 = v3_len2(d);
  if (!(d2 > 0)) return 0;
  float f = fabsf(v3_dot(r->ns, d)) / (d2 * sqrtf(d2));
  return isfinite(f) ? f : 0;
}
/* GI reservoirs: targets p^_omega times gi_area (the area measure at the sample points),
 * W divided by its owner's gi_area, so a reused W carries the Jacobian of the shift
 * (restir_gi_jacobian); visibility is a ray to the sample point. */
typedef struct gi_merge_ctx { const render_ctx *c; const gi_res *const *in; const gpix *const *gs; int use_jacobian; } gi_merge_ctx;
static float gi_merge_target(void *u, const gpix *at, int j) {
  gi_merge_ctx *m = u;
  rgb contrib;
  vec3 wi;
  return restir_gi_target(at, m->in[j], &contrib, &wi) * gi_area(at, m->in[j], m->use_jacobian);
}
static int gi_merge_visible(void *u, const gpix *at, int j, thread_stats *ts) {
  gi_merge_ctx *m = u;
  return gi_visible(m->c, at, m->in[j], ts);
}
static float gi_merge_W(void *u, int j) {
  gi_merge_ctx *m = u;
  float a_own = gi_area(m->gs[j], m->in[j], m->use_jacobian);
  return m->in[j]->W > 0 && a_own > 0 ? m->in[j]->W / a_own : 0;
}

/* Merges GI reservoirs as restir_di_merge does, in the area measure at the sample points; the
 * result's W goes back to pixel gs[0]'s solid angle. */
void restir_gi_merge(const render_ctx *c, int unbiased, int use_jacobian, const gpix *const *gs, const gi_res *const *in, int n,
                     float cap_M, sampler *rng, thread_stats *ts, gi_res *out) {
  static const merge_ops ops = {gi_merge_target, NULL, gi_merge_visible, gi_merge_W};
  gi_merge_ctx m = {c, in, gs, use_jacobian};
  float M[72], W;
  for (int i = 0; i < n; i++) M[i] = in[i]->M;
  memset(out, 0, sizeof *out);
  int kept = restir_merge(&ops, &m, unbiased, in[0]->W > 0, M, gs, n, cap_M, rng, ts, &out->M, &W);
  if (kept < 0) return;
  const gi_res *r = in[kept];
  out->xs = r->xs; out->ns = r->ns; out->Lo = r->Lo;
  out->W = W * gi_area(gs[0], r, use_jacobian); /* from the area measure to this pixel's solid angle */
}

static valo_status restir_gi_create(const render_ctx *c, void **state, valo_error *err) { return restir_create(c, state, 1, err); }

const integrator_ops integrator_restir_gi = {
    .name = "restir-gi",
    .description = "ReSTIR GI (Ouyang et al. 2021): path-traced sample points reused over pixels and frames; direct light by restir-di or NEE",
    .kind = INTEGRATOR_IMAGE,
    .params = restir_gi_params,
    .create = restir_gi_create,
    .destroy = restir_destroy,
    .render_frame = restir_frame,
};

