/* options.c — see options.h; also the public *_init functions of the option structs. */
#include "api/options.h"
#include "core/error.h"
#include "core/threadpool.h"
#include <stdio.h>
#include <string.h>

#define MAX_RES 16384
#define MAX_SPP 1048576
#define MAX_PIXEL_SAMPLES 4.0e12

VALO_API void valo_options_init(valo_options *o) {
  memset(o, 0, sizeof *o);
  o->width = o->height = o->spp = o->threads = o->max_depth = VALO_UNSET;
  o->time_budget = VALO_UNSET;
  o->seed = VALO_UNSET;
  o->aovs = VALO_UNSET;
  o->adaptive = VALO_UNSET;
  o->noise_threshold = VALO_UNSET;
  o->spectral = VALO_UNSET;
  o->aperture_radius = o->focus_distance = VALO_UNSET;
  o->max_depth = VALO_DEPTH_UNSET; /* -1 is a meaningful value */
  o->frames = VALO_UNSET;
}

VALO_API void valo_output_options_init(valo_output_options *o) {
  memset(o, 0, sizeof *o);
  snprintf(o->tonemap, sizeof o->tonemap, "clamp");
  o->bloom_threshold = 1;
}

VALO_API void valo_load_options_init(valo_load_options *o) {
  memset(o, 0, sizeof *o);
  o->env_scale = 1;
  snprintf(o->up, sizeof o->up, "y");
}

static void merge_options(valo_options *dst, const valo_options *file, const valo_options *cli) {
  valo_options_init(dst);
  const valo_options *src[2] = {file, cli};
  for (int i = 0; i < 2; i++) {
    const valo_options *o = src[i];
    if (!o) continue;
    if (o->width != VALO_UNSET) dst->width = o->width;
    if (o->height != VALO_UNSET) dst->height = o->height;
    if (o->spp != VALO_UNSET) dst->spp = o->spp;
    if (o->time_budget != VALO_UNSET) dst->time_budget = o->time_budget;
    if (o->threads != VALO_UNSET) dst->threads = o->threads;
    if (o->seed != VALO_UNSET) dst->seed = o->seed;
    if (o->max_depth != VALO_DEPTH_UNSET) dst->max_depth = o->max_depth;
    if (o->integrator[0]) memcpy(dst->integrator, o->integrator, sizeof dst->integrator);
    if (o->params[0]) {
      /* file first, then the caller's: later entries win */
      size_t used = strlen(dst->params);
      snprintf(dst->params + used, sizeof dst->params - used, "%s%s", used ? " " : "", o->params);
    }
    if (o->accel[0]) memcpy(dst->accel, o->accel, sizeof dst->accel);
    if (o->sampler[0]) memcpy(dst->sampler, o->sampler, sizeof dst->sampler);
    if (o->light_sampler[0]) memcpy(dst->light_sampler, o->light_sampler, sizeof dst->light_sampler);
    if (o->aovs != VALO_UNSET) dst->aovs = o->aovs;
    if (o->adaptive != VALO_UNSET) dst->adaptive = o->adaptive;
    if (o->noise_threshold != VALO_UNSET) dst->noise_threshold = o->noise_threshold;
    if (o->spectral != VALO_UNSET) dst->spectral = o->spectral;
    if (o->aperture_radius != VALO_UNSET) dst->aperture_radius = o->aperture_radius;
    if (o->focus_distance != VALO_UNSET) dst->focus_distance = o->focus_distance;
    if (o->frames != VALO_UNSET) dst->frames = o->frames;
  }
  if (dst->width == VALO_UNSET) dst->width = 256;
  if (dst->height == VALO_UNSET) dst->height = 256;
  if (dst->spp == VALO_UNSET) dst->spp = 16;
  if (dst->threads == VALO_UNSET || dst->threads == 0) dst->threads = threads_available();
  if (dst->seed == VALO_UNSET) dst->seed = 1;
  if (dst->aovs == VALO_UNSET) dst->aovs = 0;
  if (dst->adaptive == VALO_UNSET) dst->adaptive = 0;
  if (dst->noise_threshold == VALO_UNSET) dst->noise_threshold = 0;
  if (dst->spectral == VALO_UNSET) dst->spectral = 0;
  if (dst->max_depth == VALO_DEPTH_UNSET) dst->max_depth = -1;
  if (dst->frames == VALO_UNSET) dst->frames = 0;
  if (!dst->integrator[0]) snprintf(dst->integrator, sizeof dst->integrator, "path");
  if (!dst->accel[0]) snprintf(dst->accel, sizeof dst->accel, "kdtree");
  if (!dst->sampler[0]) snprintf(dst->sampler, sizeof dst->sampler, "sobol");
  if (!dst->light_sampler[0]) snprintf(dst->light_sampler, sizeof dst->light_sampler, "grid");
}

