/* session.c — see session.h. */
#include "render/session.h"
#include "render/adaptive.h"
#include "render/tiles.h"
#include "render/checkpoint.h"
#include "render/dist.h"
#include "core/clock.h"
#include "core/error.h"
#include "core/memlimit.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int alpha_filter_pass(const void *user, uint32_t tri, float b1, float b2, uint64_t key) { return scene_alpha_pass(user, tri, b1, b2, key); }

valo_status session_create(const scene *s, const valo_options *opts, const integrator_ops *integ, const double *params, float ao_dist,
                           session **out, valo_error *err) {
  *out = NULL;
  if (s->has_media && strcmp(integ->name, "path") && strcmp(integ->name, "path-spectral"))
    return err_set(err, VALO_ERR_UNSUPPORTED, "%s: participating media and null surfaces are rendered by the path integrator only, not %s",
                   s->path, integ->name);
  /* A crop window is the film: opt.width and height are its size from here on, and the
   * camera sees the whole frame. */
  valo_options o = *opts;
  int frame_w = o.width, frame_h = o.height, crop = o.crop_width > 0 && o.crop_height > 0;
  if (crop) { o.width = o.crop_width; o.height = o.crop_height; }
  session *ss = calloc(1, sizeof *ss);
  if (!ss) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  ss->s = s;
  ss->opt = o;
  ss->frame_w = frame_w;
  ss->frame_h = frame_h;
  ss->crop_x = crop ? o.crop_x : 0;
  ss->crop_y = crop ? o.crop_y : 0;
  ss->integ = integ;
  ss->work = dist_size() > 1 && dist_rank() == 0 ? &dist_master : &tiles_local;
  memcpy(ss->param, params, sizeof ss->param);
  ss->ao_dist = ao_dist;
  ss->sampler_kind = strcmp(o.sampler, "independent") ? SAMPLER_SOBOL : SAMPLER_INDEPENDENT;
  atomic_init(&ss->cancel, 0);
  valo_status st = VALO_OK;
  /* the film's sums (double RGB), counts, the adaptive squares and AOV sums when asked,
   * an image integrator's frame, and the float pixels an output is made from */
  uint64_t per_px = 3 * 8 + 4 + (o.adaptive || (o.aovs > 0 && (o.aovs & VALO_AOVS_VARIANCE)) ? 4 * 8 : 0) + (o.aovs ? AOV_FLOATS * 4 : 0) + (integ->kind == INTEGRATOR_IMAGE ? 12 + (o.aovs ? FRAME_GBUF * 4 : 0) : 0) + 12;
  if ((st = mem_check_pixels((uint64_t)o.width, (uint64_t)o.height, per_px, "film", err))) goto fail;
  if (film_init(&ss->film, o.width, o.height, o.adaptive != 0 || (o.aovs > 0 && (o.aovs & VALO_AOVS_VARIANCE)), o.aovs != 0) ||
      (integ->kind == INTEGRATOR_IMAGE && !(ss->frame_rgb = calloc((size_t)o.width * o.height * 3, sizeof(float)))) ||
      (integ->kind == INTEGRATOR_IMAGE && o.aovs && !(ss->frame_gbuf = calloc((size_t)o.width * o.height * FRAME_GBUF, sizeof(float))))) {
    st = err_set(err, VALO_ERR_NOMEM, "out of memory for a %dx%d film", o.width, o.height);
    goto fail;
  }
  double t0 = now_seconds();
  int any_alpha = 0;
  for (uint32_t t = 0; t < s->ntris && !any_alpha; t++) any_alpha = (s->tri_flags[t] & TRI_ALPHA) != 0;
  ss->alpha_filter.pass = alpha_filter_pass;
  ss->alpha_filter.user = s;
  ss->alpha_filter.tri_flags = s->tri_flags;
  ss->alpha_filter.flag_bit = TRI_ALPHA;
  st = accel_create(o.accel, s->pos, s->cap_verts, s->idx, s->ntris, o.threads, any_alpha ? &ss->alpha_filter : NULL, &ss->acc, err);
  if (st) goto fail;
  ss->build_seconds = now_seconds() - t0;
  int cones = strcmp(o.sphere_lights, "triangles") != 0;
  if (light_sampler_init(&ss->ctx.ls, s, strcmp(o.light_sampler, "power") ? LIGHT_SELECT_GRID : LIGHT_SELECT_POWER, cones)) {
    st = err_set(err, VALO_ERR_NOMEM, "out of memory");
    goto fail;
  }
  ss->ctx.s = s;
  ss->ctx.acc = ss->acc;
  ss->ctx.max_depth = o.max_depth;
  ss->ctx.rr_depth = o.rr_depth;
  ss->batch = integ->li_n && o.batch > 1 ? (o.batch < LI_BATCH_MAX ? o.batch : LI_BATCH_MAX) : 1;
  ss->ctx.hide_emitters = o.hide_emitters > 0;
  ss->ctx.param = ss->param;
  ss->ctx.seed = (uint64_t)o.seed;
  ss->ctx.threads = o.threads;
  ss->ctx.width = o.width;
  ss->ctx.height = o.height;
  ss->ctx.sampler_kind = ss->sampler_kind;
  ss->ctx.prep = &ss->prep;
  ss->ctx.lens = &ss->lens;
  ss->ctx.spp = o.spp;
  ss->ctx.time_budget = o.time_budget > 0 ? o.time_budget : 0;
  /* Camera basis; an automatic camera is fitted to this film's aspect first. */
  ss->cam_still = scene_camera_fit(s, (float)frame_w / (float)frame_h);
  const camera *c = &ss->cam_still;
  if (tiles_set_view(ss, 0)) {
    st = err_set(err, VALO_ERR_INVALID, "%s: camera up vector is parallel to the view direction", s->path);
    goto fail;
  }
  ss->view_prev = ss->lens.view;
  if (pixel_filter_make(&ss->filter, o.filter, o.filter_radius != VALO_UNSET ? o.filter_radius : 0)) {
    st = err_set(err, VALO_ERR_INVALID, "unknown pixel filter \"%s\" (box, tent, gaussian, blackman-harris, mitchell, catmull-rom or lanczos)", o.filter);
    goto fail;
  }
  ss->lens.filter = ss->filter.kind == FILTER_BOX && ss->filter.radius == 0.5f ? NULL : &ss->filter;
  /* Splatting: a positive filter wider than the pixel's box and at most TILE / 2 pixels
   * in radius (tiles.c's rounds), samples from the tile loop. */
  if (o.splat == 1 && ss->lens.filter && ss->filter.weight == 1 && ss->filter.radius <= TILE / 2 && integ->kind != INTEGRATOR_IMAGE) {
    if (dist_size() > 1) {
      log_warning("splatting into neighbouring pixels is not done across MPI ranks: the filter is sampled instead (the same image in expectation)");
    } else {
      if (film_enable_splat(&ss->film)) {
        st = err_set(err, VALO_ERR_NOMEM, "out of memory for a %dx%d film", o.width, o.height);
        goto fail;
      }
      ss->splat = 1;
      ss->lens.filter = NULL; /* samples jittered over their pixel, then splatted through ss->filter */
    }
  }
  if (integ->kind == INTEGRATOR_IMAGE && ss->filter.weight != 1 && !(ss->frame_wt = calloc((size_t)o.width * o.height, sizeof(float)))) {
    st = err_set(err, VALO_ERR_NOMEM, "out of memory for a %dx%d film", o.width, o.height);
    goto fail;
  }
  ss->lens.aperture = o.aperture_radius != VALO_UNSET ? (float)o.aperture_radius : c->aperture_radius;
  if (c->spherical && ss->lens.aperture > 0) {
    st = err_set(err, VALO_ERR_INVALID, "%s: a spherical camera has no lens (aperture %g)", s->path, (double)ss->lens.aperture);
    goto fail;
  }
  ss->lens.focus = o.focus_distance != VALO_UNSET ? (float)o.focus_distance : c->focus_distance;
  if (!(ss->lens.focus > 0)) {
    /* Autofocus (file cameras carry no focus distance): the surface at the image
     * centre, or the distance to the look-at point if the centre ray escapes. */
    ray cr = {ss->lens.view.o, ss->lens.view.fwd, INFINITY};
    hit h;
    int hit_centre = accel_intersect(ss->acc, &cr, &h);
    ss->lens.focus = hit_centre ? h.t : v3_len(v3_sub(c->look_at, c->pos));
    if (!(ss->lens.focus > 0)) ss->lens.focus = 1;
    if (ss->lens.aperture > 0 && !hit_centre)
      log_warning("%s: autofocus: the ray through the image centre hits nothing, so the lens focuses at %g (%s); set --focus", s->path,
                  (double)ss->lens.focus, ss->lens.focus == 1 && !(v3_len(v3_sub(c->look_at, c->pos)) > 0) ? "a fallback" : "the look-at distance");
  }
  if (integ->create) {
    st = integ->create(&ss->ctx, &ss->istate, err);
    if (st) goto fail;
    ss->ctx.state = ss->istate;
  }
  *out = ss;
  return VALO_OK;
fail:
  session_destroy(ss);
  return st;
}

