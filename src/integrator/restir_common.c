/* restir_common.c — owns what restir-di and restir-gi (digest 001) share: reservoir-based spatiotemporal
 * importance resampling of direct light (Bitterli et al. 2020) and of indirect light
 * (Ouyang et al. 2021), as image-wide integrators (render_frame). One frame runs these
 * stages, each a parallel_for over rows with a barrier after it, each reading only the
 * buffers of earlier stages or of the previous frame and writing its own (so the image is
 * the same for any thread count):
 *   G-buffer (camera ray through delta lobes to the first surface with a non-delta lobe)
 *   -> candidates (RIS) and their visibility -> temporal reuse (the reprojected pixel of
 *   the previous frame) -> n rounds of spatial reuse (k neighbours) -> shading.
 * Reservoirs follow the digest: {y, w_sum, M} and W = w_sum / (M p^(y)) for the candidates
 * and the biased reuse; the unbiased reuse weights the merged reservoirs by pairwise MIS
 * (the digest's Z/M normalisation measured 1.1-1.9x its error: docs/integrators.md).
 * DI samples are points on lights in the light's own measure (area for triangles, a
 * direction for the environment, the light itself for delta lights), so reuse needs no
 * Jacobian; GI samples are surface points x_s found from x_v in solid angle, so reuse
 * multiplies by the Jacobian |cos phi_r| / |cos phi_q| * |x_q - x_s|^2 / |x_r - x_s|^2.
 * Geometry is static between frames; only the camera moves. */
#include "integrator/camera_path.h"
#include "integrator/restir_internal.h"
#include "core/threadpool.h"
#include "core/sampling.h"
#include "core/error.h"
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

/* ---- shared helpers */
int restir_similar(const restir_cfg *cfg, vec3 n_a, float depth_a, vec3 n_b, float depth_b) {
  if (v3_dot(n_a, n_b) < cfg->normal_threshold) return 0;
  return fabsf(depth_a - depth_b) <= cfg->depth_threshold * depth_a;
}

int restir_wrs_take(float *w_sum, float w, float u) {
  if (!(w > 0) || !isfinite(w)) return 0;
  *w_sum += w;
  return u * *w_sum < w;
}

/* ---- G-buffer: the camera ray of pixel (x, y) this frame (through the lens), walked
 * through delta lobes to the first surface with a non-delta lobe (camera_path.h) */
static void gbuffer_pixel(const render_ctx *c, const frame_ctx *f, int x, int y, gpix *g, thread_stats *ts) {
  memset(g, 0, sizeof *g);
  uint64_t pix = (uint64_t)y * (uint64_t)c->width + (uint64_t)x;
  sampler smp = sampler_make_kind(c->seed, pix, (uint64_t)f->frame, (sampler_kind)c->sampler_kind);
  ts->rays++;
  delta_walk w;
  float fw;
  delta_walk_start(&w, camera_ray(f->lens, x, y, &smp, &fw), 0);
  if (delta_walk_next(&w, c, &smp, ts)) {
    g->it = w.it; g->fr = w.fr; g->b = w.b; g->wo = w.wo; g->beta = w.beta; g->valid = 1; g->chain = w.depth > 0;
  }
  if (w.hit_any) g->depth = cam_view_depth(&f->lens->view, w.first_p);
  g->Le = w.L;
  g->fw = fw;
  if (f->gbuf) {
    /* the AOVs of the surface the camera sees (through delta lobes: its albedo times the chain's throughput) */
    float *o = &f->gbuf[FRAME_GBUF * pix];
    memset(o, 0, FRAME_GBUF * sizeof *o);
    o[7] = g->Le.r; o[8] = g->Le.g; o[9] = g->Le.b;
    if (!g->valid) return;
    material tm = *g->it.m;
    tm.kd = g->b.kd;
    tm.ks = g->b.ks;
    rgb a = c3_mul(material_albedo(&tm, v3_dot(g->it.ns, g->wo)), g->beta);
    vec3 n = v3_faceforward(g->it.ns, g->wo);
    o[0] = a.r; o[1] = a.g; o[2] = a.b;
    o[3] = n.x; o[4] = n.y; o[5] = n.z;
    o[6] = g->depth;
  }
}

