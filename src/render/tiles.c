/* tiles.c — see tiles.h. Every sample draws its random numbers from (seed, pixel, sample
 * index, dimension), and each pixel's samples are summed in sample order, so the image is
 * the same for any thread count or tile order. */
#include "render/tiles.h"
#include "render/aov.h"
#include "core/threadpool.h"
#include "core/error.h"

typedef struct pass_job {
  session *ss;
  int s0, s1;             /* sample indices [s0, s1) */
  const uint32_t *target; /* or, when not NULL: each pixel from its count up to target[pix] */
  int tiles_x;
  thread_stats *ts;       /* one per thread */
} pass_job;

void tiles_sample_pixel(session *ss, int x, int y, int s0, int s1, thread_stats *ts) {
  uint64_t pix = (uint64_t)y * (uint64_t)ss->opt.width + (uint64_t)x;
  for (int si = s0; si < s1; si++) {
    sampler smp = sampler_make_kind((uint64_t)ss->opt.seed, pix, (uint64_t)si, ss->sampler_kind);
    ray ry = camera_ray(&ss->lens, x, y, &smp);
    ts->rays++;
    if (ss->film.aov) aov_record(ss, ry, &ss->film.aov[AOV_FLOATS * pix], &smp, ts);
    film_add(&ss->film, pix, ss->integ->li(&ss->ctx, ry, &smp, ts), ts);
  }
}

static void render_tile(void *user, int64_t item, int thread) {
  pass_job *j = user;
  session *ss = j->ss;
  if (session_cancelled(ss)) return;
  thread_stats *ts = &j->ts[thread];
  int tx = (int)(item % j->tiles_x), ty = (int)(item / j->tiles_x);
  int x0 = tx * TILE, y0 = ty * TILE;
  int x1 = x0 + TILE < ss->opt.width ? x0 + TILE : ss->opt.width;
  int y1 = y0 + TILE < ss->opt.height ? y0 + TILE : ss->opt.height;
  for (int y = y0; y < y1; y++)
    for (int x = x0; x < x1; x++) {
      if (!j->target) { tiles_sample_pixel(ss, x, y, j->s0, j->s1, ts); continue; }
      size_t pix = (size_t)y * (size_t)ss->opt.width + (size_t)x;
      int c = (int)ss->film.count[pix], t = (int)j->target[pix];
      if (t > c) tiles_sample_pixel(ss, x, y, c, t, ts);
    }
}

static void run_tiles(session *ss, int s0, int s1, const uint32_t *target, thread_stats *ts) {
  int tiles_x = (ss->opt.width + TILE - 1) / TILE, tiles_y = (ss->opt.height + TILE - 1) / TILE;
  pass_job job = {ss, s0, s1, target, tiles_x, ts};
  parallel_for(ss->opt.threads, (int64_t)tiles_x * tiles_y, render_tile, &job);
}

void tiles_render_to(session *ss, const uint32_t *target, thread_stats *ts) { run_tiles(ss, 0, 0, target, ts); }

valo_status tiles_render(session *ss, int s0, int s1, thread_stats *ts, valo_error *err) {
  for (int a = s0; a < s1;) {
    int b = s1;
    if (ss->integ->prepare) {
      b = a + 1;
      valo_status pst = ss->integ->prepare(ss->istate, &ss->ctx, a, err);
      if (pst) return pst;
    }
    run_tiles(ss, a, b, NULL, ts);
    if (atomic_load(&ss->cancel)) return err_set(err, VALO_ERR_CANCELLED, "render cancelled");
    a = b;
  }
  return VALO_OK;
}