void session_destroy(session *ss) {
  if (!ss) return;
  free(ss->resume.first);
  free(ss->resume.fin);
  free(ss->ranks);
  accel_destroy(ss->acc);
  light_sampler_free(&ss->ctx.ls);
  if (ss->integ && ss->integ->destroy && ss->istate) ss->integ->destroy(ss->istate);
  film_free(&ss->film);
  free(ss->frame_rgb);
  free(ss->frame_wt);
  free(ss->frame_gbuf);
  free(ss);
}

/* One frame of an image-wide integrator, added to the film as one sample per pixel (in
 * pixel order: the film does not depend on the thread count). */
static valo_status image_frame(session *ss, thread_stats *ts, valo_error *err) {
  frame_ctx f = {ss->image_frames, ss->image_frames ? ss->view_prev : ss->lens.view, ss->frame_rgb, ts, &ss->cancel,
                 ss->opt.frames > 0 || ss->stepped, &ss->lens, ss->frame_wt, ss->frame_gbuf};
  valo_status st = ss->integ->render_frame(ss->istate, &ss->ctx, &f, err);
  if (st) return st;
  ss->image_frames++;
  ss->view_prev = ss->lens.view;
  size_t np = (size_t)ss->opt.width * ss->opt.height;
  for (size_t i = 0; i < np; i++) {
    film_add(&ss->film, i, c3(ss->frame_rgb[3 * i], ss->frame_rgb[3 * i + 1], ss->frame_rgb[3 * i + 2]), ss->frame_wt ? ss->frame_wt[i] : 1, &ts[0]);
    if (ss->frame_gbuf) {
      const float *g = &ss->frame_gbuf[FRAME_GBUF * i];
      float *a = &ss->film.aov[AOV_FLOATS * i];
      for (int k = 0; k < 3; k++) { a[AOV_ALBEDO + k] += g[k]; a[AOV_NORMAL + k] += g[3 + k]; a[AOV_EMIT + k] += g[7 + k]; }
      a[AOV_DEPTH] += g[6];
    }
  }
  return VALO_OK;
}