sampler restir_pixel_stream(const render_ctx *c, const frame_ctx *f, size_t pix, uint32_t dim) {
  sampler s = sampler_make(c->seed ^ STREAM_RESTIR_PIXEL, pix, (uint64_t)f->frame);
  sampler_set_dim(&s, dim);
  return s;
}

static void stage_gbuffer(void *user, int64_t row, int thread) {
  stage_job *j = user;
  for (int x = 0; x < j->s->width; x++)
    gbuffer_pixel(j->c, j->f, x, (int)row, &j->s->g[(size_t)row * j->s->width + x], &j->f->ts[thread]);
}

/* Previous-frame pixel of this pixel's surface, or -1 (no history, moved off screen, a
 * delta chain, or a different surface there). */
static int64_t reproject(const restir_state *s, const restir_cfg *cfg, const frame_ctx *f, const gpix *g) {
  if (!s->have_prev || !g->valid || g->chain) return -1;
  float fx, fy;
  if (!cam_view_project(&f->prev, g->it.p, &fx, &fy)) return -1;
  int px = (int)fx, py = (int)fy;
  size_t q = (size_t)py * s->width + px;
  const gpix *h = &s->g_prev[q];
  if (!h->valid || h->chain) return -1;
  float d_prev = cam_view_depth(&f->prev, g->it.p);
  if (!restir_similar(cfg, g->fr.n, d_prev, h->fr.n, h->depth)) return -1;
  return (int64_t)q;
}

/* ---- unbiased reuse: pairwise MIS with confidence weights (Bitterli 2022, ch. 9.1;
 * Lin et al. 2022, "Generalized resampled importance sampling", sec. 7). Input 0 is the
 * canonical (this pixel's) reservoir, 1..k the neighbours'. Each neighbour forms a pair
 * with the canonical; pair i gets the share a_i = (M_i + M_0/k) / sum M and splits it by
 * the balance heuristic between neighbour i (confidence M_i) and the canonical (M_0/k):
 *   m_i(y) = a_i M_i p_i(y) / (M_i p_i(y) + M_0/k p_0(y)),
 *   m_0(y) = sum_i a_i (M_0/k) p_0(y) / (M_i p_i(y) + M_0/k p_0(y)),
 * so that the weights of every y sum to one. p_j is input j's target with its own
 * visibility, in a measure common to all pixels (DI: the light's; GI: area at x_s).
 * Resampling weight w_i = m_i(y_i) p_0(y_i) W_i; the result's W = w_sum / p_0(y). Costs
 * two shadow rays per neighbour (y_i seen from here; y_0 seen from there), as the Z test
 * did, with far lower variance when neighbours' targets differ from ours. */
typedef struct pw_in {
  float M;       /* confidence (capped for history) */
  float W;       /* contribution weight in the common measure */
  float p_own;   /* p_i(y_i) (its own sample, visible there) */
  float p_here;  /* p_0(y_i): this pixel's target (with visibility) of its sample */
  float p_can;   /* p_i(y_0): its target (with visibility) of the canonical sample */
} pw_in;
/* Resamples one of the inputs: returns the chosen one (or -1) and sets *W, its contribution
 * weight in the common measure. Unbiased: the pairwise MIS weights above, W = w_sum / p_0(y).
 * Biased (Bitterli et al.'s 1/M): weights p_0(y_i) W_i M_i, W = w_sum / (sum M p_0(y)); it
 * needs neither p_own nor p_can. */