valo_status options_resolve(const valo_options *file, const valo_options *caller, resolved_options *out, valo_error *err) {
  memset(out, 0, sizeof *out);
  valo_options o;
  merge_options(&o, file, caller);
  if (o.width < 1 || o.height < 1 || o.width > MAX_RES || o.height > MAX_RES)
    return err_set(err, VALO_ERR_INVALID, "resolution %dx%d is out of range (1..%d per side)", o.width, o.height, MAX_RES);
  if (o.spp < 1 || o.spp > MAX_SPP) return err_set(err, VALO_ERR_INVALID, "sample count %d is out of range (1..%d)", o.spp, MAX_SPP);
  if ((double)o.width * o.height * o.spp > MAX_PIXEL_SAMPLES)
    return err_set(err, VALO_ERR_INVALID, "%dx%d at %d spp is more than %.0e samples", o.width, o.height, o.spp, MAX_PIXEL_SAMPLES);
  if (o.threads < 1 || o.threads > 1024) return err_set(err, VALO_ERR_INVALID, "thread count %d is out of range (1..1024)", o.threads);
  if (o.seed < 0) return err_set(err, VALO_ERR_INVALID, "seed must not be negative");
  if (o.aperture_radius != VALO_UNSET && !(o.aperture_radius >= 0 && o.aperture_radius < 1e6))
    return err_set(err, VALO_ERR_INVALID, "aperture radius must be >= 0");
  if (o.focus_distance != VALO_UNSET && !(o.focus_distance > 0 && o.focus_distance < 1e9))
    return err_set(err, VALO_ERR_INVALID, "focus distance must be > 0");
  if (o.frames < 0 || o.frames > 1000000) return err_set(err, VALO_ERR_INVALID, "frame count %d is out of range (1..1000000)", o.frames);
  if (o.max_depth < -1) return err_set(err, VALO_ERR_INVALID, "max_depth must be -1 (unlimited) or >= 0");
  if (strcmp(o.sampler, "sobol") && strcmp(o.sampler, "independent"))
    return err_set(err, VALO_ERR_INVALID, "unknown sampler \"%s\" (sobol or independent)", o.sampler);
  if (strcmp(o.light_sampler, "grid") && strcmp(o.light_sampler, "power"))
    return err_set(err, VALO_ERR_INVALID, "unknown light sampler \"%s\" (grid or power)", o.light_sampler);
  const integrator_ops *integ = integrator_find(o.integrator);
  if (!integ) {
    char list[256] = "";
    for (const char *const *n = valo_integrator_names(); *n; n++) { strncat(list, " ", sizeof list - strlen(list) - 1); strncat(list, *n, sizeof list - strlen(list) - 1); }
    return err_set(err, VALO_ERR_INVALID, "unknown integrator \"%s\" (available:%s)", o.integrator, list);
  }
  if (o.spectral) {
    if (strcmp(o.integrator, "path")) return err_set(err, VALO_ERR_UNSUPPORTED, "spectral mode works with the path integrator only");
    integ = integrator_find("path-spectral");
  }
  double ao_param[INTEGRATOR_MAX_PARAMS] = {0};
  valo_status pst = integrator_params_parse(integ, o.params, out->param, 0, err);
  if (pst) return pst;
  /* The ao AOV takes the ao integrator's ray length ("ao.distance=..."). */
  pst = integrator_params_parse(integrator_find("ao"), o.params, ao_param, !strcmp(integ->name, "ao") ? 0 : 1, err);
  if (pst) return pst;
  if (o.adaptive && integ->prepare)
    return err_set(err, VALO_ERR_UNSUPPORTED, "adaptive sampling does not work with the %s integrator (each pass shares one light-path set)", integ->name);
  if (o.adaptive && o.frames > 0) return err_set(err, VALO_ERR_UNSUPPORTED, "adaptive sampling does not work with --frames");
  if (integ->kind == INTEGRATOR_IMAGE) {
    if (o.adaptive) return err_set(err, VALO_ERR_UNSUPPORTED, "adaptive sampling does not work with the %s integrator (it renders whole frames)", integ->name);
    if (o.aovs) return err_set(err, VALO_ERR_UNSUPPORTED, "the %s integrator records no AOVs (albedo:, normal:, depth:, ao:, bent: outputs)", integ->name);
  }
  out->o = o;
  out->integ = integ;
  out->ao_distance = ao_param[0];
  return VALO_OK;
}
