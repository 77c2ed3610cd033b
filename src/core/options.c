/* options.c — see options.h: the table, and setting, copying, defaulting and checking an
 * option through its declaration. */
#include "core/options.h"
#include "core/error.h"
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The ray backend: Embree 3 wherever valo was built with it (docs/performance.md, section
 * 1), else the kd-tree, the seed's own structure, which --accel kdtree always picks. */
#ifdef VALO_HAVE_EMBREE
#define VALO_ACCEL_DEFAULT "embree"
#define ACCEL_HELP "embree (default: Embree 3) or kdtree (the seed's own\nkd-tree, 0.6-0.9x Embree's speed)"
#else
#define VALO_ACCEL_DEFAULT "kdtree"
#define ACCEL_HELP "kdtree (default: this build has no Embree) or embree"
#endif

#define R(field) .target = OPT_RENDER, .offset = offsetof(valo_options, field), .size = sizeof(((valo_options *)0)->field)
#define L(field) .target = OPT_LOAD, .offset = offsetof(valo_load_options, field), .size = sizeof(((valo_load_options *)0)->field)
#define O(field) .target = OPT_OUTPUT, .offset = offsetof(valo_output_options, field), .size = sizeof(((valo_output_options *)0)->field)
#define INFO(flag, metavar, json, help) .info = {flag, metavar, json, help}

