/* tiles.c — see tiles.h. Every sample draws its random numbers from (seed, pixel, sample
 * index, dimension), and each pixel's samples are summed in sample order, so the image is
 * the same for any thread count, tile order or number of processes (render/dist.c). */
#include "render/tiles.h"
#include "render/aov.h"
#include "core/threadpool.h"
#include "core/error.h"

typedef struct pass_job {
  session *ss;
  const tile_pass *p;
  thread_stats *ts; /* one per thread */
  int round;        /* splatting: the tiles (tx, ty) with (tx % 2, ty % 2) = (round % 2, round / 2) */
} pass_job;

int tiles_set_view(session *ss, int f) {
  camera c = ss->opt.frames > 0 ? scene_camera_at(ss->s, &ss->cam_still, (float)f) : ss->cam_still;
  ss->view_frame = f;
  cam_view *v = &ss->lens.view;
  int bad = cam_view_make(&c, ss->frame_w, ss->frame_h, v);
  v->x0 = ss->crop_x;
  v->y0 = ss->crop_y;
  v->film_w = ss->opt.width;
  v->film_h = ss->opt.height;
  return bad;
}

/* A camera sample: its pixel, the camera ray's filter weight and the splat's jitter (the
 * numbers camera_ray takes). */
typedef struct cam_sample {
  int x, y;
  float w, jx, jy;
} cam_sample;

/* Starts sample si of pixel (x, y): its sampler *smp, the camera ray *r and the AOVs of
 * its first hit. */
static void sample_start(session *ss, int x, int y, int si, thread_stats *ts, cam_sample *cs, ray *r, sampler *smp) {
  uint64_t pix = (uint64_t)y * (uint64_t)ss->opt.width + (uint64_t)x;
  /* the random numbers of the frame's pixel, so that a crop is that part of the frame's image */
  uint64_t frame_pix = (uint64_t)(y + ss->crop_y) * (uint64_t)ss->frame_w + (uint64_t)(x + ss->crop_x);
  cs->x = x;
  cs->y = y;
  *smp = sampler_make_kind((uint64_t)ss->opt.seed, frame_pix, (uint64_t)si, ss->sampler_kind);
  cs->jx = cs->jy = 0;
  if (ss->splat) { /* camera_ray's jitter over the pixel, the same numbers */
    sampler j = *smp;
    sampler_set_dim(&j, SDIM_FILM);
    sampler_2d(&j, &cs->jx, &cs->jy);
  }
  *r = camera_ray(&ss->lens, x, y, smp, &cs->w);
  ts->rays++;
  if (ss->film.aov) aov_record(ss, *r, &ss->film.aov[AOV_FLOATS * pix], smp, ts);
}

static void sample_finish(session *ss, const cam_sample *cs, rgb L, thread_stats *ts) {
  uint64_t pix = (uint64_t)cs->y * (uint64_t)ss->opt.width + (uint64_t)cs->x;
  if (ss->splat) film_add_splat(&ss->film, pix, (float)cs->x + cs->jx, (float)cs->y + cs->jy, L, &ss->filter, ts);
  else film_add(&ss->film, pix, L, cs->w, ts);
}

void tiles_sample_pixel(session *ss, int x, int y, int s0, int s1, thread_stats *ts) {
  for (int si = s0; si < s1; si++) {
    cam_sample cs;
    ray r;
    sampler smp;
    sample_start(ss, x, y, si, ts, &cs, &r, &smp);
    sample_finish(ss, &cs, ss->integ->li(&ss->ctx, r, &smp, ts), ts);
  }
}

/* Samples traced together (integ->li_n): taken in the tile loop's order and added to the
 * film in that order, so each pixel sums its samples as tiles_sample_pixel does. */
typedef struct sample_batch {
  int n;
  cam_sample cs[LI_BATCH_MAX];
  ray r[LI_BATCH_MAX];
  sampler smp[LI_BATCH_MAX];
  rgb L[LI_BATCH_MAX];
} sample_batch;

static void batch_flush(session *ss, sample_batch *b, thread_stats *ts) {
  ss->integ->li_n(&ss->ctx, b->r, b->smp, ts, b->L, b->n);
  for (int i = 0; i < b->n; i++) sample_finish(ss, &b->cs[i], b->L[i], ts);
  b->n = 0;
}

static void batch_pixel(session *ss, sample_batch *b, int x, int y, int s0, int s1, thread_stats *ts) {
  for (int si = s0; si < s1; si++) {
    sample_start(ss, x, y, si, ts, &b->cs[b->n], &b->r[b->n], &b->smp[b->n]);
    if (++b->n == ss->batch) batch_flush(ss, b, ts);
  }
}

int64_t tiles_count(const session *ss) {
  int64_t tx = (ss->opt.width + TILE - 1) / TILE, ty = (ss->opt.height + TILE - 1) / TILE;
  return tx * ty;
}