static int reservoir_select(const pw_in *in, int n, int unbiased, sampler *rng, float *W) {
  int k = n - 1, kept = -1;
  float w_sum = 0;
  *W = 0;
  float Mt = 0;
  for (int i = 0; i < n; i++) Mt += in[i].M;
  if (!(Mt > 0)) return -1;
  if (!unbiased) {
    for (int i = 0; i < n; i++) {
      float u = rnd(rng);
      if (in[i].W > 0 && in[i].p_here > 0 && restir_wrs_take(&w_sum, in[i].p_here * in[i].W * in[i].M, u)) kept = i;
    }
    if (kept >= 0) *W = w_sum / (Mt * in[kept].p_here);
    return kept;
  }
  float Mck = k > 0 ? in[0].M / (float)k : in[0].M;
  for (int i = 0; i < n; i++) {
    float u = rnd(rng);
    if (!(in[i].W > 0) || !(in[i].p_here > 0)) continue;
    float m;
    if (k == 0) m = 1;
    else if (i == 0) {
      m = 0;
      for (int j = 1; j < n; j++) {
        float a = (in[j].M + Mck) / Mt, den = in[j].M * in[j].p_can + Mck * in[0].p_here;
        if (den > 0) m += a * Mck * in[0].p_here / den;
      }
    } else {
      float a = (in[i].M + Mck) / Mt, den = in[i].M * in[i].p_own + Mck * in[i].p_here;
      m = den > 0 ? a * in[i].M * in[i].p_own / den : 0;
    }
    if (restir_wrs_take(&w_sum, m * in[i].p_here * in[i].W, u)) kept = i;
  }
  if (kept >= 0) *W = w_sum / in[kept].p_here;
  return kept;
}


/* Merges inputs 0..n-1 (0 the pixel gs[0]'s own, j from pixel gs[j]; M[j] of j > 0
 * capped by cap_M when > 0; `can`: input 0 holds a sample) through reservoir_select:
 * returns the kept input (or -1), its W and the merged M. The targets include
 * visibility: another pixel's sample counts only if gs[0] sees it (one shadow ray), so
 * every reservoir holds a sample its own pixel sees (or W = 0) and shading needs no
 * shadow ray; unbiased, also whether gs[j] sees input 0's (another). */
int restir_merge(const merge_ops *ops, void *u, int unbiased, int can, const float *M, const gpix *const *gs, int n, float cap_M,
                 sampler *rng, thread_stats *ts, float *M_out, float *W_out) {
  pw_in pw[72];
  *M_out = 0;
  for (int i = 0; i < n; i++) {
    pw_in *p = &pw[i];
    p->M = M[i];
    if (i > 0 && cap_M > 0 && p->M > cap_M) p->M = cap_M;
    *M_out += p->M;
    p->p_own = p->p_here = p->p_can = 0;
    p->W = ops->W(u, i);
    if (i == 0) {
      if (can) p->p_own = p->p_here = ops->target(u, gs[0], 0);
      continue;
    }
    if (p->W > 0) {
      p->p_here = ops->target(u, gs[0], i);
      if (p->p_here > 0 && !ops->visible(u, gs[0], i, ts)) p->p_here = 0;
      if (unbiased) p->p_own = ops->own ? ops->own(u, i) : ops->target(u, gs[i], i);
    }
    if (can && unbiased) {
      p->p_can = ops->target(u, gs[i], 0);
      if (p->p_can > 0 && !ops->visible(u, gs[i], 0, ts)) p->p_can = 0;
    }
  }
  return reservoir_select(pw, n, unbiased, rng, W_out);
}

/* k distinct-ish neighbours of (x, y) in a disc of radius R, similar to g; returns how
 * many were found (indices in nb). */
static int neighbours(const restir_state *s, const restir_cfg *cfg, int x, int y, const gpix *g, sampler *rng, size_t *nb) {
  int n = 0;
  for (int t = 0; t < cfg->spatial; t++) {
    float u1 = rnd(rng), u2 = rnd(rng);
    float dx, dy;
    sample_concentric_disk(u1, u2, &dx, &dy);
    int nx = x + (int)lrintf(dx * cfg->radius), ny = y + (int)lrintf(dy * cfg->radius);
    if (nx < 0 || ny < 0 || nx >= s->width || ny >= s->height || (nx == x && ny == y)) continue;
    size_t q = (size_t)ny * s->width + nx;
    const gpix *h = &s->g[q];
    if (!h->valid || h->chain != g->chain || !restir_similar(cfg, g->fr.n, g->depth, h->fr.n, h->depth)) continue;
    nb[n++] = q;
  }
  return n;
}