/* Entries in the order --help lists them. */
const option_decl option_table[] = {
    {INFO("--spp", "N", "render.spp", "samples per pixel (default 16)"), R(spp), .type = OPT_INT, .lo = 1, .hi = 1048576, .def = 16,
     .unset = VALO_UNSET, .range_text = "a whole number from 1 to 1048576"},
    {INFO("--time", "SECONDS", "render.time",
          "time budget: stop after the pass that reaches it\n(with --spp, whichever comes first; 0: none)"),
     R(time_budget), .type = OPT_REAL, .lo = 0, .hi = 1e9, .keep_unset = 1, .unset = VALO_UNSET, .range_text = "seconds, 0 to 1e9"},
    {INFO("--frames", "N", NULL,
          "render a sequence of N frames (the scene's camera keyframes,\nor a static camera), each at --spp; outputs with a frame\n"
          "pattern (out_%04d.png) get every frame, plain names the last"),
     R(frames), .type = OPT_INT, .lo = 1, .hi = 1000000, .def = 0, .unset = VALO_UNSET, .range_text = "a whole number from 1 to 1000000"},
    {INFO("--threads", "N", NULL, "worker threads (default: all cores)"), R(threads), .type = OPT_INT, .lo = 1, .hi = 1024, .keep_unset = 1,
     .unset = VALO_UNSET, .range_text = "a whole number from 1 to 1024"},
    {INFO("--seed", "N", "render.seed", "random seed (default 1); same seed, same image, any thread count"), R(seed), .type = OPT_INT64,
     .lo = 0, .hi = 9007199254740992.0, .def = 1, .unset = VALO_UNSET, .range_text = "a whole number from 0 to 2^53"},
    {INFO("--res", "WxH", NULL, "film resolution (default 256x256)"), R(width), .type = OPT_SIZE, .lo = 1, .hi = 16384,
     .unset = VALO_UNSET, .range_text = "WIDTHxHEIGHT, each 1..16384"},
    {INFO(NULL, NULL, "film.width", "film width in pixels (default 256)"), R(width), .type = OPT_INT, .lo = 1, .hi = 16384, .def = 256,
     .unset = VALO_UNSET, .range_text = "a whole number from 1 to 16384"},
    {INFO(NULL, NULL, "film.height", "film height in pixels (default 256)"), R(height), .type = OPT_INT, .lo = 1, .hi = 16384, .def = 256,
     .unset = VALO_UNSET, .range_text = "a whole number from 1 to 16384"},
    {INFO("--crop", "X,Y,W,H", NULL, "render only the W x H window at pixel (X, Y) of the --res frame;\nthe image is the window"),
     R(crop_x), .type = OPT_RECT, .lo = 0, .hi = 16384, .keep_unset = 1, .unset = VALO_UNSET, .range_text = "X,Y,W,H in pixels"},
    {INFO(NULL, NULL, "film.crop_x", "the crop window's left column"), R(crop_x), .type = OPT_INT, .lo = 0, .hi = 16383, .keep_unset = 1,
     .unset = VALO_UNSET, .range_text = "a whole number from 0 to 16383"},
    {INFO(NULL, NULL, "film.crop_y", "the crop window's top row"), R(crop_y), .type = OPT_INT, .lo = 0, .hi = 16383, .keep_unset = 1,
     .unset = VALO_UNSET, .range_text = "a whole number from 0 to 16383"},
    {INFO(NULL, NULL, "film.crop_width", "the crop window's width"), R(crop_width), .type = OPT_INT, .lo = 1, .hi = 16384, .keep_unset = 1,
     .unset = VALO_UNSET, .range_text = "a whole number from 1 to 16384"},
    {INFO(NULL, NULL, "film.crop_height", "the crop window's height"), R(crop_height), .type = OPT_INT, .lo = 1, .hi = 16384, .keep_unset = 1,
     .unset = VALO_UNSET, .range_text = "a whole number from 1 to 16384"},
    {INFO("--filter", "NAME", "film.filter",
          "pixel filter: box (default, one pixel wide), tent, gaussian\n(Mitsuba's windowed Gaussian, standard deviation radius/4),\n"
          "blackman-harris (Cycles' default), or with negative lobes\nmitchell, catmull-rom or lanczos"),
     R(filter), .type = OPT_NAME, .names = "box|tent|gaussian|blackman-harris|mitchell|catmull-rom|lanczos", .def_text = "box",
     .range_text = "box, tent, gaussian, blackman-harris, mitchell, catmull-rom or lanczos"},
    {INFO("--filter-radius", "PIXELS", "film.filter_radius",
          "the filter's radius (default: box 0.5, tent 1, gaussian 2,\nblackman-harris 1.5 as Cycles' filter width, mitchell and\n"
          "catmull-rom 2, lanczos 3)"),
     R(filter_radius), .type = OPT_REAL, .lo = 0.1, .hi = 16, .keep_unset = 1, .unset = VALO_UNSET, .range_text = "pixels, 0.1..16"},
    {INFO("--splat", NULL, "film.splat",
          "splat each sample into every pixel the filter reaches (Mitsuba's\nfilm; a Mitsuba file's default) instead of sampling the filter"),
     R(splat), .type = OPT_FLAG, .hi = 1, .def = 0, .unset = VALO_UNSET},
    {INFO("--integrator", "NAME", "render.integrator", "the integrator (default path; --help-integrators lists them)"), R(integrator),
     .type = OPT_NAME, .def_text = "path", .range_text = "an integrator's name"},
    {INFO("--param", "NAME=VALUE", NULL,
          "an integrator parameter (repeatable; NAME or INTEGRATOR.NAME);\n--help-integrators lists them with defaults"),
     R(params), .type = OPT_PARAMS, .range_text = "NAME=VALUE"},
    {INFO("--accel", "NAME", "render.accel", ACCEL_HELP), R(accel), .type = OPT_NAME, .names = "kdtree|embree",
     .def_text = VALO_ACCEL_DEFAULT, .range_text = "kdtree or embree"},
    {INFO("--sampler", "NAME", "render.sampler", "sobol (default: Owen-scrambled Sobol) or independent"), R(sampler), .type = OPT_NAME,
     .names = "sobol|independent", .def_text = "sobol", .range_text = "sobol or independent"},
    {INFO("--light-sampler", "NAME", "render.light_sampler",
          "grid (default: lights near the point first, in scenes\nwith more than 64 lights) or power"),
     R(light_sampler), .type = OPT_NAME, .names = "grid|power", .def_text = "grid", .range_text = "grid or power"},
    {INFO("--sphere-lights", "NAME", "render.sphere_lights",
          "cone (default: an emitting sphere sampled by the cone it\nsubtends) or triangles (by its triangles, as area lights)"),
     R(sphere_lights), .type = OPT_NAME, .names = "cone|triangles", .def_text = "cone", .range_text = "cone or triangles"},
    {INFO("--max-depth", "N", "render.max_depth", "maximum path length (default -1: unlimited, Russian roulette\nends paths)"),
     R(max_depth), .type = OPT_INT, .lo = -1, .hi = 100000, .def = -1, .unset = VALO_DEPTH_UNSET,
     .range_text = "-1 or a whole number from 0 to 100000"},
    {INFO("--rr-depth", "N", "render.rr_depth",
          "the bounce from which Russian roulette may end paths (default 5;\n0: from the first surface; Mitsuba's rr_depth N is N - 1)"),
     R(rr_depth), .type = OPT_INT, .lo = 0, .hi = 100000, .def = 5, .unset = VALO_UNSET,
     .range_text = "a whole number from 0 to 100000"},
    {INFO("--batch", "N", "render.batch",
          "camera samples a thread traces together, stage by stage (path;\ndefault 256; 1: one path at a time)"),
     R(batch), .type = OPT_INT, .lo = 1, .hi = 1024, .def = 256, .unset = VALO_UNSET,
     .range_text = "a whole number from 1 to 1024"},
    {INFO("--aperture", "R", NULL, "thin-lens radius in scene units (0 = pinhole); overrides\nthe scene camera's"), R(aperture_radius),
     .type = OPT_REAL, .lo = 0, .hi = 1e6, .keep_unset = 1, .unset = VALO_UNSET, .range_text = "a lens radius in scene units, >= 0"},
    {INFO("--focus", "D", NULL, "focus distance along the view axis (default: the scene's; for\na file camera, the surface at the image centre)"),
     R(focus_distance), .type = OPT_REAL, .lo = 1e-6, .hi = 1e9, .keep_unset = 1, .unset = VALO_UNSET,
     .range_text = "a distance in scene units, > 0"},
    {INFO("--spectral", NULL, NULL, "spectral rendering (path): 4 wavelengths per path, dispersion"), R(spectral), .type = OPT_FLAG,
     .hi = 1, .def = 0, .unset = VALO_UNSET},
    {INFO("--hide-emitters", NULL, "render.hide_emitters",
          "do not draw lights seen directly by camera rays (area lights,\nthe environment); their light and reflections stay"),
     R(hide_emitters), .type = OPT_FLAG, .hi = 1, .def = 0, .unset = VALO_UNSET},
    {INFO("--adaptive", NULL, NULL, "adaptive sampling: --spp is the average per pixel; the\nnoisiest pixels get more (spp:FILE writes the count map)"),
     R(adaptive), .type = OPT_FLAG, .hi = VALO_ADAPTIVE_ERROR, .def = 0, .unset = VALO_UNSET},
    {INFO("--adaptive-rule", "R", NULL,
          "error (default: relative error from the neighbours,\nunbiased) or digest (the design digest's priority on the\n"
          "pixel itself: biased dark on rare bright paths); implies\n--adaptive"),
     R(adaptive), .type = OPT_CHOICE, .names = "error|digest", .choice_base = VALO_ADAPTIVE_ERROR, .def = 0, .unset = VALO_UNSET,
     .range_text = "error or digest"},
    {INFO("--noise-threshold", "X", NULL,
          "adaptive sampling that stops once every pixel's relative\nstandard error is below X (e.g. 0.01); implies --adaptive"),
     R(noise_threshold), .type = OPT_REAL, .lo = 0, .hi = 10, .def = 0, .unset = VALO_UNSET, .range_text = "a relative error, 1e-6..10"},
    {INFO("--env", "FILE", NULL,
          "light by this environment map (.exr/.hdr/.pfm, or PNG/JPEG\nfrom sRGB), replacing the scene's; a mesh file without\n"
          "lights gets a uniform white environment otherwise"),
     L(env_file), .type = OPT_NAME, .range_text = "a file name"},
    {INFO("--env-scale", "S", NULL, "multiply the --env map by S (default 1)"), L(env_scale), .type = OPT_REAL, .lo = 0, .hi = 1e9, .def = 1,
     .range_text = "a scale >= 0"},
    {INFO("--env-rotation", "DEG", NULL, "turn the --env map about the up axis (default 0)"), L(env_rotation), .type = OPT_REAL,
     .lo = -36000, .hi = 36000, .def = 0, .range_text = "degrees"},
    {INFO("--up", "y|z", NULL, "up axis of a mesh file framed automatically (default y;\nz for scans and CAD models)"), L(up),
     .type = OPT_NAME, .names = "y|z", .def_text = "y", .range_text = "y or z"},
    {INFO("--define", "NAME=VALUE", NULL, "a Mitsuba scene (.xml): set its <default> NAME, which\n$NAME stands for (repeatable; -D, as Mitsuba's)"),
     L(defines), .type = OPT_PARAMS, .range_text = "NAME=VALUE"},
    {INFO("--exposure", "STOPS", NULL, "PNG exposure (default 0)"), O(exposure), .type = OPT_FLOAT, .lo = -100, .hi = 100, .def = 0,
     .range_text = "stops, -100..100"},
    {INFO("--tonemap", "NAME", NULL, "PNG tone curve: clamp (default), log, reinhard, aces"), O(tonemap), .type = OPT_NAME,
     .names = "clamp|log|reinhard|aces", .def_text = "clamp", .range_text = "clamp, log, reinhard or aces"},
    {INFO("--bloom", "STRENGTH", NULL, "PNG bloom: add STRENGTH x a Gaussian blur of what exceeds\n--bloom-threshold"), O(bloom),
     .type = OPT_FLOAT, .lo = 0, .hi = 100, .def = 0, .range_text = "0..100"},
    {INFO("--bloom-radius", "PIXELS", NULL, "bloom blur standard deviation (default 1/100 of the width)"), O(bloom_radius),
     .type = OPT_FLOAT, .lo = 0.1, .hi = 500, .def = 0, .range_text = "pixels, 0.1..500"},
    {INFO("--bloom-threshold", "X", NULL, "radiance above which pixels bloom, after exposure (default 1)"), O(bloom_threshold),
     .type = OPT_FLOAT, .lo = 0, .hi = 1e6, .def = 1, .range_text = "a radiance >= 0"},
    {INFO(NULL, NULL, NULL, NULL)}};