void tiles_rect(const session *ss, int64_t tile, int *x0, int *y0, int *x1, int *y1) {
  int tiles_x = (ss->opt.width + TILE - 1) / TILE;
  *x0 = (int)(tile % tiles_x) * TILE;
  *y0 = (int)(tile / tiles_x) * TILE;
  *x1 = *x0 + TILE < ss->opt.width ? *x0 + TILE : ss->opt.width;
  *y1 = *y0 + TILE < ss->opt.height ? *y0 + TILE : ss->opt.height;
}

uint64_t tiles_render_tile(session *ss, int64_t tile, int s0, int s1, const uint32_t *target, thread_stats *ts) {
  int x0, y0, x1, y1;
  tiles_rect(ss, tile, &x0, &y0, &x1, &y1);
  uint64_t taken = 0;
  sample_batch bs, *b = ss->batch > 1 ? &bs : NULL; /* on the stack: about 100 KB */
  bs.n = 0;
  for (int y = y0; y < y1; y++)
    for (int x = x0; x < x1; x++) {
      int a = s0, e = s1;
      if (target) {
        size_t pix = (size_t)y * (size_t)ss->opt.width + (size_t)x;
        a = (int)ss->film.count[pix];
        e = (int)target[pix];
      }
      if (e <= a) continue;
      if (b) batch_pixel(ss, b, x, y, a, e, ts);
      else tiles_sample_pixel(ss, x, y, a, e, ts);
      taken += (uint64_t)(e - a);
    }
  if (b && b->n) batch_flush(ss, b, ts);
  return taken;
}

static void render_tile(void *user, int64_t item, int thread) {
  pass_job *j = user;
  if (session_cancelled(j->ss)) return;
  tiles_render_tile(j->ss, item, j->p->s0, j->p->s1, j->p->target, &j->ts[thread]);
}

/* The item-th tile of a splatting round: tiles two apart in x and y, whose splats (at
 * most the filter's radius, up to TILE / 2 pixels, past their edges) never meet. */
static int64_t round_tile(const session *ss, int round, int64_t item) {
  int64_t tx = (ss->opt.width + TILE - 1) / TILE, nx = (tx - round % 2 + 1) / 2;
  return (item / nx * 2 + round / 2) * tx + item % nx * 2 + round % 2;
}
static void render_round_tile(void *user, int64_t item, int thread) {
  pass_job *j = user;
  if (session_cancelled(j->ss)) return;
  tiles_render_tile(j->ss, round_tile(j->ss, j->round, item), j->p->s0, j->p->s1, j->p->target, &j->ts[thread]);
}

static valo_status local_run(session *ss, const tile_pass *p, thread_stats *ts, valo_error *err) {
  (void)err;
  pass_job job = {ss, p, ts, 0};
  if (!ss->splat) {
    parallel_for(ss->opt.threads, tiles_count(ss), render_tile, &job);
    return VALO_OK;
  }
  /* Four rounds, one after another: a pixel gets its splats from up to four tiles, always
   * in round order, so the image does not depend on the thread count. */
  int64_t tx = (ss->opt.width + TILE - 1) / TILE, ty = (ss->opt.height + TILE - 1) / TILE;
  for (job.round = 0; job.round < 4; job.round++) {
    int64_t nx = (tx - job.round % 2 + 1) / 2, ny = (ty - job.round / 2 + 1) / 2;
    if (nx > 0 && ny > 0) parallel_for(ss->opt.threads, nx * ny, render_round_tile, &job);
  }
  return VALO_OK;
}
const tile_source tiles_local = {local_run};

static valo_status run_tiles(session *ss, int s0, int s1, const uint32_t *target, int prep, thread_stats *ts, valo_error *err) {
  tile_pass p = {s0, s1, target, prep};
  return (ss->work ? ss->work : &tiles_local)->run(ss, &p, ts, err);
}

valo_status tiles_render_to(session *ss, const uint32_t *target, thread_stats *ts, valo_error *err) { return run_tiles(ss, 0, 0, target, -1, ts, err); }

valo_status tiles_render(session *ss, int s0, int s1, thread_stats *ts, valo_error *err) {
  for (int a = s0; a < s1;) {
    int b = s1;
    if (ss->integ->prepare) {
      b = a + 1;
      valo_status pst = ss->integ->prepare(ss->istate, &ss->ctx, a, err);
      if (pst) return pst;
    }
    valo_status st = run_tiles(ss, a, b, NULL, ss->integ->prepare ? a : -1, ts, err);
    if (st) return st;
    if (atomic_load(&ss->cancel)) return err_set(err, VALO_ERR_CANCELLED, "render cancelled");
    a = b;
  }
  return VALO_OK;
}
