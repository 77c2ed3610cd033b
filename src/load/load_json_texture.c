/* load_json_texture.c — owns the JSON scene format's texture values (docs/scene-format.md,
 * "Textures"): a file name, or an object giving an image file or a checkerboard, whether
 * it is read as its luminance, and how it is looked up (wrap, filter, a map of the
 * texture coordinates). */
#include "load/load_json_internal.h"
#include "core/error.h"
#include "image/texture.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* The image file named by `name`, as *tex. */
static valo_status image_file(jctx *c, const char *name, int srgb, const char *w, const char *what, int *tex) {
  char full[2048], msg[2400];
  json_resolve_path(c, name, full, sizeof full);
  FILE *f = fopen(full, "rb");
  if (!f) {
    snprintf(msg, sizeof msg, "cannot open the %s %s: %s", what, full, strerror(errno));
    return json_bad(c, w, msg);
  }
  fclose(f);
  valo_error terr;
  *tex = scene_texture_file(c->s, full, srgb, &terr);
  if (*tex >= 0) return VALO_OK;
  snprintf(msg, sizeof msg, "the %s could not be decoded: %s", what, terr.message);
  return json_bad(c, w, msg);
}

/* A list of n finite numbers at key, into out (left as it is when absent). */
static valo_status numbers(jctx *c, const cJSON *o, const char *key, const char *w, int n, float *out) {
  const cJSON *a = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!a) return VALO_OK;
  char at[400], msg[80];
  snprintf(at, sizeof at, "%s.%s", w, key);
  snprintf(msg, sizeof msg, "must be an array of %d numbers", n);
  if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != n) return json_bad(c, at, msg);
  int i = 0;
  for (const cJSON *e = a->child; e; e = e->next, i++) {
    if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > 1e8) return json_bad(c, at, "must hold finite numbers (at most 1e8 in size)");
    out[i] = (float)e->valuedouble;
  }
  return VALO_OK;
}

/* A checkerboard's colour at key: a number or [r, g, b], each >= 0. */
static valo_status colour(jctx *c, const cJSON *o, const char *key, const char *w, float def, float out[3]) {
  rgb v = c3(def, def, def);
  TRY(json_get_rgb(c, o, key, w, &v));
  if (!(v.r >= 0 && v.g >= 0 && v.b >= 0)) {
    char at[400];
    snprintf(at, sizeof at, "%s.%s", w, key);
    return json_bad(c, at, "must not be negative");
  }
  out[0] = v.r; out[1] = v.g; out[2] = v.b;
  return VALO_OK;
}

valo_status json_get_texture(jctx *c, const cJSON *v, int srgb, const char *w, const char *what, int *tex) {
  if (cJSON_IsString(v)) return image_file(c, v->valuestring, srgb, w, what, tex);
  if (!cJSON_IsObject(v)) return json_bad(c, w, "must be a file name or a texture object ({\"file\": ...} or {\"type\": \"checkerboard\", ...})");
  static const char *const keys[] = {"type", "file", "raw", "luminance", "color0", "color1", "wrap", "filter", "uv_scale", "uv_offset", "uv_matrix", NULL};
  TRY(json_check_keys(c, v, w, keys));
  const char *type = "bitmap", *file = NULL, *wrap = NULL, *filter = NULL;
  int raw = !srgb, lum = 0;
  TRY(json_get_bool(c, v, "luminance", w, &lum));
  TRY(json_get_str(c, v, "type", w, &type));
  TRY(json_get_str(c, v, "file", w, &file));
  TRY(json_get_bool(c, v, "raw", w, &raw));
  TRY(json_get_str(c, v, "wrap", w, &wrap));
  TRY(json_get_str(c, v, "filter", w, &filter));
  if (!strcmp(type, "bitmap")) {
    if (!file) return json_bad(c, w, "a bitmap texture needs \"file\"");
    if (cJSON_GetObjectItemCaseSensitive(v, "color0") || cJSON_GetObjectItemCaseSensitive(v, "color1"))
      return json_bad(c, w, "color0 and color1 belong to a checkerboard");
    TRY(image_file(c, file, !raw, w, what, tex));
  } else if (!strcmp(type, "checkerboard")) {
    if (file || cJSON_GetObjectItemCaseSensitive(v, "raw")) return json_bad(c, w, "a checkerboard has no file");
    float c0[3], c1[3];
    TRY(colour(c, v, "color0", w, 0.4f, c0));
    TRY(colour(c, v, "color1", w, 0.2f, c1));
    valo_error terr;
    *tex = scene_texture_checkerboard(c->s, c0, c1, &terr);
    if (*tex < 0) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  } else {
    return json_bad(c, w, "\"type\" must be \"bitmap\" or \"checkerboard\"");
  }
  if (lum && (*tex = scene_texture_luminance(c->s, *tex)) < 0) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  const texture *t = &c->s->tex[*tex];
  tex_sampling smp = t->smp;
  if (wrap) {
    if (!strcmp(wrap, "repeat")) smp.wrap = TEX_REPEAT;
    else if (!strcmp(wrap, "mirror")) smp.wrap = TEX_MIRROR;
    else if (!strcmp(wrap, "clamp")) smp.wrap = TEX_CLAMP;
    else return json_bad(c, w, "\"wrap\" must be \"repeat\", \"mirror\" or \"clamp\"");
  }
  if (filter) {
    if (!strcmp(filter, "bilinear")) smp.filter = TEX_BILINEAR;
    else if (!strcmp(filter, "nearest")) smp.filter = TEX_NEAREST;
    else return json_bad(c, w, "\"filter\" must be \"bilinear\" or \"nearest\"");
  }
  int has_m = cJSON_GetObjectItemCaseSensitive(v, "uv_matrix") != NULL;
  int has_so = cJSON_GetObjectItemCaseSensitive(v, "uv_scale") || cJSON_GetObjectItemCaseSensitive(v, "uv_offset");
  if (has_m && has_so) return json_bad(c, w, "give uv_matrix, or uv_scale and uv_offset, not both");
  if (has_m) {
    TRY(numbers(c, v, "uv_matrix", w, 6, smp.uvm));
    smp.has_uvm = 1;
  } else if (has_so) {
    float sc[2] = {1, 1}, of[2] = {0, 0};
    TRY(numbers(c, v, "uv_scale", w, 2, sc));
    TRY(numbers(c, v, "uv_offset", w, 2, of));
    float m[6] = {sc[0], 0, of[0], 0, sc[1], of[1]};
    memcpy(smp.uvm, m, sizeof m);
    smp.has_uvm = 1;
  }
  *tex = scene_texture_sampled(c->s, *tex, &smp);
  if (*tex < 0) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  return VALO_OK;
}
