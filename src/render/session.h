/* session.h — owns one render (Cycles' word for it: a session): the film, the camera of
 * this frame and the last, the accelerator, the light sampler, the integrator instance,
 * the budgets, passes, frames, cancellation and progress, and the counters. The public
 * valo_render handle (src/api/) wraps it. Options reach it resolved and checked
 * (src/api/options.c). Within render/, calls run one way: session -> adaptive ->
 * checkpoint, and session -> dist (the MPI tile source) -> tiles (the tile loop and its
 * local source) -> aov -> film. */
#ifndef VALO_SESSION_H
#define VALO_SESSION_H
#include "integrator/integrator.h"
#include "render/film.h"
#include "scene/camera.h"
#include <stdatomic.h>

#define TILE 16 /* tiles of TILE x TILE pixels: the unit of work and of cancellation */
#define SESSION_RESTART_FRESH 2 /* session_step's restart: with sample indices not used before */

typedef struct session session;
struct tile_source; /* render/tiles.h: where a pass's tiles are rendered */
/* Where a checkpoint stands (render/checkpoint.h): the uniform passes, a stage of the
 * error rule's plan (the counts it started from, first, and ends at, fin), or a round
 * of the digest rule; taken: samples over the whole film. */
enum { CKPT_UNIFORM = 0, CKPT_ADAPT_ERROR = 1, CKPT_ADAPT_DIGEST = 2 };
typedef struct ckpt_state { int phase, stage, stages; double taken; uint32_t *first, *fin; } ckpt_state;
/* One rank's share of a render under MPI (render/dist.h): its host, threads, the tiles
 * and samples it rendered, its rays (prepare's included), its peak memory (bytes) and the
 * seconds it spent rendering. */
typedef struct rank_stats { char host[64]; int threads; uint64_t tiles, samples, rays, peak_memory; double busy_seconds; } rank_stats;
/* Called after each frame of a sequence (opt.frames > 0), from the thread that runs it. */
typedef valo_status (*session_frame_fn)(void *user, int frame, valo_error *err);

struct session {
  const scene *s;
  valo_options opt;        /* resolved: every field set */
  render_ctx ctx;
  const integrator_ops *integ;
  sampler_kind sampler_kind;
  accel *acc;
  accel_filter alpha_filter;
  film film;
  double param[INTEGRATOR_MAX_PARAMS];
  void *istate;            /* the integrator's create() result */
  float ao_dist;           /* ray length of the ao AOV */
  int spp_done;
  double build_seconds, render_seconds;
  thread_stats total;      /* rays, losses and surface samples of every run so far */
  thread_stats prep;       /* create's and prepare's, added to total at the end of a run */
  atomic_int cancel;
  camera cam_still;        /* the scene camera fitted to the film (frame 0 of an animation) */
  cam_lens lens;           /* this frame's camera and lens */
  pixel_filter filter;     /* the lens's pixel filter (lens.filter: NULL for the box of one pixel) */
  int batch;               /* camera samples traced together by integ->li_n (1: li one by one) */
  int splat;               /* samples splatted through filter (film.wsum; tiles.c renders tiles
                              in four rounds so that no two threads reach one pixel) */
  cam_view view_prev;      /* the previous frame's */
  int frames_done;         /* a sequence: frames finished */
  int image_frames;        /* render_frame calls made (the integrator's frame index) */
  float *frame_rgb;        /* render_frame output, width*height*3 */
  float *frame_wt;         /* and its samples' filter weights when the filter has negative lobes */
  float *frame_gbuf;       /* and its AOVs when the film keeps them (FRAME_GBUF per pixel) */
  session_frame_fn on_frame;
  void *on_frame_user;
  char ckpt_path[4096];    /* checkpoints to this file ("" for none), at pass boundaries */
  double ckpt_every;       /* at most this often (seconds; 0: every boundary) */
  double ckpt_last;        /* when the last was written (now_seconds) */
  double ckpt_run_seconds; /* this run's time at the checkpoint being written */
  ckpt_state ckpt_state;   /* the state at the boundary being checkpointed */
  ckpt_state resume;       /* the state a resumed render goes on from (owns first, fin) */
  int resumed;
  int view_frame;          /* the frame whose camera ss->lens holds */
  int frame_w, frame_h;    /* the camera's frame; the film (opt.width x opt.height) is its
                              window at (crop_x, crop_y): the whole frame without a crop */
  int crop_x, crop_y;
  int stepped;             /* rendered by session_step (valo view): image-wide frames as a sequence's */
  int64_t step_base;       /* steps: the sample index of the film's first sample */
  int64_t step_next;       /* steps: one past the largest sample index used */
  uint64_t restarts;       /* times the film was emptied for a new estimate (a step's restart, a
                              sequence's frame): the live denoiser's history is reprojected then */
  const struct tile_source *work; /* this process's threads, or under MPI rank 0 handing tiles to every rank */
  struct dist_state *dist; /* rank 0 under MPI: the other ranks' state (render/dist.c) */
  rank_stats *ranks;       /* rank 0 under MPI, after a run: every rank's share, nranks of them */
  int nranks;
};

/* Builds the accelerator, the light sampler, the camera (autofocus included) and the
 * integrator for scene s with resolved options o; params/ao_param are the integrator's
 * and the ao AOV's parameter values. */
valo_status session_create(const scene *s, const valo_options *o, const integrator_ops *integ, const double *params, float ao_dist,
                           session **out, valo_error *err);
void session_destroy(session *ss);
/* Renders: passes until the sample or time budget, or a sequence of frames. */
valo_status session_run(session *ss, valo_progress_fn progress, void *user, valo_error *err);
/* Moves the still camera (position, look-at, up, field of view); refused for sequences
 * and degenerate cameras, which leave it unchanged. */
valo_status session_set_camera(session *ss, const camera *c, valo_error *err);
/* One step of interactive rendering (valo_render_step in valo.h). */
valo_status session_step(session *ss, int spp, int restart, valo_error *err);
/* Calls the progress callback (if any) with the larger of frac and the share of the time
 * budget spent; non-zero when it asks to cancel. */
static inline int session_report_progress(valo_progress_fn progress, void *user, double frac, int spp, double el, double budget) {
  if (budget > 0 && el / budget > frac) frac = el / budget < 1 ? el / budget : 1;
  return progress && progress(user, frac, spp, el);
}
static inline int session_cancelled(const session *ss) { return atomic_load_explicit(&ss->cancel, memory_order_relaxed); }
#endif