/* A reuse pass over the DI (gi = 0) or GI reservoirs: temporal (round < 0: each pixel
 * merges its reservoir with the history at its reprojected pixel, M of the history capped)
 * or spatial round `round` (with k similar neighbours). Reads buffer src and the history,
 * writes dst. */
typedef struct reuse_job { stage_job j; int gi, round; } reuse_job;
static void stage_reuse(void *user, int64_t row, int thread) {
  reuse_job *rj = user;
  stage_job *j = &rj->j;
  restir_state *s = j->s;
  const restir_cfg *cfg = rj->gi ? &s->gcfg : &s->dcfg;
  int temporal = rj->round < 0;
  for (int x = 0; x < s->width; x++) {
    size_t pix = (size_t)row * s->width + x, from[65];
    const gpix *g = &s->g[pix], *gs[65];
    int n = 1;
    float cap = 0;
    sampler rng;
    if (temporal) {
      rng = restir_pixel_stream(j->c, j->f, pix, RDIM_TEMPORAL + 7 * (uint32_t)rj->gi);
      int64_t q = reproject(s, cfg, j->f, g);
      if (q >= 0) { from[1] = (size_t)q; gs[1] = &s->g_prev[q]; n = 2; }
      cap = cfg->history; /* GI: times one; DI: times a reservoir's own candidates (below) */
    } else if (g->valid) {
      rng = restir_pixel_stream(j->c, j->f, pix, RDIM_SPATIAL + 256 * (uint32_t)rj->round + 7 * (uint32_t)rj->gi);
      n += neighbours(s, cfg, x, (int)row, g, &rng, from + 1);
      for (int i = 1; i < n; i++) gs[i] = &s->g[from[i]];
    }
    gs[0] = g;
    if (rj->gi) {
      const gi_res *in[65];
      in[0] = &s->gr[j->src][pix];
      for (int i = 1; i < n; i++) in[i] = temporal ? &s->gr_prev[from[i]] : &s->gr[j->src][from[i]];
      if (n == 1) s->gr[j->dst][pix] = *in[0];
      else restir_gi_merge(j->c, cfg->unbiased, cfg->jacobian, gs, in, n, cap, &rng, &j->f->ts[thread], &s->gr[j->dst][pix]);
    } else {
      /* reservoir k merges the k-th of the history or of the same neighbours, its choices
       * from its own stream (k = 0: the pixel's) */
      size_t K = (size_t)s->reservoirs;
      int M = cfg->candidates;
      for (size_t k = 0; k < K; k++) {
        float cap_k = cap * (float)restir_share(M, (int)K, (int)k); /* history x the reservoir's M */
        const di_res *in[65];
        in[0] = &s->di[j->src][pix * K + k];
        for (int i = 1; i < n; i++) in[i] = temporal ? &s->di_prev[from[i] * K + k] : &s->di[j->src][from[i] * K + k];
        sampler rk = k ? sampler_child(&rng, (uint32_t)k, (uint32_t)K) : rng;
        if (k) sampler_set_dim(&rk, rng.dim);
        if (n == 1) s->di[j->dst][pix * K + k] = *in[0];
        else restir_di_merge(j->c, cfg->unbiased, gs, in, n, cap_k, &rk, &j->f->ts[thread], &s->di[j->dst][pix * K + k]);
      }
    }
  }
}