const option_decl *option_find_flag(const char *flag) {
  for (const option_decl *d = option_table; d->info.flag || d->info.json; d++)
    if (d->info.flag && !strcmp(d->info.flag, flag)) return d;
  return NULL;
}
const option_decl *option_find_json(const char *key) {
  for (const option_decl *d = option_table; d->info.flag || d->info.json; d++)
    if (d->info.json && !strcmp(d->info.json, key)) return d;
  return NULL;
}

static void *field(const option_decl *d, valo_options *ro, valo_load_options *lo, valo_output_options *oo) {
  char *base = d->target == OPT_RENDER ? (char *)ro : d->target == OPT_LOAD ? (char *)lo : (char *)oo;
  return base ? base + d->offset : NULL;
}

/* The index of name in "a|b|c", or -1. */
static int name_index(const char *names, const char *v) {
  int i = 0;
  for (const char *p = names; *p; i++) {
    size_t n = strcspn(p, "|");
    if (strlen(v) == n && !strncmp(p, v, n)) return i;
    p += n;
    if (*p) p++;
  }
  return -1;
}

static int parse_number(const char *s, int whole, double *out) {
  char *end;
  errno = 0;
  double v = strtod(s, &end);
  if (errno || end == s || *end || !isfinite(v)) return -1;
  if (whole && v != floor(v)) return -1;
  *out = v;
  return 0;
}

