/* guided.c — owns the `guided` integrator: path tracing with next-event estimation and
 * MIS (path.c's estimator) whose direction sampling is a one-sample mixture of the BSDF
 * and a learned distribution of incident radiance (guide.h, Müller et al. 2017; each
 * vertex learns the light that arrived along its sampled direction, less the emission its
 * own next-event estimation could have found): with
 * probability 1 - the BSDF fraction (the leaf's and normal bin's learned one, or
 * bsdf_fraction) the direction comes from the SD-tree leaf of the shading point, and
 * the mixture's pdf is the one every MIS weight uses (the emission a
 * sampled ray finds, and next-event estimation's light samples), so the estimate stays
 * unbiased. The render's own samples learn, in passes of 1, 2, 4, ... samples per pixel:
 * each pass records into the tree that the next one samples (refined between passes, in
 * prepare, so a pass samples one fixed tree and every sample is unbiased; all of them are
 * kept in the image), until train_spp; the later samples take the last tree without
 * recording. Surfaces without a smooth lobe (mirrors, smooth glass) and delta samples are
 * not guided. Scenes with media take path's walk. */
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

enum { P_TRAIN, P_FRACTION, P_SPATIAL, P_NODES, P_LEARN_FRACTION };
static const integrator_param guided_params[] = {
    {"train_spp", IPARAM_INT, -1, -1, 1 << 20,
     "samples per pixel that learn, in passes of 1, 2, 4, ... (-1: half the render's spp, or a quarter of its --time)"},
    {"bsdf_fraction", IPARAM_FLOAT, 0.5, 0.01, 1, "share of directions drawn from the BSDF rather than from the learned distribution"},
    {"spatial_threshold", IPARAM_FLOAT, 12000, 1, 1e9, "a spatial leaf splits past this many records times sqrt(2^pass)"},
    {"max_nodes", IPARAM_INT, 4000000, 1024, 1e9, "directional quadtree nodes at most, over all leaves (48 bytes each)"},
    {"learn_fraction", IPARAM_INT, 1, 0, 1,
     "1: each leaf and normal bin learns its BSDF fraction (0.25, 0.5, 0.75 or 1) from the training passes; 0: bsdf_fraction everywhere"},
    {NULL, 0, 0, 0, 0, NULL}};

typedef struct gstate {
  guide g;
  int learning;      /* the render's samples record into the building trees */
  int done;          /* learning is over (or never started) */
  int next;          /* the sample index before which the current pass is refined */
  int passes;        /* passes refined */
  int train_spp;     /* learning stops at the first pass boundary at or past this */
  double t0, seconds;
  _Atomic uint32_t probe_max; /* the largest record of the probe pass (float bits) */
} gstate;

#define MAXV 48
/* L0: the path's radiance when it left; ex: what it does not learn; fc: the luminance of
 * f |cos| of its direction, pb and pg the BSDF's and the quadtree's pdfs there (pg < 0:
 * no quadtree to compare with, no moments) */
typedef struct gvert { gleaf *l; int bin; vec3 d; rgb beta, L0, ex; float pdf, fc, pb, pg; } gvert;
typedef struct recorder { guide *g; _Atomic uint32_t *probe; gvert v[MAXV]; int n; } recorder;

static void rec_value(recorder *rc, gleaf *l, int bin, vec3 d, float value) {
  if (!(value >= 0) || !isfinite(value)) return;
  if (rc->probe) {
    uint32_t bits, old = atomic_load_explicit(rc->probe, memory_order_relaxed);
    memcpy(&bits, &value, sizeof bits);
    while (bits > old && !atomic_compare_exchange_weak_explicit(rc->probe, &old, bits, memory_order_relaxed, memory_order_relaxed)) {}
    return;
  }
  if (l) guide_record(rc->g, l, bin, d, value);
}
static float channel_ratio(float a, float b) { return b > 0 ? a / b : 0; }
/* Each vertex's incident radiance along its sampled direction: what the path gathered
 * after it left, over the throughput it left with. */
static void rec_flush(recorder *rc, rgb L) {
  for (int k = 0; k < rc->n; k++) {
    const gvert *v = &rc->v[k];
    rgb acc = c3_sub(c3_sub(L, v->L0), v->ex);
    rgb Lin = c3(channel_ratio(acc.r, v->beta.r), channel_ratio(acc.g, v->beta.g), channel_ratio(acc.b, v->beta.b));
    float lin = c3_lum(Lin);
    rec_value(rc, v->l, v->bin, v->d, lin / v->pdf);
    if (v->l && !rc->probe && v->pg >= 0)
      guide_record_moments(rc->g, v->l, v->bin, (double)v->fc * lin / v->pdf / rc->g->scale, v->pdf, v->pb, v->pg);
  }
  rc->n = 0;
}

