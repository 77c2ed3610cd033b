/* restir_di.c — owns restir-di (digest 001; Bitterli et al. 2020): its parameters, the DI
 * target (unshadowed f Le |cos| g in the light's measure), RIS candidates, the merge of
 * DI reservoirs and shading; the frame's stages are in restir_common.c. */
#include "integrator/direct.h"
#include "integrator/restir_internal.h"
#include "core/threadpool.h"
#include "core/sampling.h"
#include "core/error.h"
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#define DI_PARAMS_COMMON                                                                                                              \
  {"candidates", IPARAM_INT, 8, 1, 1024, "M: light samples per pixel per frame (RIS candidates)"},                                    \
  {"temporal", IPARAM_INT, -1, -1, 1, "1: reuse the previous frame's reservoir at the reprojected pixel; -1: in sequences only"},  \
  {"history", IPARAM_FLOAT, 2, 0, 1000, "the previous frame's M is capped at this many times the current one's (paper: 20)"},          \
  {"spatial", IPARAM_INT, 5, 0, 64, "k: neighbours merged per spatial round"},                                                         \
  {"radius", IPARAM_FLOAT, 0, 0, 1000, "spatial neighbours come from a disc of this many pixels; 0: width / 64 (30 at 1920), >= 3"}, \
  {"iterations", IPARAM_INT, -1, -1, 8, "n: rounds of spatial reuse; -1: one in sequences, none in stills"},                           \
  {"unbiased", IPARAM_INT, 1, 0, 1, "1: pairwise MIS with visibility (unbiased); 0: 1/M (biased, darker)"},                        \
  {"normal_threshold", IPARAM_FLOAT, 0.9, -1, 1, "reuse only from pixels whose normal has at least this cosine with ours (25 deg)"}, \
  {"depth_threshold", IPARAM_FLOAT, 0.1, 0, 10, "... and whose depth differs from ours by at most this fraction"}
const integrator_param restir_di_params[] = {
    DI_PARAMS_COMMON,
    {"reservoirs", IPARAM_INT, 4, 1, 8, "K: reservoirs per pixel (at most one per candidate), the candidates split among them, each with its own history; shaded as their mean"},
    {NULL, IPARAM_INT, 0, 0, 0, NULL}};

/* ---- DI target: unshadowed f * Le * |cos| * g at pixel g for light sample y (in y's
 * measure); p^ is its luminance. */
/* p^ from a light evaluation li (g: its measure factor). */
static float di_target_li(const isect *it, const bsdf *b, const frame *fr, vec3 wo, const light_li *li, float g, rgb *contrib) {
  vec3 wi_l = frame_to_local(fr, li->wi), wo_l = frame_to_local(fr, wo);
  int refl_l = (wi_l.z > 0) == (wo_l.z > 0), refl_g = (v3_dot(li->wi, it->ng) > 0) == (v3_dot(wo, it->ng) > 0);
  if (refl_l != refl_g || v3_dot(li->wi, it->ng) == 0) return 0;
  rgb f = bsdf_eval(b, wo_l, wi_l);
  if (c3_black(f)) return 0;
  *contrib = c3_scale(c3_mul(f, li->L), fabsf(wi_l.z) * g);
  float p = c3_lum(*contrib);
  return p > 0 && isfinite(p) ? p : 0;
}
float restir_di_target(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, const di_sample *y, rgb *contrib,
                       light_li *li) {
  const light *l = &c->s->lights[y->light];
  float g;
  if (!light_eval_point(c->s, l, it->p, y->y, li, &g)) return 0;
  return di_target_li(it, b, fr, wo, li, g, contrib);
}
static float di_target_g(const render_ctx *c, const gpix *g, const di_sample *y, rgb *contrib, light_li *li) {
  return restir_di_target(c, &g->it, &g->b, &g->fr, g->wo, y, contrib, li);
}
static int di_visible(const render_ctx *c, const gpix *g, const light_li *li, thread_stats *ts) {
  return !ctx_segment_blocked(c, &g->it, li->p_light, li->n_light, ts);
}

int restir_di_candidates(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, int M, const sampler *smp,
                         sampler *rng, di_res *r, light_li *kept) {
  return restir_di_candidates_of(c, it, b, fr, wo, M, 0, (uint32_t)M, smp, rng, r, kept);
}

int restir_di_candidates_of(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, int M, uint32_t first,
                            uint32_t of, const sampler *smp, sampler *rng, di_res *r, light_li *kept) {
  memset(r, 0, sizeof *r);
  float phat_kept = 0;
  light_site at = light_locate(&c->ls, it->p);
  for (int i = 0; i < M; i++) {
    sampler cs = sampler_child(smp, first + (uint32_t)i, of);
    float ul = sampler_1d(&cs), u1, u2;
    sampler_2d(&cs, &u1, &u2);
    float u = rnd(rng);
    float pmf;
    uint32_t li = light_select_at(&c->ls, c->s, &at, ul, &pmf);
    if (li == UINT32_MAX || !(pmf > 0)) continue;
    const light *l = &c->s->lights[li];
    light_li ls;
    if (!light_sample(c->s, l, it->p, u1, u2, &ls)) continue;
    di_sample y = {li, l->type == LIGHT_ENV ? ls.wi : ls.p_light};
    rgb contrib;
    /* y's measure factor (|cos_l| / d^2 for area lights): the target and the source
     * density pmf * pdf_omega * g in that measure */
    float g = l->type == LIGHT_AREA ? fabsf(v3_dot(ls.n_light, ls.wi)) / (ls.dist * ls.dist) : 1.0f;
    float phat = di_target_li(it, b, fr, wo, &ls, g, &contrib);
    if (!(phat > 0)) continue;
    float pdf = pmf * ls.pdf * g;
    if (!(pdf > 0) || !isfinite(pdf)) continue;
    if (restir_wrs_take(&r->w_sum, phat / pdf, u)) {
      r->y = y;
      phat_kept = phat;
      if (kept) *kept = ls;
    }
  }
  r->M = (float)M;
  r->W = phat_kept > 0 ? r->w_sum / (r->M * phat_kept) : 0;
  if (phat_kept > 0) {
    /* evaluated as merges and shading would evaluate it here, so they read the same bits */
    light_li li;
    r->p = restir_di_target(c, it, b, fr, wo, &r->y, &r->f, &li);
    if (!(r->p > 0)) r->f = c3(0, 0, 0);
  }
  return phat_kept > 0;
}

