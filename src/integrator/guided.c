/* guided.c — owns the `guided` integrator: path tracing with next-event estimation and
 * MIS (path.c's estimator) whose direction sampling is a one-sample mixture of the BSDF
 * and a learned distribution of incident radiance (guide.h, Müller et al. 2017): with
 * probability 1 - bsdf_fraction the direction comes from the SD-tree leaf of the
 * shading point, and the mixture's pdf is the one every MIS weight uses (the emission a
 * sampled ray finds, and next-event estimation's light samples), so the estimate stays
 * unbiased. Learning happens before the first sample (prepare): passes of 1, 2, 4, ...
 * samples per pixel over the whole film, from their own random stream, each recording
 * into the tree that the next one samples; their images are not kept. The render then
 * samples the last tree, which no longer changes. Surfaces without a smooth lobe (mirrors,
 * smooth glass) and delta samples are not guided. Scenes with media take path's walk. */
#include "integrator/guide.h"
#include "integrator/path_common.h"
#include "integrator/direct.h"
#include "integrator/integrator.h"
#include "core/sampling.h"
#include "core/streams.h"
#include "core/threadpool.h"
#include "core/clock.h"
#include "core/error.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { P_TRAIN, P_FRACTION, P_SPATIAL, P_NODES };
static const integrator_param guided_params[] = {
    {"train_spp", IPARAM_INT, -1, -1, 1 << 20,
     "samples per pixel spent learning before the render, in passes of 1, 2, 4, ... (-1: about a quarter of the render's spp, or of its --time)"},
    {"bsdf_fraction", IPARAM_FLOAT, 0.5, 0.01, 1, "share of directions drawn from the BSDF rather than from the learned distribution"},
    {"spatial_threshold", IPARAM_FLOAT, 12000, 1, 1e9, "a spatial leaf splits past this many records times sqrt(2^pass)"},
    {"max_nodes", IPARAM_INT, 4000000, 1024, 1e9, "directional quadtree nodes at most, over all leaves (48 bytes each)"},
    {NULL, 0, 0, 0, 0, NULL}};

typedef struct gstate {
  guide g;
  int passes;        /* training passes run */
  int train_spp;     /* samples per pixel they took */
  double seconds;
  _Atomic uint32_t probe_max; /* the largest record of the probe pass (float bits) */
} gstate;

#define MAXV 48
typedef struct gvert { vec3 p, d; rgb beta, acc; float pdf; } gvert;
typedef struct recorder { guide *g; _Atomic uint32_t *probe; gvert v[MAXV]; int n; } recorder;

static void rec_value(recorder *rc, vec3 p, vec3 d, float value) {
  if (!(value > 0) || !isfinite(value)) return;
  if (rc->probe) {
    uint32_t bits, old = atomic_load_explicit(rc->probe, memory_order_relaxed);
    memcpy(&bits, &value, sizeof bits);
    while (bits > old && !atomic_compare_exchange_weak_explicit(rc->probe, &old, bits, memory_order_relaxed, memory_order_relaxed)) {}
    return;
  }
  guide_record(rc->g, p, d, value);
}
static void add_contrib(rgb *L, recorder *rc, rgb x) {
  *L = c3_add(*L, x);
  if (rc)
    for (int k = 0; k < rc->n; k++) rc->v[k].acc = c3_add(rc->v[k].acc, x);
}
static float channel_ratio(float a, float b) { return b > 0 ? a / b : 0; }
static void rec_flush(recorder *rc) {
  for (int k = 0; k < rc->n; k++) {
    const gvert *v = &rc->v[k];
    rgb Lin = c3(channel_ratio(v->acc.r, v->beta.r), channel_ratio(v->acc.g, v->beta.g), channel_ratio(v->acc.b, v->beta.b));
    rec_value(rc, v->p, v->d, c3_lum(Lin) / v->pdf);
  }
  rc->n = 0;
}