/* A sequence (opt.frames): each frame on its own camera (the animation's), with a fresh
 * film of spp samples per pixel, handed to the frame callback. Sample indices go on
 * from frame to frame (frame f takes [f spp, (f+1) spp)), so no two frames share noise. */
static valo_status run_sequence(session *ss, valo_progress_fn progress, void *user, thread_stats *ts, valo_error *err) {
  double t0 = now_seconds();
  double budget = ss->opt.time_budget > 0 ? ss->opt.time_budget : 0;
  for (int f = ss->frames_done; f < ss->opt.frames; f++) {
    if (tiles_set_view(ss, f)) return err_set(err, VALO_ERR_INVALID, "%s: the camera at frame %d has its up vector along the view direction", ss->s->path, f);
    film_clear(&ss->film);
    ss->spp_done = 0;
    ss->restarts++;
    if (ss->integ->kind == INTEGRATOR_IMAGE) {
      for (int k = 0; k < ss->opt.spp; k++) {
        valo_status st = image_frame(ss, ts, err);
        if (st) return st;
        ss->spp_done++;
      }
    } else {
      int64_t s0 = (int64_t)f * ss->opt.spp;
      if (s0 + ss->opt.spp > UINT32_MAX) return err_set(err, VALO_ERR_INVALID, "frames x spp is more than 2^32 sample indices");
      valo_status st = tiles_render(ss, (int)s0, (int)(s0 + ss->opt.spp), ts, err);
      if (st) return st;
      ss->spp_done = ss->opt.spp;
    }
    ss->frames_done++;
    if (ss->on_frame) {
      valo_status st = ss->on_frame(ss->on_frame_user, f, err);
      if (st) return st;
    }
    double el = now_seconds() - t0;
    double frac = (double)(f + 1) / ss->opt.frames;
    if (progress && progress(user, frac, ss->spp_done, el)) return err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d frames", ss->frames_done);
    if (budget > 0 && el >= budget) break;
  }
  return VALO_OK;
}

