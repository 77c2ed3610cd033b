/* adaptive.c — see adaptive.h. */
#include "render/adaptive.h"
#include "render/tiles.h"
#include "render/checkpoint.h"
#include "core/clock.h"
#include "core/error.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Adaptive sampling (docs/integrators.md). A uniform first pass takes ADAPT_UNIFORM of the
 * budget (of the samples, or of the time with --time). "error" (the default, unbiased)
 * then fixes each pixel's count from its neighbours' relative variance (adapt_error:
 * water-filling, in a few stages over tiles); "digest" gives rounds of ADAPT_BATCH more
 * samples to the 1/ADAPT_FRACTION of pixels with the highest priority on their own
 * samples (adapt_digest). The first pass's share and the 17x17 neighbourhood are the best
 * of those bench_adaptive measures against the bound of any allocation
 * (docs/performance.md); counts are fixed from deterministic sums between stages, so the
 * image is identical for any thread count. */
#define ADAPT_BATCH 8
#define ADAPT_FRACTION 8
#define ADAPT_EPS 0.01
#define ADAPT_RADIUS 8 /* the 17x17 neighbourhood whose variance sets a pixel's priority */

/* The "error" rule's v of pixel i: the relative variance of one sample, var / (mean^2 +
 * eps) per channel (as relMSE weighs them), averaged over r, g, b; 0 with fewer than two
 * samples. (Per channel, not on luminance: the bound bench_adaptive measures is 1.12x
 * against 1.08x on CornellBox-Original, whose walls are red and green.) */
double adapt_pixel_relvar(const session *ss, size_t i) {
  double n = ss->film.count[i], acc = 0;
  if (n < 2) return 0;
  for (int c = 0; c < 3; c++) {
    double s = ss->film.sum[3 * i + c], mean = s / n, var = (ss->film.sq[4 * i + c] - s * mean) / (n - 1);
    if (var > 0) acc += var / (mean * mean + ADAPT_EPS);
  }
  return acc / 3;
}
/* The "digest" rule's priority of pixel i, on its own samples' luminance:
 * (N sum s^2 / (sum s)^2 - 1) / N. */
double adapt_pixel_digest(const session *ss, size_t i) {
  const double *m = &ss->film.sum[3 * i];
  double n = ss->film.count[i], s = 0.2126 * m[0] + 0.7152 * m[1] + 0.0722 * m[2], s2 = ss->film.sq[4 * i + 3];
  if (n < 2 || !(s > 0)) return 0;
  double rel = (n * s2 / (s * s) - 1) / n;
  return rel > 0 ? rel : 0;
}

typedef struct prio { double p; uint32_t i; } prio;
static int prio_cmp(const void *a, const void *b) {
  const prio *x = a, *y = b;
  if (x->p != y->p) return x->p < y->p ? 1 : -1;
  return x->i < y->i ? -1 : (x->i > y->i);
}

/* Partially orders a so that its first k entries are the k first by prio_cmp (a total
 * order: ties go by pixel index), in O(n) expected time: quickselect with Lomuto
 * partitions around a median-of-three pivot; deterministic. */
static void prio_select(prio *a, size_t n, size_t k) {
  size_t lo = 0, hi = n;
  while (hi - lo > 1) {
    size_t m = lo + (hi - lo) / 2, l = hi - 1, piv;
    /* index of the median of a[lo], a[m], a[l] */
    if (prio_cmp(&a[lo], &a[m]) < 0) piv = prio_cmp(&a[m], &a[l]) < 0 ? m : (prio_cmp(&a[lo], &a[l]) < 0 ? l : lo);
    else piv = prio_cmp(&a[lo], &a[l]) < 0 ? lo : (prio_cmp(&a[m], &a[l]) < 0 ? l : m);
    prio t = a[piv]; a[piv] = a[l]; a[l] = t;
    size_t store = lo;
    for (size_t i = lo; i < l; i++)
      if (prio_cmp(&a[i], &a[l]) < 0) { t = a[i]; a[i] = a[store]; a[store] = t; store++; }
    t = a[store]; a[store] = a[l]; a[l] = t;
    if (store == k) return;
    if (store > k) hi = store;
    else lo = store + 1;
  }
}