static valo_status bad_value(const option_decl *d, const char *value, valo_error *err) {
  return err_set(err, VALO_ERR_INVALID, "invalid value \"%s\" (%s)", value, d->range_text ? d->range_text : "see --help");
}

valo_status option_set(const option_decl *d, const char *value, valo_options *ro, valo_load_options *lo, valo_output_options *oo,
                       valo_error *err) {
  void *f = field(d, ro, lo, oo);
  if (!f) return err_set(err, VALO_ERR_INVALID, "no options to set");
  double v;
  switch (d->type) {
  case OPT_FLAG: *(int *)f = value && !strcmp(value, "0") ? 0 : (int)d->hi; return VALO_OK; /* "0": a scene file's false */
  case OPT_INT:
  case OPT_INT64:
  case OPT_REAL:
  case OPT_FLOAT: {
    int whole = d->type == OPT_INT || d->type == OPT_INT64;
    if (!value || parse_number(value, whole, &v)) return bad_value(d, value ? value : "", err);
    if (!(v >= d->lo && v <= d->hi)) return err_set(err, VALO_ERR_INVALID, "%s is out of range (%s)", value, d->range_text);
    if (d->type == OPT_INT) *(int *)f = (int)v;
    else if (d->type == OPT_INT64) *(int64_t *)f = (int64_t)v;
    else if (d->type == OPT_REAL) *(double *)f = v;
    else *(float *)f = (float)v;
    return VALO_OK;
  }
  case OPT_NAME:
    if (!value || (d->names && name_index(d->names, value) < 0) || strlen(value) >= d->size) return bad_value(d, value ? value : "", err);
    snprintf((char *)f, d->size, "%s", value);
    return VALO_OK;
  case OPT_CHOICE: {
    int k = value && d->names ? name_index(d->names, value) : -1;
    if (k < 0) return bad_value(d, value ? value : "", err);
    *(int *)f = d->choice_base + k;
    return VALO_OK;
  }
  case OPT_RECT: {
    int r[4];
    char extra;
    if (!value || sscanf(value, "%d,%d,%d,%d%c", &r[0], &r[1], &r[2], &r[3], &extra) != 4 || r[0] < 0 || r[1] < 0 || r[2] < 1 || r[3] < 1 ||
        r[0] >= d->hi || r[1] >= d->hi || r[2] > d->hi || r[3] > d->hi)
      return bad_value(d, value ? value : "", err);
    memcpy(f, r, sizeof r); /* x, y, width, height: adjacent ints in valo_options */
    return VALO_OK;
  }
  case OPT_SIZE: {
    int w = 0, h = 0;
    char extra;
    if (!value || sscanf(value, "%dx%d%c", &w, &h, &extra) != 2 || w < d->lo || h < d->lo || w > d->hi || h > d->hi)
      return bad_value(d, value ? value : "", err);
    ((int *)f)[0] = w; /* width, then height: adjacent ints in valo_options */
    ((int *)f)[1] = h;
    return VALO_OK;
  }
  case OPT_PARAMS: {
    char *p = f;
    if (!value || !strchr(value, '=')) return err_set(err, VALO_ERR_INVALID, "expected NAME=VALUE, got \"%s\"", value ? value : "");
    size_t used = strlen(p);
    if (used + strlen(value) + 2 > d->size) return err_set(err, VALO_ERR_INVALID, "too many parameters");
    snprintf(p + used, d->size - used, "%s%s", used ? " " : "", value);
    return VALO_OK;
  }
  }
  return bad_value(d, value ? value : "", err);
}