/* The end of session_run: time and per-thread counters into the render's totals, and
 * a warning naming each cause of dropped camera samples or BSDF failures (shading-normal
 * refusals are expected with interpolated normals: valo_stats reports them). Frees ts. */
static valo_status run_finish(session *ss, thread_stats *ts, double t0, valo_status st) {
  ss->render_seconds += now_seconds() - t0;
  thread_stats sum = ss->prep;
  memset(&ss->prep, 0, sizeof ss->prep);
  for (int t = 0; t < ss->opt.threads; t++) thread_stats_add(&sum, &ts[t]);
  free(ts);
  if (dist_size() > 1 && dist_rank() > 0) return st; /* rank 0 counts and reports every rank's */
  if (dist_size() > 1) dist_finish(ss, &sum);
  thread_stats_add(&ss->total, &sum);
  const uint64_t *run = sum.lost;
  for (int k = 0; k < VALO_LOSS_COUNT; k++) {
    if (run[k] && k <= VALO_LOSS_NEGATIVE)
      log_warning("%llu samples were %s and were dropped (their pixels are darker)", (unsigned long long)run[k], stats_loss_name(k));
    else if (run[k] && k == VALO_LOSS_BSDF_NONFINITE)
      log_warning("%llu BSDF samples had a non-finite weight or pdf and ended their paths", (unsigned long long)run[k]);
  }
  return st;
}

valo_status session_run(session *ss, valo_progress_fn progress, void *user, valo_error *err) {
  int threads = ss->opt.threads;
  thread_stats *ts = thread_stats_alloc(threads);
  if (!ts) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  double t0 = now_seconds();
  if (dist_size() > 1 && dist_rank() > 0) return run_finish(ss, ts, t0, dist_worker(ss, ts, err));
  if (ss->opt.frames > 0) return run_finish(ss, ts, t0, run_sequence(ss, progress, user, ts, err));
  double budget = ss->opt.time_budget > 0 ? ss->opt.time_budget : 0;
  int pass_spp = 1;
  valo_status st = VALO_OK;
  int uniform_spp = ss->opt.spp;
  if (ss->opt.adaptive) {
    uniform_spp = (int)(ss->opt.spp * ADAPT_UNIFORM);
    if (uniform_spp < 4) uniform_spp = ss->opt.spp < 4 ? ss->opt.spp : 4;
  }
  /* Passes grow until one takes about a second, so progress stays lively. */
  /* a render resumed in its adaptive phase goes straight on with it */
  int adaptive_resumed = ss->resumed && ss->resume.phase != CKPT_UNIFORM;
  ss->ckpt_last = t0;
  while (ss->spp_done < uniform_spp && !adaptive_resumed) {
    int n = pass_spp;
    if (ss->spp_done + n > uniform_spp) n = uniform_spp - ss->spp_done;
    /* One sample index per pass for integrators with prepare (its light paths are shot
     * first) and for image-wide ones (a still is frames on the static camera, averaged). */
    if (ss->integ->prepare || ss->integ->kind == INTEGRATOR_IMAGE) n = 1;
    double p0 = now_seconds();
    valo_status pst = ss->integ->kind == INTEGRATOR_IMAGE ? image_frame(ss, ts, err) : tiles_render(ss, ss->spp_done, ss->spp_done + n, ts, err);
    if (pst && pst != VALO_ERR_CANCELLED) { st = pst; break; }
    double pt = now_seconds() - p0;
    if (atomic_load(&ss->cancel)) {
      /* A cancelled pass stops between tiles: every tile holds whole samples (a tile
       * that started finished its samples), so the film stays a valid image. Pixels of
       * the tiles this pass finished hold n more samples; spp_done counts whole passes. */
      st = err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d spp", ss->spp_done);
      break;
    }
    ss->spp_done += n;
    double el = now_seconds() - t0;
    double frac = (double)ss->spp_done / ss->opt.spp;
    if (session_report_progress(progress, user, frac, ss->spp_done, el, budget)) {
      st = err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d spp", ss->spp_done);
      break;
    }
    ss->ckpt_state = (ckpt_state){CKPT_UNIFORM, 0, 0, 0, NULL, NULL};
    checkpoint_tick(ss, ts, t0);
    if (budget > 0 && el >= budget) break;
    /* Adaptive with a time budget: the uniform first pass gets ADAPT_UNIFORM of the time
     * (at least 4 spp), as it gets that share of a sample budget, so adaptive sampling
     * has the rest. */
    if (ss->opt.adaptive && budget > 0 && el >= budget * ADAPT_UNIFORM && ss->spp_done >= 4) break;
    if (pt < 0.5 && pass_spp < 64) pass_spp *= 2;
    if (ss->opt.adaptive && budget > 0 && pass_spp * (pt / n) > budget * ADAPT_UNIFORM / 2) pass_spp = pass_spp > 1 ? pass_spp / 2 : 1;
  }
  if (ss->opt.adaptive && !adaptive_resumed) uniform_spp = ss->spp_done;
  if (ss->opt.adaptive && st == VALO_OK && !(budget > 0 && now_seconds() - t0 >= budget)) {
    size_t np = (size_t)ss->opt.width * ss->opt.height;
    double total = (double)ss->opt.spp * (double)np;
    if (ss->opt.adaptive == VALO_ADAPTIVE_DIGEST) st = adapt_digest(ss, uniform_spp, total, budget, t0, progress, user, ts, err);
    else st = adapt_error(ss, total, budget, t0, progress, user, ts, err);
  }
  return run_finish(ss, ts, t0, st);
}