static void stage_shade(void *user, int64_t row, int thread) {
  stage_job *j = user;
  restir_state *s = j->s;
  const render_ctx *c = j->c;
  thread_stats *ts = &j->f->ts[thread];
  for (int x = 0; x < s->width; x++) {
    size_t pix = (size_t)row * s->width + x;
    const gpix *g = &s->g[pix];
    rgb L = g->Le;
    if (g->valid) {
      rgb Lr = c3(0, 0, 0);
      if (!s->gi || s->direct_restir) {
        int K = s->reservoirs;
        for (int k = 0; k < K; k++) Lr = c3_add(Lr, restir_di_shade(&s->di[s->di_final][pix * (size_t)K + (size_t)k]));
        if (K > 1) Lr = c3_scale(Lr, 1.0f / (float)K);
      }
      else {
        sampler smp = sampler_make_kind(c->seed, pix, (uint64_t)j->f->frame, (sampler_kind)c->sampler_kind);
        sampler_set_dim(&smp, SDIM_RESTIR_NEE);
        isect it = g->it;
        Lr = estimate_direct_nomis(c, &it, &g->b, &g->fr, g->wo, &smp, ts);
      }
      if (s->gi) {
        const gi_res *r = &s->gr[s->gi_final][pix];
        rgb contrib;
        vec3 wi;
        if (r->W > 0 && restir_gi_target(g, r, &contrib, &wi) > 0) Lr = c3_add(Lr, c3_scale(contrib, r->W));
      }
      L = c3_add(L, c3_mul(g->beta, Lr));
    }
    float *o = &j->f->rgb[3 * pix];
    o[0] = L.r; o[1] = L.g; o[2] = L.b;
    if (j->f->wt) j->f->wt[pix] = g->fw;
  }
}

/* ---- the frame */
/* Temporal reuse: 1 on, 0 off, -1 (default) on in sequences and off for a still, whose
 * frames are averaged: history correlates them, so the average converges slower
 * (measured on the many-light room, docs/integrators.md). */
static int temporal_on(int t, const frame_ctx *f) { return t > 0 || (t < 0 && f->sequence); }
/* Spatial rounds: n, or -1 (restir-di's default and restir-gi's direct light) one in
 * sequences and none in a still: there the shadow rays and targets of a round cost more
 * than the error it removes (on the many-light room, the walls room and Sponza a still
 * without them has 0.8-0.9x the relMSE at equal time; docs/integrators.md). */
static int spatial_rounds(const restir_cfg *k, const frame_ctx *f) {
  if (k->spatial <= 0) return 0;
  return k->iterations >= 0 ? k->iterations : f->sequence ? 1 : 0;
}

static int run_stage(const render_ctx *c, const frame_ctx *f, parallel_fn fn, void *job) {
  parallel_for(c->threads, c->height, fn, job);
  return atomic_load(f->cancel) != 0;
}

valo_status restir_frame(void *state, const render_ctx *c, const frame_ctx *f, valo_error *err) {
  restir_state *s = state;
  if (f->frame == 0) s->have_prev = 0;
  stage_job j = {s, c, f, 0, 0};
#define STAGE(fn, job) do { if (run_stage(c, f, fn, job)) return err_set(err, VALO_ERR_CANCELLED, "render cancelled"); } while (0)
  STAGE(stage_gbuffer, &j);
  for (int gi = 0; gi < 2; gi++) {
    if (gi ? !s->gi : (s->gi && !s->direct_restir)) continue;
    const restir_cfg *cfg = gi ? &s->gcfg : &s->dcfg;
    j.src = 0; j.dst = 0;
    STAGE(gi ? restir_stage_gi_initial : restir_stage_di_initial, &j);
    int cur = 0;
    for (int round = temporal_on(cfg->temporal, f) ? -1 : 0; round < spatial_rounds(cfg, f); round++) {
      reuse_job rj = {{s, c, f, cur, 1 - cur}, gi, round};
      STAGE(stage_reuse, &rj);
      cur = 1 - cur;
    }
    if (gi) s->gi_final = cur;
    else s->di_final = cur;
  }
  STAGE(stage_shade, &j);
#undef STAGE
  /* this frame's G-buffer and final reservoirs become the history */
  gpix *tg = s->g; s->g = s->g_prev; s->g_prev = tg;
  if (!s->gi || s->direct_restir) { di_res *t = s->di_prev; s->di_prev = s->di[s->di_final]; s->di[s->di_final] = t; }
  if (s->gi) { gi_res *t = s->gr_prev; s->gr_prev = s->gr[s->gi_final]; s->gr[s->gi_final] = t; }
  s->have_prev = 1;
  return VALO_OK;
}

