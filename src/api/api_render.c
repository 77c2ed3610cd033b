/* api_render.c — owns the public render handle: valo_render is a render session
 * (src/render/session.h) with the frame callback and warning handler the caller gave.
 * Each function checks its handle, routes warnings to the handle's handler, resolves
 * options (options.c) and calls inward. */
#include "integrator/ao.h"
#include "valo/valo.h"
#include "api/api.h"
#include "api/options.h"
#include "render/session.h"
#include "render/output.h"
#include "render/live.h"
#include "render/checkpoint.h"
#include "render/dist.h"
#include "core/error.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct valo_render {
  session *ss;
  live_state *live; /* valo_render_denoise_live's history, made on its first call */
  valo_frame_fn on_frame;
  void *on_frame_user;
  valo_log_fn warn_fn;
  void *warn_user;
};

static void clear_err(valo_error *err) {
  if (err) { err->status = VALO_OK; err->message[0] = 0; }
}

VALO_API valo_status valo_render_create(const valo_scene *vs, const valo_options *opts, valo_render **out, valo_error *err) {
  *out = NULL;
  clear_err(err);
  if (!vs) return err_set(err, VALO_ERR_INVALID, "no scene");
  log_scope scope;
  log_scope_enter(&scope, vs->warn_fn, vs->warn_user);
  resolved_options ro;
  valo_render *r = NULL;
  valo_status st = options_resolve(&vs->file_opts, opts, &ro, err);
  if (!st && dist_size() > 1 && ro.integ->kind == INTEGRATOR_IMAGE)
    st = err_set(err, VALO_ERR_INVALID, "%s is image-wide (its stages share the whole image each frame): it runs in one process, not across %d MPI ranks",
                 ro.integ->name, dist_size());
  if (!st && !(r = calloc(1, sizeof *r))) st = err_set(err, VALO_ERR_NOMEM, "out of memory");
  if (!st) {
    r->warn_fn = vs->warn_fn;
    r->warn_user = vs->warn_user;
    st = session_create(vs->s, &ro.o, ro.integ, ro.param, ao_ray_length(vs->s, ro.ao_distance), &r->ss, err);
  }
  if (st) { free(r); r = NULL; }
  log_scope_leave(&scope);
  *out = r;
  return st;
}

VALO_API void valo_render_set_warning_handler(valo_render *r, valo_log_fn fn, void *user) {
  if (!r) return;
  r->warn_fn = fn;
  r->warn_user = user;
}

static valo_status frame_callback(void *user, int f, valo_error *err) {
  valo_render *r = user;
  return r->on_frame(r->on_frame_user, r, f, err);
}

VALO_API void valo_render_on_frame(valo_render *r, valo_frame_fn fn, void *user) {
  if (!r) return;
  r->on_frame = fn;
  r->on_frame_user = user;
  r->ss->on_frame = fn ? frame_callback : NULL;
  r->ss->on_frame_user = r;
}

VALO_API const char *valo_loss_name(int cause) { return stats_loss_name(cause); }

static valo_status checkpointable(const valo_render *r, valo_error *err) {
  if (!r) return err_set(err, VALO_ERR_INVALID, "no render");
  if (r->ss->opt.frames > 0) return err_set(err, VALO_ERR_INVALID, "checkpoints are for still images, not sequences (--frames)");
  if (r->ss->integ->kind == INTEGRATOR_IMAGE)
    return err_set(err, VALO_ERR_INVALID, "checkpoints are not supported for image-wide integrators (%s)", r->ss->integ->name);
  return VALO_OK;
}

VALO_API valo_status valo_render_checkpoint_to(valo_render *r, const char *path, double every_seconds, valo_error *err) {
  clear_err(err);
  valo_status st = checkpointable(r, err);
  if (st) return st;
  if (dist_rank() > 0) return VALO_OK; /* rank 0 checkpoints for every rank */
  if (!path || !*path || strlen(path) >= sizeof r->ss->ckpt_path) return err_set(err, VALO_ERR_INVALID, "no checkpoint file, or its name is too long");
  if (!(every_seconds >= 0)) return err_set(err, VALO_ERR_INVALID, "checkpoint interval %g: must be 0 or more seconds", every_seconds);
  snprintf(r->ss->ckpt_path, sizeof r->ss->ckpt_path, "%s", path);
  r->ss->ckpt_every = every_seconds;
  return VALO_OK;
}

VALO_API valo_status valo_render_resume(valo_render *r, const char *path, valo_error *err) {
  clear_err(err);
  valo_status st = checkpointable(r, err);
  if (st) return st;
  if (r->ss->resumed || r->ss->spp_done > 0) return err_set(err, VALO_ERR_INVALID, "resume before the render runs");
  if (dist_rank() > 0) return VALO_OK; /* rank 0 resumes and hands its film out */
  log_scope scope;
  log_scope_enter(&scope, r->warn_fn, r->warn_user);
  st = checkpoint_read(r->ss, path, err);
  log_scope_leave(&scope);
  return st;
}

VALO_API valo_status valo_render_run(valo_render *r, valo_progress_fn progress, void *user, valo_error *err) {
  clear_err(err);
  if (!r) return err_set(err, VALO_ERR_INVALID, "no render");
  log_scope scope;
  log_scope_enter(&scope, r->warn_fn, r->warn_user);
  valo_status st = session_run(r->ss, progress, user, err);
  log_scope_leave(&scope);
  return st;
}

VALO_API void valo_render_cancel(valo_render *r) {
  if (r) atomic_store(&r->ss->cancel, 1);
}