/* The "digest" rule after the first pass: rounds that give ADAPT_BATCH more samples to
 * the 1/ADAPT_FRACTION of pixels with the highest priority (N sum s^2 / (sum s)^2 - 1) / N,
 * on each pixel's own samples so far (biased: docs/integrators.md), until the budget or
 * every pixel is below the noise threshold. */
valo_status adapt_digest(session *ss, int uniform_spp, double total, double budget, double t0, valo_progress_fn progress, void *user,
                                thread_stats *ts, valo_error *err) {
  size_t np = (size_t)ss->opt.width * ss->opt.height;
  double taken = ss->resumed && ss->resume.phase == CKPT_ADAPT_DIGEST ? ss->resume.taken : (double)uniform_spp * (double)np;
  prio *pr = malloc(np * sizeof *pr);
  uint32_t *target = malloc(np * sizeof *target);
  if (!pr || !target) { free(pr); free(target); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  size_t k = np / ADAPT_FRACTION > 0 ? np / ADAPT_FRACTION : 1;
  double thr2 = ss->opt.noise_threshold > 0 ? ss->opt.noise_threshold * ss->opt.noise_threshold : 0;
  valo_status st = VALO_OK;
  while (taken < total) {
    for (size_t i = 0; i < np; i++) {
      double pd = adapt_pixel_digest(ss, i);
      pr[i].i = (uint32_t)i;
      pr[i].p = pd > thr2 ? pd : 0;
    }
    size_t sel = k;
    if (taken + (double)sel * ADAPT_BATCH > total) sel = (size_t)((total - taken) / ADAPT_BATCH);
    if (sel == 0) break;
    prio_select(pr, np, sel);
    qsort(pr, sel, sizeof *pr, prio_cmp);
    if (!(pr[0].p > 0)) break; /* every pixel below the noise threshold */
    while (sel > 0 && !(pr[sel - 1].p > 0)) sel--;
    /* the chosen pixels ADAPT_BATCH samples more, through the tiles (coherent rays) */
    memcpy(target, ss->film.count, np * sizeof *target);
    for (size_t q = 0; q < sel; q++) target[pr[q].i] += ADAPT_BATCH;
    if ((st = tiles_render_to(ss, target, ts, err))) break;
    if (atomic_load(&ss->cancel)) { st = err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d spp", (int)(taken / (double)np)); break; }
    taken += (double)sel * ADAPT_BATCH;
    double el = now_seconds() - t0;
    if (session_report_progress(progress, user, taken / total, (int)(taken / (double)np), el, budget)) {
      st = err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d spp", (int)(taken / (double)np));
      break;
    }
    ss->spp_done = (int)(taken / (double)np);
    ss->ckpt_state = (ckpt_state){CKPT_ADAPT_DIGEST, 0, 0, taken, NULL, NULL};
    checkpoint_tick(ss, ts, t0);
    if (budget > 0 && el >= budget) break;
  }
  ss->spp_done = (int)(taken / (double)np);
  free(pr);
  free(target);
  return st;
}

/* out = sums of in over the (2 ADAPT_RADIUS + 1)^2 window around each pixel (clipped to
 * the image), separably: rows into tmp, then columns. */
static void box_sums(const double *in, double *tmp, double *out, int W, int H) {
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      double acc = 0;
      for (int xx = x - ADAPT_RADIUS; xx <= x + ADAPT_RADIUS; xx++)
        if (xx >= 0 && xx < W) acc += in[(size_t)y * W + xx];
      tmp[(size_t)y * W + x] = acc;
    }
  for (int y = 0; y < H; y++) {
    double *row = &out[(size_t)y * W];
    memset(row, 0, (size_t)W * sizeof *row);
    for (int yy = y - ADAPT_RADIUS; yy <= y + ADAPT_RADIUS; yy++)
      if (yy >= 0 && yy < H)
        for (int x = 0; x < W; x++) row[x] += tmp[(size_t)yy * W + x];
  }
}

/* Sample counts for `total` samples over the image (water-filling): target_i =
 * min(cap_i, max(count_i, floor(lam a_i))), lam the largest whose targets sum to at most
 * total; the samples left over go one each to the pixels next in line, by index. So
 * counts grow as a_i = sqrt(v_i) where the budget reaches, and never fall below what a
 * pixel has. Deterministic (no thread or timing enters). Returns the targets' sum. */
static double waterfill_at(const session *ss, const double *a, const uint32_t *cap, size_t np, double lam, uint32_t *target) {
  double sum = 0;
  for (size_t i = 0; i < np; i++) {
    double want = floor(lam * a[i]);
    uint32_t t = ss->film.count[i];
    if (want > (double)t) t = want >= (double)cap[i] ? cap[i] : (uint32_t)want;
    target[i] = t;
    sum += t;
  }
  return sum;
}
static double waterfill(const session *ss, const double *a, const uint32_t *cap, size_t np, double total, uint32_t *target, uint32_t *hi_t) {
  double all = waterfill_at(ss, a, cap, np, 1e300, target);
  if (all <= total) return all; /* every pixel that can grow is at its cap */
  double lo = 0, hi = 1;
  while (waterfill_at(ss, a, cap, np, hi, hi_t) <= total) {
    lo = hi;
    hi *= 2;
  }
  for (int it = 0; it < 52; it++) { /* a double's precision; the remainder goes out below */
    double mid = 0.5 * (lo + hi);
    if (waterfill_at(ss, a, cap, np, mid, hi_t) <= total) lo = mid;
    else hi = mid;
  }
  double sum = waterfill_at(ss, a, cap, np, lo, target);
  waterfill_at(ss, a, cap, np, hi, hi_t);
  for (size_t i = 0; i < np && sum < total; i++)
    if (hi_t[i] > target[i]) { target[i]++; sum++; }
  return sum;
}

/* The "error" rule after the first pass (docs/integrators.md): each pixel's relative
 * variance per sample, var(L) / (mean^2 + eps), from the first pass and then frozen; a
 * pixel's share comes from its neighbours' (17x17 without itself). A pixel's own samples
 * never decide how many samples it gets, so its mean stays unbiased (a pixel that
 * happened to miss a rare bright path is not left with too few samples to find it:
 * test_analytic adaptive_unbiased); the neighbours share the rare paths a caustic
 * spreads. Counts grow as the square root of that variance (the allocation that
 * minimises the summed relMSE), up to v / X^2 with a noise threshold X. The samples go
 * out in stages over tiles: equal steps towards the final counts for a sample budget
 * (the same image for any thread count), and with a time budget stages of 60 % of the
 * samples the remaining time holds at the last stage's rate. */
valo_status adapt_error(session *ss, double total, double budget, double t0, valo_progress_fn progress, void *user, thread_stats *ts,
                               valo_error *err) {
  size_t np = (size_t)ss->opt.width * ss->opt.height;
  int W = ss->opt.width, H = ss->opt.height;
  double *rv = calloc(np, sizeof *rv), *a = malloc(np * sizeof *a), *box = malloc(np * sizeof *box);
  uint32_t *cap = malloc(np * sizeof *cap), *target = malloc(np * sizeof *target), *tmp = malloc(np * sizeof *tmp);
  uint32_t *fin = malloc(np * sizeof *fin), *first = malloc(np * sizeof *first);
  valo_status st = VALO_OK;
  if (!rv || !a || !box || !cap || !target || !tmp || !fin || !first) { st = err_set(err, VALO_ERR_NOMEM, "out of memory"); goto done; }
  double thr2 = ss->opt.noise_threshold > 0 ? ss->opt.noise_threshold * ss->opt.noise_threshold : 0;
  double taken = 0;
  for (size_t i = 0; i < np; i++) { rv[i] = adapt_pixel_relvar(ss, i); taken += ss->film.count[i]; }
  box_sums(rv, a, box, W, H);
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      size_t i = (size_t)y * W + x;
      int wx = (x + ADAPT_RADIUS < W ? x + ADAPT_RADIUS : W - 1) - (x - ADAPT_RADIUS > 0 ? x - ADAPT_RADIUS : 0) + 1;
      int wy = (y + ADAPT_RADIUS < H ? y + ADAPT_RADIUS : H - 1) - (y - ADAPT_RADIUS > 0 ? y - ADAPT_RADIUS : 0) + 1;
      int cnt = wx * wy - 1; /* without the pixel itself */
      double v = cnt > 0 ? (box[i] - rv[i]) / cnt : 0;
      if (!(v > 0)) v = 0;
      a[i] = sqrt(v);
      double c = thr2 > 0 ? ceil(v / thr2) : 2e9; /* sample indices are int */
      cap[i] = c < (double)ss->film.count[i] ? ss->film.count[i] : c > 2e9 ? 2000000000u : (uint32_t)c;
    }
  double rate = 0, t_prev = now_seconds();
  if (budget > 0) rate = taken / (t_prev - t0 > 1e-6 ? t_prev - t0 : 1e-6);
  /* A sample budget: the final counts at once, taken in equal stages of about 2 samples
   * per pixel (8 to 64 of them) so that progress moves; they depend on the budget alone,
   * so the image does not depend on timing. */
  int stages = 0, stage0 = 1;
  if (!(budget > 0) && ss->resumed && ss->resume.phase == CKPT_ADAPT_ERROR) {
    /* resumed: the plan made after the uniform passes, from the stage after the saved one */
    memcpy(first, ss->resume.first, np * sizeof *first);
    memcpy(fin, ss->resume.fin, np * sizeof *fin);
    stages = ss->resume.stages;
    stage0 = ss->resume.stage + 1;
  } else if (!(budget > 0)) {
    if (waterfill(ss, a, cap, np, total, fin, tmp) <= taken) goto finish; /* all at their noise threshold */
    for (size_t i = 0; i < np; i++) first[i] = ss->film.count[i];
    double per_pixel = (total - taken) / (double)np;
    stages = per_pixel / 2 < 8 ? 8 : per_pixel / 2 > 64 ? 64 : (int)(per_pixel / 2);
  }
  for (int stage = stage0;; stage++) {
    double sum = 0;
    if (budget > 0) {
      double rem = budget - (now_seconds() - t0);
      if (rem <= 0.02 * budget) break;
      double goal = taken + (rem > 0.1 * budget ? 0.6 : 0.95) * rate * rem;
      if (goal > total) goal = total;
      if (goal < taken + 1) break;
      sum = waterfill(ss, a, cap, np, goal, target, tmp);
      if (sum <= taken) break; /* nothing left to take: every pixel at its noise threshold */
    } else {
      if (stage > stages) break;
      for (size_t i = 0; i < np; i++) {
        target[i] = first[i] + (uint32_t)((uint64_t)(fin[i] - first[i]) * (uint64_t)stage / (uint64_t)stages);
        sum += target[i];
      }
    }
    double s0 = now_seconds();
    if ((st = tiles_render_to(ss, target, ts, err))) break; /* tiles keep rays coherent */
    if (atomic_load(&ss->cancel)) {
      st = err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d spp", (int)(taken / (double)np));
      break;
    }
    double el = now_seconds() - t0, dt = now_seconds() - s0;
    if (dt > 1e-6) rate = (sum - taken) / dt;
    taken = sum;
    if (session_report_progress(progress, user, taken / total, (int)(taken / (double)np), el, budget)) {
      st = err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d spp", (int)(taken / (double)np));
      break;
    }
    if (!(budget > 0)) {
      /* a sample budget's plan is fixed, so a stage boundary can be resumed from; a time
       * budget's stages depend on timing, and are not checkpointed */
      ss->spp_done = (int)(taken / (double)np);
      ss->ckpt_state = (ckpt_state){CKPT_ADAPT_ERROR, stage, stages, taken, first, fin};
      checkpoint_tick(ss, ts, t0);
    }
    if (taken >= total || (budget > 0 && el >= budget)) break;
  }
finish:
  ss->spp_done = (int)(taken / (double)np);
done:
  free(rv); free(a); free(box); free(cap); free(target); free(tmp); free(fin); free(first);
  return st;
}