valo_status session_set_camera(session *ss, const camera *c, valo_error *err) {
  if (ss->opt.frames > 0) return err_set(err, VALO_ERR_INVALID, "the camera of a sequence (frames) follows the scene's animation");
  if (!(c->ortho_height >= 0 && c->ortho_height < 1e30f))
    return err_set(err, VALO_ERR_INVALID, "orthographic height %g: must be positive and finite (0: a perspective camera)", (double)c->ortho_height);
  if (c->spherical && ss->lens.aperture > 0) return err_set(err, VALO_ERR_INVALID, "a spherical camera has no lens");
  if (!c->spherical && !(c->ortho_height > 0) && !(c->fov_deg > 0 && c->fov_deg < 180))
    return err_set(err, VALO_ERR_INVALID, "field of view %g: must be in (0, 180) degrees", (double)c->fov_deg);
  camera keep = ss->cam_still;
  ss->cam_still.pos = c->pos;
  ss->cam_still.look_at = c->look_at;
  ss->cam_still.up = c->up;
  ss->cam_still.fov_deg = c->fov_deg;
  ss->cam_still.ortho_height = c->ortho_height;
  ss->cam_still.spherical = c->spherical;
  if (v3_len(v3_sub(c->look_at, c->pos)) > 0 && !tiles_set_view(ss, 0)) return VALO_OK;
  ss->cam_still = keep;
  tiles_set_view(ss, 0);
  return err_set(err, VALO_ERR_INVALID, "the camera looks at its own position, or its up vector is parallel to the view direction");
}

valo_status session_step(session *ss, int spp, int restart, valo_error *err) {
  if (ss->opt.frames > 0 || ss->opt.adaptive || dist_size() > 1)
    return err_set(err, VALO_ERR_INVALID, "steps are for one process rendering a still without adaptive sampling");
  if (spp < 1 || (int64_t)ss->spp_done * !restart + spp > INT32_MAX) return err_set(err, VALO_ERR_INVALID, "step of %d samples per pixel: out of range", spp);
  thread_stats *ts = thread_stats_alloc(ss->opt.threads);
  if (!ts) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  double t0 = now_seconds();
  atomic_store(&ss->cancel, 0);
  ss->stepped = 1;
  if (restart) {
    film_clear(&ss->film);
    ss->spp_done = 0;
    ss->restarts++;
    /* a fresh restart takes sample indices no film of this render has used */
    ss->step_base = restart == SESSION_RESTART_FRESH ? ss->step_next : 0;
  }
  valo_status st = VALO_OK;
  if (ss->integ->kind == INTEGRATOR_IMAGE) {
    for (int k = 0; k < spp && !st; k++)
      if (!(st = image_frame(ss, ts, err))) ss->spp_done++;
  } else if (ss->step_base + ss->spp_done + spp > UINT32_MAX) {
    st = err_set(err, VALO_ERR_INVALID, "the render's steps have used 2^32 sample indices");
  } else if (!(st = tiles_render(ss, (int)(ss->step_base + ss->spp_done), (int)(ss->step_base + ss->spp_done + spp), ts, err))) {
    ss->spp_done += spp;
    if (ss->step_base + ss->spp_done > ss->step_next) ss->step_next = ss->step_base + ss->spp_done;
  }
  return run_finish(ss, ts, t0, st);
}
