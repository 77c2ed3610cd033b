/* output.c — see output.h. */
#include "render/output.h"
#include "render/aov.h"
#include "image/image_io.h"
#include "image/tonemap.h"
#include "image/denoise.h"
#include "core/error.h"
#include "core/strutil.h"
#include "core/options.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* Data AOVs written as PNG: mapped into [0, 1] so that they are visible, then stored
 * linearly in the 8 bits (each value pre-decoded from sRGB, so the PNG writer's sRGB
 * encoding gives back byte = round(255 v)). kind 0: normals, n/2 + 1/2; 1: depth, divided
 * by the largest in the image (black where nothing was hit); 2: sample counts, divided by
 * the largest. */
static void png_data_map(float *px, size_t np, int kind) {
  float mx = 0;
  for (size_t i = 0; i < 3 * np; i++) mx = px[i] > mx ? px[i] : mx;
  for (size_t i = 0; i < 3 * np; i++) {
    float v = kind == 0 ? px[i] * 0.5f + 0.5f : (mx > 0 ? px[i] / mx : 0);
    v = clampf(v, 0, 1);
    px[i] = srgb_to_linear(v);
  }
}

/* The per-pixel values of AOV kind k (AOV_KIND_SPP: the sample counts) into px. */
static void aov_resolve(const session *ss, int k, float *px) {
  const film *f = &ss->film;
  size_t np = film_pixels(f);
  for (size_t i = 0; i < np; i++) {
    if (k == AOV_KIND_SPP) { px[3 * i] = px[3 * i + 1] = px[3 * i + 2] = (float)f->count[i]; continue; }
    const float *a = &f->aov[AOV_FLOATS * i];
    float inv = f->count[i] > 0 ? 1.0f / (float)f->count[i] : 0;
    if (k == AOV_KIND_BENT) {
      /* the mean unoccluded direction, normalised (0 where all occluded) */
      vec3 b = v3(a[AOV_BENT], a[AOV_BENT + 1], a[AOV_BENT + 2]);
      float l = v3_len(b);
      b = l > 0 ? v3_scale(b, 1 / l) : v3(0, 0, 0);
      px[3 * i] = b.x; px[3 * i + 1] = b.y; px[3 * i + 2] = b.z;
      continue;
    }
    for (int c = 0; c < 3; c++)
      px[3 * i + c] = (k == AOV_KIND_DEPTH ? a[AOV_DEPTH] : k == AOV_KIND_AO ? a[AOV_AO] : a[3 * k + c]) * inv;
  }
}

/* The denoised image (image/denoise.h) from the film's radiance, its per-pixel variance
 * of the mean (when the film kept squares) and the AOVs. */
static valo_status denoised_resolve(const session *ss, float *px, valo_error *err) {
  const film *f = &ss->film;
  size_t np = film_pixels(f);
  float *buf = malloc(np * 3 * sizeof(float) * 4 + np * sizeof(float));
  if (!buf) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  float *color = buf, *var = buf + 3 * np, *alb = buf + 6 * np, *nrm = buf + 9 * np, *dep = buf + 12 * np;
  film_resolve(f, color);
  aov_resolve(ss, AOV_KIND_ALBEDO, alb);
  aov_resolve(ss, AOV_KIND_NORMAL, nrm);
  for (size_t i = 0; i < np; i++) dep[i] = f->count[i] ? f->aov[AOV_FLOATS * i + AOV_DEPTH] / (float)f->count[i] : 0;
  for (size_t i = 0; f->sq && i < np; i++)
    for (int c = 0; c < 3; c++) {
      double n = f->count[i], s = f->sum[3 * i + c];
      var[3 * i + c] = n > 1 ? (float)(fmax(0, (f->sq[4 * i + c] - s * s / n) / (n - 1)) / n) : 0;
    }
  denoise_in in = {ss->opt.width, ss->opt.height, color, f->sq ? var : NULL, alb, nrm, dep};
  int rc = denoise_image(&in, px, ss->opt.threads);
  free(buf);
  return rc ? err_set(err, VALO_ERR_NOMEM, "out of memory") : VALO_OK;
}

/* VALO_OK when the film holds layer k (-1: the image); name is what the message calls it. */
static valo_status layer_check(const session *ss, int k, const char *name, valo_error *err) {
  if (k < 0 || k == AOV_KIND_SPP) return VALO_OK;
  if (!ss->film.aov) return err_set(err, VALO_ERR_INVALID, "%s: the render was made without AOVs", name);
  if ((k == AOV_KIND_AO || k == AOV_KIND_BENT) && !(ss->opt.aovs & VALO_AOVS_AO))
    return err_set(err, VALO_ERR_INVALID, "%s: the render was made without the ao AOV (aovs needs VALO_AOVS_AO)", name);
  return VALO_OK;
}

valo_status output_layer(const session *ss, const char *layer, float *px, valo_error *err) {
  int k = -1;
  if (*layer) {
    /* a layer is an output prefix without its colon */
    char prefix[32];
    size_t plen = 0;
    snprintf(prefix, sizeof prefix, "%s:", layer);
    k = aov_kind_of(prefix, &plen);
    if (k < 0 || plen != strlen(prefix)) return err_set(err, VALO_ERR_INVALID, "unknown layer \"%s\" (albedo, normal, depth, ao, bent, spp, denoised)", layer);
  }
  valo_status st = layer_check(ss, k, layer, err);
  if (st) return st;
  if (k < 0) film_resolve(&ss->film, px);
  else if (k == AOV_KIND_DENOISED) return denoised_resolve(ss, px, err);
  else aov_resolve(ss, k, px);
  return VALO_OK;
}

valo_status output_write(const session *ss, const char *path, const valo_output_options *o, valo_error *err) {
  size_t plen;
  int k = aov_kind_of(path, &plen);
  int w = ss->opt.width, h = ss->opt.height;
  size_t np = film_pixels(&ss->film);
  if (k < 0 || k == AOV_KIND_DENOISED) {
    tonemap_kind tk;
    if (tonemap_parse(o->tonemap, &tk)) return err_set(err, VALO_ERR_INVALID, "unknown tone mapper \"%s\" (clamp, log, reinhard, aces)", o->tonemap);
  }
  valo_status cst = layer_check(ss, k, path, err);
  if (cst) return cst;
  float *px = malloc(np * 3 * sizeof(float));
  if (!px) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  const valo_output_options *use = o;
  valo_output_options raw;
  options_default_target(OPT_OUTPUT, &raw);
  if (k < 0) {
    film_resolve(&ss->film, px);
  } else if (k == AOV_KIND_DENOISED) {
    valo_status dst = denoised_resolve(ss, px, err);
    if (dst) { free(px); return dst; }
  } else {
    aov_resolve(ss, k, px);
    int data = k == AOV_KIND_NORMAL || k == AOV_KIND_DEPTH || k == AOV_KIND_BENT || k == AOV_KIND_SPP;
    if (str_ends_with(path, ".png") && data) {
      png_data_map(px, np, k == AOV_KIND_SPP ? 2 : k == AOV_KIND_DEPTH ? 1 : 0);
      use = &raw;
    }
  }
  valo_status st = image_write(path + plen, w, h, px, use, err);
  free(px);
  return st;
}