/* The automatic radius: the paper's 30 pixels at 1920 wide, scaled to the film (a fixed 30
 * pixels on a 160-pixel film mixes surfaces lit by different lamps: 1.8x the per-frame
 * error of 3 pixels on the many-light room, docs/integrators.md). */
static float auto_radius(int width) { float r = (float)width / 64.0f; return r > 3 ? r : 3; }

static restir_cfg cfg_from(const double *p, int gi, int width) {
  restir_cfg k;
  k.candidates = (int)p[P_CANDIDATES];
  k.temporal = (int)p[P_TEMPORAL];
  k.history = (float)p[P_HISTORY];
  k.spatial = (int)p[P_SPATIAL];
  k.radius = p[P_RADIUS] > 0 ? (float)p[P_RADIUS] : auto_radius(width);
  k.iterations = (int)p[P_ITER];
  k.unbiased = (int)p[P_UNBIASED];
  k.normal_threshold = (float)p[P_NORMAL];
  k.depth_threshold = (float)p[P_DEPTH];
  k.jacobian = gi ? (int)p[P_JACOBIAN] : 1;
  k.reservoirs = gi ? 1 : (int)p[P_RESERVOIRS];
  return k;
}

void restir_destroy(void *state) {
  restir_state *s = state;
  if (!s) return;
  free(s->g); free(s->g_prev);
  free(s->di[0]); free(s->di[1]); free(s->di_prev);
  free(s->gr[0]); free(s->gr[1]); free(s->gr_prev);
  free(s);
}

valo_status restir_create(const render_ctx *c, void **state, int gi, valo_error *err) {
  restir_state *s = calloc(1, sizeof *s);
  if (!s) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  s->gi = gi;
  s->width = c->width; s->height = c->height;
  s->np = (size_t)c->width * c->height;
  if (gi) {
    s->gcfg = cfg_from(c->param, 1, c->width);
    s->direct_restir = (int)c->param[P_DIRECT];
    /* direct light: restir-di's defaults, with this integrator's candidates, spatial and
     * iterations (one round of 3: the same GI frame error as restir-di's 2 rounds of 5 in
     * 0.71x the time on the many-light room) */
    double dp[INTEGRATOR_MAX_PARAMS];
    for (int i = 0; restir_di_params[i].name; i++) dp[i] = restir_di_params[i].def;
    dp[P_CANDIDATES] = c->param[P_CANDIDATES];
    dp[P_SPATIAL] = c->param[P_DIRECT_SPATIAL];
    dp[P_ITER] = c->param[P_DIRECT_ITER];
    dp[P_RESERVOIRS] = 1; /* several were measured on restir-di only */
    s->dcfg = cfg_from(dp, 0, c->width);
  } else s->dcfg = cfg_from(c->param, 0, c->width);
  /* Reservoirs per pixel, at most one per candidate. One reservoir's history stops
   * lowering a sequence's frame error at about 1.4x (the one sample it shades); four of
   * two candidates each fall about 2x (docs/integrators.md, restir-di). */
  s->reservoirs = s->dcfg.reservoirs < s->dcfg.candidates ? s->dcfg.reservoirs : s->dcfg.candidates;
  int ok = (s->g = calloc(s->np, sizeof *s->g)) && (s->g_prev = calloc(s->np, sizeof *s->g_prev));
  size_t nr = s->np * (size_t)s->reservoirs;
  if (ok && (!gi || s->direct_restir))
    ok = (s->di[0] = calloc(nr, sizeof(di_res))) && (s->di[1] = calloc(nr, sizeof(di_res))) && (s->di_prev = calloc(nr, sizeof(di_res)));
  if (ok && gi)
    ok = (s->gr[0] = calloc(s->np, sizeof(gi_res))) && (s->gr[1] = calloc(s->np, sizeof(gi_res))) && (s->gr_prev = calloc(s->np, sizeof(gi_res)));
  if (!ok) { restir_destroy(s); return err_set(err, VALO_ERR_NOMEM, "out of memory for the %dx%d reservoir buffers", c->width, c->height); }
  if (!c->s->nlights) log_warning("the scene has no light: restir renders only what is seen directly");
  *state = s;
  return VALO_OK;
}