static rgb guided_walk(const render_ctx *c, const guide *g, ray r, sampler *smp, thread_stats *ts, recorder *rc) {
  const scene *s = c->s;
  float alpha_b = (float)c->param[P_FRACTION];
  int learned = c->param[P_LEARN_FRACTION] > 0;
  rgb L = c3(0, 0, 0), beta = c3(1, 1, 1);
  path_state st = path_state_start(r.o);
  int max_depth = c->max_depth >= 0 ? c->max_depth : PATH_HARD_CAP;
  for (int depth = 0;; depth++) {
    isect it;
    rgb Le;
    float w;
    int surface = path_trace_vertex(c, &r, &st, ts, &it, &Le, &w);
    if (!c3_black(Le) && (depth > 0 || !c->hide_emitters)) {
      rgb e = c3_scale(c3_mul(beta, Le), w);
      L = c3_add(L, e);
      /* emission that next-event estimation at the vertex before could have found is not
         learned there: the guide learns the light NEE misses (caustics, indirect light) */
      if (rc && rc->n > 0 && !st.specular) rc->v[rc->n - 1].ex = c3_add(rc->v[rc->n - 1].ex, e);
    }
    if (!surface || depth >= max_depth) break;
    vec3 wo = v3_neg(r.d);
    bsdf b2, b = bsdf_at_blend(s, &it, &b2);
    frame fr = shading_frame(&it, &b, wo);
    int smooth = bsdf_has_smooth(&b);
    gleaf *lf = smooth && (g->pass > 0 || rc) ? (gleaf *)guide_leaf(g, it.p) : NULL; /* recording writes its building tree */
    int bin = guide_bin(fr.n);
    const gleaf *gl = lf && guide_can_sample(lf, bin) ? lf : NULL;
    float ab = gl && learned && gl->frac[bin] >= 0 ? gl->frac[bin] : alpha_b;
    float ag = gl ? 1 - ab : 0; /* probability of sampling the guide (0 where the leaf learned fraction 1) */
    vec3 wo_l = frame_to_local(&fr, wo);
    if (smooth) { /* next-event estimation, MIS against the mixture */
      sampler_set_dim(smp, sdim_bounce(depth, SDIM_LIGHT_PICK));
      direct_sample d;
      if (sample_direct(c, &it, &b, &fr, wo, smp, ts, 0, &d)) {
        float mw = 1;
        if (!d.delta) {
          float pb = bsdf_pdf(&b, wo_l, frame_to_local(&fr, d.wi));
          float pm = (1 - ag) * pb + (ag > 0 ? ag * guide_pdf(gl, bin, d.wi) : 0);
          mw = power_heuristic(d.light_pdf, pm);
        }
        rgb Li = c3_scale(d.Li, mw / d.light_pdf);
        L = c3_add(L, c3_mul(beta, c3_mul(d.f_cos, Li)));
      }
    }
    /* the direction: guide with probability ag, else the BSDF */
    sampler_set_dim(smp, sdim_bounce(depth, SDIM_LOBE));
    float ul = sampler_1d(smp), u1, u2;
    sampler_2d(smp, &u1, &u2);
    ts->surface_samples++;
    vec3 wi;
    rgb weight;
    float pm, pb = 0, pg = -1, fc = 0; /* for the moments: pg < 0 leaves them out */
    int delta = 0;
    float eta_scale = 1;
    if (ag > 0 && ul < ag) {
      wi = guide_sample(gl, bin, u1, u2, &pg);
      vec3 wi_l = frame_to_local(&fr, wi);
      rgb f = bsdf_eval(&b, wo_l, wi_l);
      pb = bsdf_pdf(&b, wo_l, wi_l);
      pm = ag * pg + (1 - ag) * pb;
      if (!c3_finite(f) || !isfinite(pb)) { ts->lost[VALO_LOSS_BSDF_NONFINITE]++; break; }
      if (c3_black(f) || !(pm > 0) || !sides_agree(&it, wo_l, wi_l, wo, wi, ts)) break;
      fc = c3_lum(f) * fabsf(wi_l.z);
      weight = c3_scale(f, fabsf(wi_l.z) / pm);
    } else {
      bsdf_sample bs;
      float ub = ag > 0 ? fminf((ul - ag) / (1 - ag), 0x1.fffffep-1f) : ul;
      if (!sample_bsdf_world_u(&it, &b, &fr, wo, ub, u1, u2, ts, &bs, &wi)) break;
      delta = bs.delta;
      eta_scale = bs.eta_scale;
      if (delta) { /* only the BSDF makes delta directions */
        weight = c3_scale(bs.weight, 1 / (1 - ag));
        pm = bs.pdf;
      } else {
        /* the quadtree's pdf: for the mixture, and while learning for the moments */
        if (gl && (ag > 0 || (rc && learned))) pg = guide_pdf(gl, bin, wi);
        pm = (1 - ag) * bs.pdf + (ag > 0 ? ag * pg : 0);
        weight = c3_scale(bs.weight, bs.pdf / pm);
        pb = bs.pdf;
        fc = c3_lum(bs.weight) * bs.pdf;
      }
    }
    st.specular = delta;
    st.prev_pdf = pm;
    st.prev_p = it.p;
    st.eta_acc /= eta_scale;
    r = spawn_ray(&it, wi);
    beta = c3_mul(beta, weight);
    if (rc && !delta && rc->n < MAXV) rc->v[rc->n++] = (gvert){lf, bin, wi, beta, L, c3(0, 0, 0), pm, fc, pb, learned ? pg : -1};
    if (!path_survive(&st, &beta, depth, c->rr_depth, smp)) break;
  }
  if (rc) rec_flush(rc, L);
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

typedef struct probe_job { const render_ctx *c; gstate *gs; thread_stats *ts; } probe_job;

static void probe_row(void *user, int64_t y, int thread) {
  probe_job *j = user;
  const render_ctx *c = j->c;
  recorder *rc = malloc(sizeof *rc);
  if (!rc) return;
  rc->g = &j->gs->g;
  rc->probe = &j->gs->probe_max;
  rc->n = 0;
  for (int x = 0; x < c->width; x++) {
    sampler smp = sampler_make_kind(c->seed ^ STREAM_GUIDE, (uint64_t)y * (uint64_t)c->width + (uint64_t)x, 0, (sampler_kind)c->sampler_kind);
    float wt;
    ray r = camera_ray(c->lens, x, (int)y, &smp, &wt);
    (void)guided_walk(c, &j->gs->g, r, &smp, &j->ts[thread], rc);
  }
  free(rc);
}

/* Before sample 0: a probe pass (one path per pixel from the guide's own stream) whose
 * largest record sets the fixed point's unit; learning starts. Before samples 1, 3, 7,
 * ...: the pass that ends there is refined into the next one's tree. Learning stops at
 * the first such boundary past train_spp (or, with a time budget, past a quarter of it);
 * the tree sampled from then on no longer changes. */
static valo_status guided_prepare(void *state, const render_ctx *c, int sample_index, valo_error *err) {
  gstate *gs = state;
  if (!c->lens || c->s->has_media) return VALO_OK;
  if (sample_index == 0 && gs->passes == 0 && !gs->done) {
    gs->t0 = now_seconds();
    gs->train_spp = (int)c->param[P_TRAIN];
    if (gs->train_spp < 0) gs->train_spp = c->time_budget > 0 ? 1 << 30 : c->spp / 2;
    if (gs->train_spp < 1) { gs->done = 1; return VALO_OK; }
    thread_stats *ts = thread_stats_alloc(c->threads);
    if (!ts) return err_set(err, VALO_ERR_NOMEM, "out of memory");
    probe_job j = {c, gs, ts};
    parallel_for(c->threads, c->height, probe_row, &j);
    for (int t = 0; t < c->threads && c->prep; t++) thread_stats_add(c->prep, &ts[t]);
    free(ts);
    uint32_t bits = atomic_load(&gs->probe_max);
    float mx;
    memcpy(&mx, &bits, sizeof mx);
    guide_set_scale(&gs->g, mx);
    gs->learning = 1;
    gs->next = 1;
    return VALO_OK;
  }
  if (sample_index > 0 && gs->passes == 0 && !gs->learning && !gs->done) { /* a resumed render: no tree was kept */
    log_warning("guided: a resumed render does not learn again; its remaining samples are path tracing (unguided)");
    gs->done = 1;
  }
  if (!gs->learning || sample_index != gs->next) return VALO_OK;
  if (guide_refine(&gs->g)) return err_set(err, VALO_ERR_NOMEM, "out of memory for the guide's trees");
  gs->passes++;
  int stop = 2 * sample_index + 1 > gs->train_spp || (c->time_budget > 0 && now_seconds() - gs->t0 > 0.25 * c->time_budget);
  gs->next = 2 * gs->next + 1;
  if (stop) {
    gs->learning = 0;
    gs->done = 1;
    guide_stop(&gs->g);
    gs->seconds = now_seconds() - gs->t0;
    log_note("guided: learned in %d passes (%d spp); %u spatial leaves, %llu quadtree nodes%s; BSDF fraction 1 (unguided) in %.0f %% of leaf-bins",
             gs->passes, sample_index, gs->g.nleaves, (unsigned long long)gs->g.nodes, gs->g.full ? " (the max_nodes cap was reached)" : "",
             100 * guide_pure_share(&gs->g));
  }
  return VALO_OK;
}

static rgb guided_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) {
  gstate *gs = (gstate *)c->state;
  if (c->s->has_media) return path_radiance_media(c, r, smp, ts, !c->hide_emitters);
  if (!gs->learning) return guided_walk(c, &gs->g, r, smp, ts, NULL);
  recorder rc;
  rc.g = &gs->g;
  rc.probe = NULL;
  rc.n = 0;
  return guided_walk(c, &gs->g, r, smp, ts, &rc);
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