VALO_API void valo_render_stats(const valo_render *r, valo_stats *o) {
  memset(o, 0, sizeof *o);
  const session *ss = r->ss;
  o->triangles = ss->s->ntris;
  o->build_seconds = ss->build_seconds;
  o->render_seconds = ss->render_seconds;
  o->rays = ss->total.rays;
  memcpy(o->lost, ss->total.lost, sizeof o->lost);
  o->surface_samples = ss->total.surface_samples;
  o->spp_done = ss->spp_done;
  o->frames_done = ss->frames_done;
  size_t np = film_pixels(&ss->film);
  for (size_t i = 0; i < np; i++) o->samples += ss->film.count[i];
  o->width = ss->opt.width;
  o->height = ss->opt.height;
  o->threads = ss->opt.threads;
  snprintf(o->integrator, sizeof o->integrator, "%s", ss->opt.integrator);
  snprintf(o->accel, sizeof o->accel, "%s", ss->opt.accel);
  snprintf(o->sampler, sizeof o->sampler, "%s", ss->opt.sampler);
  snprintf(o->light_sampler, sizeof o->light_sampler, "%s", ss->opt.light_sampler);
}

VALO_API int valo_render_rank_stats(const valo_render *r, int k, valo_rank_stats *out) {
  memset(out, 0, sizeof *out);
  if (!r || k < 0 || k >= r->ss->nranks) return -1;
  const rank_stats *rs = &r->ss->ranks[k];
  snprintf(out->host, sizeof out->host, "%s", rs->host);
  out->threads = rs->threads;
  out->tiles = rs->tiles;
  out->samples = rs->samples;
  out->rays = rs->rays;
  out->peak_memory_bytes = rs->peak_memory;
  out->busy_seconds = rs->busy_seconds;
  return 0;
}

VALO_API int valo_mpi_init(int *argc, char ***argv) { return dist_init(argc, argv); }
VALO_API int valo_mpi_rank(void) { return dist_rank(); }
VALO_API int valo_mpi_size(void) { return dist_size(); }
VALO_API void valo_mpi_finalize(void) { dist_finalize(); }
VALO_API int valo_mpi_agree(int code, valo_error *err) {
  valo_error local;
  if (!err) { err = &local; local.message[0] = 0; }
  return dist_agree(code, err);
}

VALO_API void valo_render_camera(const valo_render *r, valo_camera *o) {
  memset(o, 0, sizeof *o);
  if (!r) return;
  const camera *c = &r->ss->cam_still;
  const vec3 v[3] = {c->pos, c->look_at, c->up};
  double *d[3] = {o->pos, o->look_at, o->up};
  for (int k = 0; k < 3; k++) { d[k][0] = v[k].x; d[k][1] = v[k].y; d[k][2] = v[k].z; }
  o->fov_deg = c->fov_deg;
  o->ortho_height = c->ortho_height;
  o->spherical = c->spherical;
}

VALO_API valo_status valo_render_set_camera(valo_render *r, const valo_camera *c, valo_error *err) {
  clear_err(err);
  if (!r || !c) return err_set(err, VALO_ERR_INVALID, "no render or no camera");
  camera cam = r->ss->cam_still;
  cam.pos = v3((float)c->pos[0], (float)c->pos[1], (float)c->pos[2]);
  cam.look_at = v3((float)c->look_at[0], (float)c->look_at[1], (float)c->look_at[2]);
  cam.up = v3((float)c->up[0], (float)c->up[1], (float)c->up[2]);
  cam.fov_deg = (float)c->fov_deg;
  cam.ortho_height = (float)c->ortho_height;
  cam.spherical = c->spherical != 0;
  return session_set_camera(r->ss, &cam, err);
}

VALO_API valo_status valo_render_step(valo_render *r, int spp, int restart, valo_error *err) {
  clear_err(err);
  if (!r) return err_set(err, VALO_ERR_INVALID, "no render");
  if (restart < 0 || restart > VALO_STEP_FRESH) return err_set(err, VALO_ERR_INVALID, "restart %d: 0, 1 or VALO_STEP_FRESH", restart);
  log_scope scope;
  log_scope_enter(&scope, r->warn_fn, r->warn_user);
  valo_status st = session_step(r->ss, spp, restart == VALO_STEP_FRESH ? SESSION_RESTART_FRESH : restart, err);
  log_scope_leave(&scope);
  return st;
}

VALO_API valo_status valo_render_layer(const valo_render *r, const char *layer, float *rgb_out, valo_error *err) {
  clear_err(err);
  if (!r || !layer || !rgb_out) return err_set(err, VALO_ERR_INVALID, "no render, layer or buffer");
  return output_layer(r->ss, layer, rgb_out, err);
}

VALO_API valo_status valo_render_denoise_live(valo_render *r, float *rgb_out, valo_error *err) {
  clear_err(err);
  if (!r || !rgb_out) return err_set(err, VALO_ERR_INVALID, "no render or buffer");
  return live_denoise(&r->live, r->ss, rgb_out, err);
}

VALO_API void valo_render_denoise_reset(valo_render *r) {
  if (r) live_reset(r->live);
}

VALO_API void valo_render_pixels(const valo_render *r, float *rgb_out) { film_resolve(&r->ss->film, rgb_out); }

VALO_API valo_status valo_render_write(const valo_render *r, const char *path, const valo_output_options *o, valo_error *err) {
  clear_err(err);
  if (!r || !path) return err_set(err, VALO_ERR_INVALID, "no render or no path");
  valo_output_options def;
  valo_output_options_init(&def);
  log_scope scope;
  log_scope_enter(&scope, r->warn_fn, r->warn_user);
  valo_status st = output_write(r->ss, path, o ? o : &def, err);
  log_scope_leave(&scope);
  return st;
}

VALO_API void valo_render_destroy(valo_render *r) {
  if (!r) return;
  live_free(r->live);
  session_destroy(r->ss);
  free(r);
}