static rgb guided_walk(const render_ctx *c, const guide *g, ray r, sampler *smp, thread_stats *ts, recorder *rc) {
  const scene *s = c->s;
  float alpha_b = (float)c->param[P_FRACTION];
  rgb L = c3(0, 0, 0), beta = c3(1, 1, 1);
  path_state st = path_state_start(r.o);
  int max_depth = c->max_depth >= 0 ? c->max_depth : PATH_HARD_CAP;
  for (int depth = 0;; depth++) {
    isect it;
    rgb Le;
    float w;
    int surface = path_trace_vertex(c, &r, &st, ts, &it, &Le, &w);
    if (!c3_black(Le) && (depth > 0 || !c->hide_emitters)) add_contrib(&L, rc, c3_scale(c3_mul(beta, Le), w));
    if (!surface || depth >= max_depth) break;
    vec3 wo = v3_neg(r.d);
    bsdf b2, b = bsdf_at_blend(s, &it, &b2);
    frame fr = shading_frame(&it, &b, wo);
    int smooth = bsdf_has_smooth(&b);
    const gleaf *gl = smooth && g->pass > 0 ? guide_leaf(g, it.p) : NULL;
    if (gl && !guide_can_sample(gl)) gl = NULL;
    float ag = gl ? 1 - alpha_b : 0; /* probability of sampling the guide */
    vec3 wo_l = frame_to_local(&fr, wo);
    if (smooth) { /* next-event estimation, MIS against the mixture */
      sampler_set_dim(smp, sdim_bounce(depth, SDIM_LIGHT_PICK));
      direct_sample d;
      if (sample_direct(c, &it, &b, &fr, wo, smp, ts, 0, &d)) {
        float mw = 1;
        if (!d.delta) {
          float pb = bsdf_pdf(&b, wo_l, frame_to_local(&fr, d.wi));
          float pm = (1 - ag) * pb + (ag > 0 ? ag * guide_pdf(gl, d.wi) : 0);
          mw = power_heuristic(d.light_pdf, pm);
        }
        rgb Li = c3_scale(d.Li, mw / d.light_pdf);
        add_contrib(&L, rc, c3_mul(beta, c3_mul(d.f_cos, Li)));
        if (rc && !d.delta) rec_value(rc, it.p, d.wi, c3_lum(Li));
      }
    }
    /* the direction: guide with probability ag, else the BSDF */
    sampler_set_dim(smp, sdim_bounce(depth, SDIM_LOBE));
    float ul = sampler_1d(smp), u1, u2;
    sampler_2d(smp, &u1, &u2);
    ts->surface_samples++;
    vec3 wi;
    rgb weight;
    float pm;
    int delta = 0;
    float eta_scale = 1;
    if (ag > 0 && ul < ag) {
      float pg;
      wi = guide_sample(gl, u1, u2, &pg);
      vec3 wi_l = frame_to_local(&fr, wi);
      rgb f = bsdf_eval(&b, wo_l, wi_l);
      float pb = bsdf_pdf(&b, wo_l, wi_l);
      pm = ag * pg + (1 - ag) * pb;
      if (!c3_finite(f) || !isfinite(pb)) { ts->lost[VALO_LOSS_BSDF_NONFINITE]++; break; }
      if (c3_black(f) || !(pm > 0)) break;
      int refl_l = (wi_l.z > 0) == (wo_l.z > 0), refl_g = (v3_dot(wi, it.ng) > 0) == (v3_dot(wo, it.ng) > 0);
      if (refl_l != refl_g) { ts->lost[VALO_LOSS_SHADING_NORMAL]++; break; }
      weight = c3_scale(f, fabsf(wi_l.z) / pm);
    } else {
      bsdf_sample bs;
      float ub = ag > 0 ? fminf((ul - ag) / (1 - ag), 0x1.fffffep-1f) : ul;
      if (!bsdf_sample_dir(&b, wo_l, ub, u1, u2, &bs)) {
        if (bs.nonfinite) ts->lost[VALO_LOSS_BSDF_NONFINITE]++;
        break;
      }
      wi = v3_norm(frame_to_world(&fr, bs.wi));
      int refl_l = (bs.wi.z > 0) == (wo_l.z > 0), refl_g = (v3_dot(wi, it.ng) > 0) == (v3_dot(wo, it.ng) > 0);
      if (refl_l != refl_g) { ts->lost[VALO_LOSS_SHADING_NORMAL]++; break; }
      delta = bs.delta;
      eta_scale = bs.eta_scale;
      if (delta) { /* only the BSDF makes delta directions */
        weight = c3_scale(bs.weight, 1 / (1 - ag));
        pm = bs.pdf;
      } else {
        pm = (1 - ag) * bs.pdf + (ag > 0 ? ag * guide_pdf(gl, wi) : 0);
        weight = c3_scale(bs.weight, bs.pdf / pm);
      }
    }
    st.specular = delta;
    st.prev_pdf = pm;
    st.prev_p = it.p;
    st.eta_acc /= eta_scale;
    r = spawn_ray(&it, wi);
    beta = c3_mul(beta, weight);
    if (rc && !delta && rc->n < MAXV) rc->v[rc->n++] = (gvert){it.p, wi, beta, c3(0, 0, 0), pm};
    if (!path_survive(&st, &beta, depth, c->rr_depth, smp)) break;
  }
  if (rc) rec_flush(rc);
  return L;
}