static double number_of(const option_decl *d, const void *f) {
  switch (d->type) {
  case OPT_INT: case OPT_FLAG: case OPT_CHOICE: case OPT_SIZE: case OPT_RECT: return *(const int *)f;
  case OPT_INT64: return (double)*(const int64_t *)f;
  case OPT_REAL: return *(const double *)f;
  case OPT_FLOAT: return *(const float *)f;
  case OPT_NAME: case OPT_PARAMS: return 0;
  }
  return 0;
}

int option_is_set(const option_decl *d, const valo_options *o) {
  const char *f = (const char *)o + d->offset;
  if (d->type == OPT_NAME || d->type == OPT_PARAMS) return f[0] != 0;
  return number_of(d, f) != d->unset;
}

void option_copy(const option_decl *d, valo_options *dst, const valo_options *src) {
  if (d->target != OPT_RENDER || !option_is_set(d, src)) return;
  char *t = (char *)dst + d->offset;
  const char *s = (const char *)src + d->offset;
  if (d->type == OPT_PARAMS) {
    /* file first, then the caller's: later entries win */
    size_t used = strlen(t);
    snprintf(t + used, d->size - used, "%s%s", used ? " " : "", s);
    return;
  }
  memcpy(t, s, d->type == OPT_SIZE ? 2 * sizeof(int) : d->type == OPT_RECT ? 4 * sizeof(int) : d->size);
}

