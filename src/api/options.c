/* options.c — see options.h; also the public *_init functions of the option structs and
 * the public view of the declared options (core/options.h). */
#include "api/options.h"
#include "core/error.h"
#include "core/options.h"
#include <stddef.h>
#include "core/threadpool.h"
#include <stdio.h>
#include <string.h>

#define MAX_PIXEL_SAMPLES 4.0e12

/* " path whitted ...": the registered integrators, for messages. */
static void integrator_list(char *list, size_t n) {
  list[0] = 0;
  for (const char *const *name = valo_integrator_names(); *name; name++) {
    strncat(list, " ", n - strlen(list) - 1);
    strncat(list, *name, n - strlen(list) - 1);
  }
}

VALO_API void valo_options_init(valo_options *o) {
  memset(o, 0, sizeof *o);
  options_init_target(OPT_RENDER, o);
  o->aovs = VALO_UNSET; /* set by the API caller (the CLI: from its outputs), not an option */
}
VALO_API void valo_output_options_init(valo_output_options *o) {
  memset(o, 0, sizeof *o);
  options_default_target(OPT_OUTPUT, o);
}
VALO_API void valo_load_options_init(valo_load_options *o) {
  memset(o, 0, sizeof *o);
  options_default_target(OPT_LOAD, o);
}

VALO_API const valo_option_info *valo_option_at(int i) {
  if (i < 0) return NULL;
  for (const option_decl *d = option_table; d->info.flag || d->info.json; d++)
    if (i-- == 0) return &d->info;
  return NULL;
}

VALO_API valo_status valo_option_set(const char *flag, const char *value, valo_options *render, valo_load_options *load,
                                     valo_output_options *output, valo_error *err) {
  if (err) { err->status = VALO_OK; err->message[0] = 0; }
  const option_decl *d = flag ? option_find_flag(flag) : NULL;
  if (!d) return err_set(err, VALO_ERR_INVALID, "unknown option \"%s\"", flag ? flag : "");
  if (d->type == OPT_NAME && d->offset == offsetof(valo_options, integrator) && d->target == OPT_RENDER && value &&
      !integrator_find(value)) {
    char list[256];
    integrator_list(list, sizeof list);
    return err_set(err, VALO_ERR_INVALID, "unknown integrator \"%s\" (one of:%s)", value, list);
  }
  return option_set(d, value, render, load, output, err);
}

/* The file's options, then the caller's over them, then the defaults. */
static void merge_options(valo_options *dst, const valo_options *file, const valo_options *cli) {
  valo_options_init(dst);
  const valo_options *src[2] = {file, cli};
  for (int i = 0; i < 2; i++) {
    if (!src[i]) continue;
    for (const option_decl *d = option_table; d->info.flag || d->info.json; d++) option_copy(d, dst, src[i]);
    if (src[i]->aovs != VALO_UNSET) dst->aovs = src[i]->aovs;
  }
  /* What the API takes beside the table's ranges: threads 0 = all cores, frames 0 = a
   * still, time budget and noise threshold <= 0 = none. */
  if (dst->threads == 0) dst->threads = VALO_UNSET;
  if (dst->frames == 0) dst->frames = VALO_UNSET;
  if (dst->time_budget != VALO_UNSET && !(dst->time_budget > 0)) dst->time_budget = VALO_UNSET;
  if (dst->noise_threshold != VALO_UNSET && !(dst->noise_threshold > 0)) dst->noise_threshold = VALO_UNSET;
}

valo_status options_resolve(const valo_options *file, const valo_options *caller, resolved_options *out, valo_error *err) {
  memset(out, 0, sizeof *out);
  valo_options o;
  merge_options(&o, file, caller);
  for (const option_decl *d = option_table; d->info.flag || d->info.json; d++) {
    valo_status cst = option_check(d, &o, err);
    if (cst) return cst;
  }
  for (const option_decl *d = option_table; d->info.flag || d->info.json; d++) option_default(d, &o);
  if (o.threads == VALO_UNSET) o.threads = threads_available();
  if (o.aovs == VALO_UNSET) o.aovs = 0;
  if (o.crop_x != VALO_UNSET || o.crop_y != VALO_UNSET || o.crop_width != VALO_UNSET || o.crop_height != VALO_UNSET) {
    /* the crop window: what is not given starts at 0 and runs to the frame's edge */
    if (o.crop_x == VALO_UNSET) o.crop_x = 0;
    if (o.crop_y == VALO_UNSET) o.crop_y = 0;
    if (o.crop_width == VALO_UNSET) o.crop_width = o.width - o.crop_x;
    if (o.crop_height == VALO_UNSET) o.crop_height = o.height - o.crop_y;
    if (o.crop_width < 1 || o.crop_height < 1 || o.crop_x + o.crop_width > o.width || o.crop_y + o.crop_height > o.height)
      return err_set(err, VALO_ERR_INVALID, "the crop window %d,%d,%d,%d does not fit in the %dx%d frame", o.crop_x, o.crop_y, o.crop_width,
                     o.crop_height, o.width, o.height);
  }
  if ((double)o.width * o.height * o.spp > MAX_PIXEL_SAMPLES)
    return err_set(err, VALO_ERR_INVALID, "%dx%d at %d spp is more than %.0e samples", o.width, o.height, o.spp, MAX_PIXEL_SAMPLES);
  const integrator_ops *integ = integrator_find(o.integrator);
  if (!integ) {
    char list[256];
    integrator_list(list, sizeof list);
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
    if (o.aovs > 0 && (o.aovs & VALO_AOVS_AO))
      return err_set(err, VALO_ERR_UNSUPPORTED, "the %s integrator records the albedo, normal and depth AOVs of its G-buffer, not ao: or bent:", integ->name);
  }
  out->o = o;
  out->integ = integ;
  out->ao_distance = ao_param[0];
  return VALO_OK;
}