static valo_status guided_create(const render_ctx *c, void **out, valo_error *err) {
  gstate *gs = calloc(1, sizeof *gs);
  if (!gs) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  bbox box = c->s->bounds;
  vec3 ext = v3_sub(box.hi, box.lo);
  float pad = 1e-3f * fmaxf(ext.x, fmaxf(ext.y, ext.z)) + 1e-6f;
  box.lo = v3_sub(box.lo, v3(pad, pad, pad));
  box.hi = v3_add(box.hi, v3(pad, pad, pad));
  if (guide_init(&gs->g, box, (uint64_t)c->param[P_NODES], c->param[P_SPATIAL])) { free(gs); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  *out = gs;
  return VALO_OK;
}

static void guided_destroy(void *state) {
  gstate *gs = state;
  if (!gs) return;
  guide_free(&gs->g);
  free(gs);
}

typedef struct train_job {
  const render_ctx *c;
  gstate *gs;
  uint32_t first, count; /* training sample indices */
  int probe;
  thread_stats *ts;
} train_job;

static void train_row(void *user, int64_t y, int thread) {
  train_job *j = user;
  const render_ctx *c = j->c;
  recorder *rc = malloc(sizeof *rc);
  if (!rc) return;
  rc->g = &j->gs->g;
  rc->probe = j->probe ? &j->gs->probe_max : NULL;
  rc->n = 0;
  for (int x = 0; x < c->width; x++) {
    uint64_t pix = (uint64_t)y * (uint64_t)c->width + (uint64_t)x;
    for (uint32_t k = 0; k < j->count; k++) {
      sampler smp = sampler_make_kind(c->seed ^ STREAM_GUIDE, pix, j->first + k, (sampler_kind)c->sampler_kind);
      float wt;
      ray r = camera_ray(c->lens, x, (int)y, &smp, &wt);
      (void)guided_walk(c, &j->gs->g, r, &smp, &j->ts[thread], rc);
    }
  }
  free(rc);
}

static valo_status run_pass(const render_ctx *c, gstate *gs, uint32_t first, uint32_t count, int probe, thread_stats *ts) {
  train_job j = {c, gs, first, count, probe, ts};
  parallel_for(c->threads, c->height, train_row, &j);
  return VALO_OK;
}

static valo_status guided_prepare(void *state, const render_ctx *c, int sample_index, valo_error *err) {
  gstate *gs = state;
  if (sample_index != 0 || gs->g.pass > 0 || !c->lens || c->s->has_media) return VALO_OK;
  int train = (int)c->param[P_TRAIN];
  double t_budget = -1;
  if (train < 0) {
    if (c->time_budget > 0) { train = 1 << 20; t_budget = 0.25 * c->time_budget; }
    else train = c->spp / 4;
  }
  if (train < 1) return VALO_OK;
  thread_stats *ts = thread_stats_alloc(c->threads);
  if (!ts) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  double t0 = now_seconds();
  /* the probe: the first pass's largest record sets the fixed point's unit */
  run_pass(c, gs, 0, 1, 1, ts);
  uint32_t bits = atomic_load(&gs->probe_max);
  float mx;
  memcpy(&mx, &bits, sizeof mx);
  guide_set_scale(&gs->g, mx);
  uint32_t first = 0, n = 1;
  valo_status st = VALO_OK;
  double last = 0;
  while ((int)(first + n) <= train) {
    double tp = now_seconds();
    run_pass(c, gs, first, n, 0, ts);
    if (guide_refine(&gs->g)) { st = err_set(err, VALO_ERR_NOMEM, "out of memory for the guide's trees"); break; }
    last = now_seconds() - tp;
    first += n;
    n *= 2;
    gs->passes++;
    if (t_budget > 0 && now_seconds() - t0 + 2 * last > t_budget) break;
  }
  gs->train_spp = (int)first;
  gs->seconds = now_seconds() - t0;
  for (int t = 0; t < c->threads && c->prep; t++) thread_stats_add(c->prep, &ts[t]);
  free(ts);
  if (!st)
    log_note("guided: %d training passes (%d spp) in %.2f s; %u spatial leaves, %llu quadtree nodes%s", gs->passes, gs->train_spp,
             gs->seconds, gs->g.nleaves, (unsigned long long)gs->g.nodes, gs->g.full ? " (the max_nodes cap was reached)" : "");
  return st;
}

static rgb guided_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) {
  const gstate *gs = c->state;
  if (c->s->has_media) return path_radiance_media(c, r, smp, ts, !c->hide_emitters);
  return guided_walk(c, &gs->g, r, smp, ts, NULL);
}

const integrator_ops integrator_guided = {
    .name = "guided",
    .description = "path tracing whose directions mix the BSDF with a learned SD-tree of incident light (Mueller et al. 2017)",
    .kind = INTEGRATOR_RAY,
    .params = guided_params,
    .li = guided_li,
    .create = guided_create,
    .prepare = guided_prepare,
    .destroy = guided_destroy,
};