void option_default(const option_decl *d, valo_options *o) {
  if (d->target != OPT_RENDER || d->keep_unset || d->type == OPT_SIZE || d->type == OPT_PARAMS || option_is_set(d, o)) return;
  char *f = (char *)o + d->offset;
  switch (d->type) {
  case OPT_NAME: if (d->def_text) snprintf(f, d->size, "%s", d->def_text); break;
  case OPT_INT: case OPT_FLAG: case OPT_CHOICE: *(int *)f = (int)d->def; break;
  case OPT_INT64: *(int64_t *)f = (int64_t)d->def; break;
  case OPT_REAL: *(double *)f = d->def; break;
  case OPT_FLOAT: *(float *)f = (float)d->def; break;
  case OPT_SIZE: case OPT_RECT: case OPT_PARAMS: break;
  }
}

valo_status option_check(const option_decl *d, const valo_options *o, valo_error *err) {
  if (d->target != OPT_RENDER || !option_is_set(d, o)) return VALO_OK;
  const char *f = (const char *)o + d->offset;
  const char *what = d->info.flag ? d->info.flag : d->info.json;
  switch (d->type) {
  case OPT_NAME:
    if (d->names && name_index(d->names, f) < 0) return err_set(err, VALO_ERR_INVALID, "%s: unknown value \"%s\" (%s)", what, f, d->range_text);
    return VALO_OK;
  case OPT_INT: case OPT_INT64: case OPT_REAL: case OPT_FLOAT: {
    double v = number_of(d, f);
    if (!(v >= d->lo && v <= d->hi)) return err_set(err, VALO_ERR_INVALID, "%s: %g is out of range (%s)", what, v, d->range_text);
    return VALO_OK;
  }
  case OPT_CHOICE: case OPT_FLAG: case OPT_SIZE: case OPT_RECT: case OPT_PARAMS: return VALO_OK;
  }
  return VALO_OK;
}

/* Numbers of every option of `target` to their "not given" value, names and text empty. */
void options_init_target(opt_target target, void *o) {
  for (const option_decl *d = option_table; d->info.flag || d->info.json; d++) {
    if (d->target != target) continue;
    char *f = (char *)o + d->offset;
    switch (d->type) {
    case OPT_INT: case OPT_FLAG: case OPT_CHOICE: *(int *)f = (int)d->unset; break;
    case OPT_INT64: *(int64_t *)f = (int64_t)d->unset; break;
    case OPT_REAL: *(double *)f = d->unset; break;
    case OPT_FLOAT: *(float *)f = (float)d->unset; break;
    case OPT_SIZE: case OPT_RECT: case OPT_NAME: case OPT_PARAMS: break;
    }
  }
}
/* The load and output options have no file to come from: their defaults at once. */
void options_default_target(opt_target target, void *o) {
  for (const option_decl *d = option_table; d->info.flag || d->info.json; d++) {
    if (d->target != target) continue;
    char *f = (char *)o + d->offset;
    switch (d->type) {
    case OPT_NAME: if (d->def_text) snprintf(f, d->size, "%s", d->def_text); break;
    case OPT_REAL: *(double *)f = d->def; break;
    case OPT_FLOAT: *(float *)f = (float)d->def; break;
    case OPT_INT: case OPT_FLAG: case OPT_CHOICE: *(int *)f = (int)d->def; break;
    case OPT_INT64: *(int64_t *)f = (int64_t)d->def; break;
    case OPT_SIZE: case OPT_RECT: case OPT_PARAMS: break;
    }
  }
}