void restir_stage_di_initial(void *user, int64_t row, int thread) {
  stage_job *j = user;
  restir_state *s = j->s;
  int K = s->reservoirs, M = s->dcfg.candidates;
  for (int x = 0; x < s->width; x++) {
    size_t pix = (size_t)row * s->width + x;
    const gpix *g = &s->g[pix];
    di_res *r = &s->di[j->dst][pix * (size_t)K];
    memset(r, 0, (size_t)K * sizeof *r);
    if (!g->valid) continue;
    sampler smp = sampler_make_kind(j->c->seed, pix, (uint64_t)j->f->frame, (sampler_kind)j->c->sampler_kind);
    sampler_set_dim(&smp, SDIM_RESTIR_CAND);
    sampler rng = restir_pixel_stream(j->c, j->f, pix, RDIM_CAND); /* each candidate's choice, in turn */
    /* the pixel's M candidates (children 0..M-1 of M) split among its K reservoirs */
    for (int k = 0, first = 0; k < K; k++) {
      int m = restir_share(M, K, k);
      light_li li;
      /* visibility reuse: a shadowed survivor passes nothing on */
      if (restir_di_candidates_of(j->c, &g->it, &g->b, &g->fr, g->wo, m, (uint32_t)first, (uint32_t)M, &smp, &rng, &r[k], &li) &&
          !di_visible(j->c, g, &li, &j->f->ts[thread]))
        r[k].W = 0;
      first += m;
    }
  }
}

/* DI reservoirs: targets in the light's measure; visibility of the light point the last
 * target found. */
typedef struct di_merge_ctx {
  const render_ctx *c;
  const di_res *const *in;
  const gpix *g0;
  light_li li;
  float p0[72]; /* each input's target at g0 (when asked) */
  rgb f0[72];
} di_merge_ctx;
static float di_merge_target(void *u, const gpix *at, int j) {
  di_merge_ctx *m = u;
  rgb contrib;
  float p = di_target_g(m->c, at, &m->in[j]->y, &contrib, &m->li);
  if (at == m->g0) { m->p0[j] = p; m->f0[j] = p > 0 ? contrib : c3(0, 0, 0); }
  return p;
}
static float di_merge_own(void *u, int j) { return ((di_merge_ctx *)u)->in[j]->p; }
static int di_merge_visible(void *u, const gpix *at, int j, thread_stats *ts) {
  (void)j;
  di_merge_ctx *m = u;
  return di_visible(m->c, at, &m->li, ts);
}
static float di_merge_W(void *u, int j) { return ((di_merge_ctx *)u)->in[j]->W; }

/* Merges DI reservoirs in[0..n) (in[0] pixel g's, in[i] from pixel gs[i], gs[0] = g) into
 * *out (restir_merge says how). */
void restir_di_merge(const render_ctx *c, int unbiased, const gpix *const *gs, const di_res *const *in, int n, float cap_M, sampler *rng,
                     thread_stats *ts, di_res *out) {
  static const merge_ops ops = {di_merge_target, di_merge_own, di_merge_visible, di_merge_W};
  di_merge_ctx m = {.c = c, .in = in, .g0 = gs[0]};
  float M[72];
  for (int i = 0; i < n; i++) M[i] = in[i]->M;
  memset(out, 0, sizeof *out);
  int kept = restir_merge(&ops, &m, unbiased, in[0]->W > 0, M, gs, n, cap_M, rng, ts, &out->M, &out->W);
  if (kept >= 0) { out->y = in[kept]->y; out->p = m.p0[kept]; out->f = m.f0[kept]; }
}

/* Direct light of a pixel from its final reservoir: f Le |cos| g W (the sample is visible:
 * reservoirs hold only samples their pixel sees; f as the reservoir found it there). */
rgb restir_di_shade(const di_res *r) {
  if (!(r->W > 0) || !(r->p > 0)) return c3(0, 0, 0);
  return c3_scale(r->f, r->W);
}

static valo_status restir_di_create(const render_ctx *c, void **state, valo_error *err) { return restir_create(c, state, 0, err); }

const integrator_ops integrator_restir_di = {
    .name = "restir-di",
    .description = "ReSTIR direct light (Bitterli et al. 2020): RIS over light samples, temporal and spatial reuse; frames averaged for a still",
    .kind = INTEGRATOR_IMAGE,
    .params = restir_di_params,
    .create = restir_di_create,
    .destroy = restir_destroy,
    .render_frame = restir_frame,
};
