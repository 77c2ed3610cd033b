/* load_json_material.c — owns the JSON scene format's materials and media
 * (docs/scene-format.md, "materials", "media"): types, colours or texture maps,
 * conductor presets and spectra, maps; homogeneous media and their names. */
#include "load/load_json_internal.h"
#include "core/error.h"
#include "core/spectrum.h"
#include "scene/volume.h"
#include "material/plastic.h"
#include "material/sheen.h"
#include "image/texture.h"
#include "core/grow.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The map v (a file name or a texture object), 8-bit decoded from sRGB unless raw (as
 * Mitsuba's and pbrt's bitmaps are), as *tex; w: "where.key" for errors. */
static valo_status get_float_map(jctx *c, const cJSON *v, int raw, const char *w, const char *what, int *tex) {
  return json_get_texture(c, v, !raw, w, what, tex);
}

/* An optional map named by `key` (decoded from sRGB unless raw): *tex stays -1 when absent. */
static valo_status get_map(jctx *c, const cJSON *o, const char *key, const char *where, const char *what, int raw, int *tex) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!v) return VALO_OK;
  char w[300];
  snprintf(w, sizeof w, "%s.%s", where, key);
  return get_float_map(c, v, raw, w, what, tex);
}
/* An optional data map (linear, not sRGB). */
static valo_status get_data_map(jctx *c, const cJSON *o, const char *key, const char *where, const char *what, int *tex) {
  return get_map(c, o, key, where, what, 1, tex);
}

/* "opacity": a number in [0, 1] or a map (8-bit decoded from sRGB, as Mitsuba's and
 * pbrt's bitmaps are, unless "opacity_raw"): a hit counts with that probability. */
static valo_status get_opacity(jctx *c, const cJSON *o, const char *where, material *m) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, "opacity");
  int raw = 0;
  TRY(json_get_bool(c, o, "opacity_raw", where, &raw));
  if (!v) return VALO_OK;
  char w[300];
  snprintf(w, sizeof w, "%s.opacity", where);
  if (m->tex_alpha >= 0) return json_bad(c, w, "give alpha_map (a cutout) or opacity, not both");
  if (!cJSON_IsString(v) && !cJSON_IsObject(v)) {
    double a = 1;
    TRY(json_get_num(c, o, "opacity", where, 0, 1, &a));
    m->opacity = (float)a;
    return VALO_OK;
  }
  TRY(get_float_map(c, v, raw, w, "opacity map", &m->tex_alpha));
  m->alpha_channel = c->s->tex[m->tex_alpha].has_alpha;
  m->alpha_stochastic = 1;
  return VALO_OK;
}

/* A colour parameter may be a texture (a file name or a texture object: a colour map,
 * sRGB-decoded unless it says "raw"); the colour then multiplies 1. */
static valo_status get_rgb_tex(jctx *c, const cJSON *o, const char *key, const char *where, rgb *out, int *tex) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (cJSON_IsString(v) || cJSON_IsObject(v)) {
    char w[300];
    snprintf(w, sizeof w, "%s.%s", where, key);
    TRY(json_get_texture(c, v, 1, w, "texture", tex));
    *out = c3(1, 1, 1);
    return VALO_OK;
  }
  return json_get_rgb(c, o, key, where, out);
}

/* "spectrum": {"wavelengths": [nm...], "eta": [...], "k": [...]}, e.g. a table of
 * measured optical constants: stored in the scene for --spectral; RGB mode takes their
 * colourimetric projection (tab_to_rgb). */
static valo_status parse_nk_spectrum(jctx *c, const cJSON *o, const char *where0, material *m) {
  char where[300];
  snprintf(where, sizeof where, "%s.spectrum", where0);
  static const char *const keys[] = {"wavelengths", "eta", "k", NULL};
  TRY(json_check_keys(c, o, where, keys));
  nk_curve cv = {0};
  float *dst[3] = {cv.nm, cv.eta, cv.k};
  for (int a = 0; a < 3; a++) {
    const cJSON *arr = cJSON_GetObjectItemCaseSensitive(o, keys[a]);
    char msg[200];
    int n = cJSON_GetArraySize(arr);
    if (!cJSON_IsArray(arr) || n < 2 || n > NK_MAX) {
      snprintf(msg, sizeof msg, "\"%s\" must be an array of 2 to %d numbers", keys[a], NK_MAX);
      return json_bad(c, where, msg);
    }
    if (a > 0 && n != cv.n) {
      snprintf(msg, sizeof msg, "\"%s\" has %d values for %d wavelengths", keys[a], n, cv.n);
      return json_bad(c, where, msg);
    }
    cv.n = n;
    int i = 0;
    for (const cJSON *e = arr->child; e; e = e->next, i++) {
      double v = cJSON_IsNumber(e) ? e->valuedouble : NAN;
      int ok = isfinite(v) && (a == 0 ? v >= 100 && v <= 20000 && (i == 0 || v > dst[0][i - 1]) : a == 1 ? v > 0 : v >= 0);
      if (!ok) {
        snprintf(msg, sizeof msg, "\"%s\"[%d] %s", keys[a], i,
                 a == 0 ? "must be a wavelength in nm (100 to 20000), increasing" : a == 1 ? "must be a number > 0" : "must be a number >= 0");
        return json_bad(c, where, msg);
      }
      dst[a][i] = (float)v;
    }
  }
  nk_curve *q = grow_for(c->s->nk, c->s->nnk, sizeof *q);
  if (!q) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  c->s->nk = q;
  q[c->s->nnk++] = cv;
  m->nk = (int)c->s->nnk;
  m->eta = tab_to_rgb(cv.nm, cv.eta, cv.n);
  m->k = tab_to_rgb(cv.nm, cv.k, cv.n);
  /* An index is not a colour: a projection with a negative channel is clamped. */
  m->eta = c3(fmaxf(m->eta.r, 1e-3f), fmaxf(m->eta.g, 1e-3f), fmaxf(m->eta.b, 1e-3f));
  m->k = c3(fmaxf(m->k.r, 0), fmaxf(m->k.g, 0), fmaxf(m->k.b, 0));
  return VALO_OK;
}

/* "principled": Mitsuba's (material/principled.h); "specular" s, or "ior", sets the index
 * (eta = 2 / (1 - sqrt(0.08 s)) - 1: 1.5 at the default 0.5). */
static valo_status parse_principled(jctx *c, const cJSON *o, const char *where, material *m) {
  m->type = MAT_PRINCIPLED;
  m->kd = c3(0.5f, 0.5f, 0.5f);
  m->roughness = 0.5f;
  TRY(get_rgb_tex(c, o, "base_color", where, &m->kd, &m->tex_kd));
  static const char *const keys[] = {"metallic", "spec_tint", "sheen", "sheen_tint", "flatness", "clearcoat", "clearcoat_gloss", "spec_trans", "anisotropic"};
  float *dst[] = {&m->metallic, &m->spec_tint, &m->sheen, &m->sheen_tint, &m->flatness, &m->clearcoat, &m->clearcoat_gloss, &m->spec_trans, &m->anisotropy};
  for (int k = 0; k < 9; k++) {
    double x = 0;
    TRY(json_get_num(c, o, keys[k], where, 0, 1, &x));
    *dst[k] = (float)x;
  }
  double spec = 0.5, ior = 0;
  TRY(json_get_num(c, o, "specular", where, 0, 1, &spec));
  TRY(json_get_num(c, o, "ior", where, 1.0001, 10, &ior));
  if (ior > 0 && cJSON_GetObjectItemCaseSensitive(o, "specular")) return json_bad(c, where, "give \"specular\" or \"ior\", not both");
  m->ior = ior > 0 ? (float)ior : (float)(2 / (1 - sqrt(0.08 * fmax(spec, 1e-3))) - 1);
  m->anisotropic = m->anisotropy > 0;
  return VALO_OK;
}

/* "blend": "materials" names two others of the file (not blends, emitters, nor with maps
 * or opacities of their own: the blend carries those), "weight" the second's share;
 * "sided" (by_side): the first seen from the front, the second from the back. */
static valo_status parse_blend(jctx *c, const cJSON *o, const char *where, int by_side, material *m) {
  m->type = MAT_BLEND;
  m->weight = 0.5f;
  m->blend_by_side = by_side;
  const cJSON *w = cJSON_GetObjectItemCaseSensitive(o, "weight");
  int raw = 0;
  TRY(json_get_bool(c, o, "weight_raw", where, &raw));
  char at[300];
  snprintf(at, sizeof at, "%s.weight", where);
  if (cJSON_IsString(w) || cJSON_IsObject(w)) {
    TRY(get_float_map(c, w, raw, at, "weight map", &m->tex_weight));
    m->weight = 1;
  } else {
    double x = m->weight;
    TRY(json_get_num(c, o, "weight", where, 0, 1, &x));
    m->weight = (float)x;
  }
  snprintf(at, sizeof at, "%s.materials", where);
  const cJSON *ms = cJSON_GetObjectItemCaseSensitive(o, "materials");
  if (!cJSON_IsArray(ms) || cJSON_GetArraySize(ms) != 2) return json_bad(c, at, "must name two materials");
  for (int k = 0; k < 2; k++) {
    const char *n = cJSON_GetStringValue(cJSON_GetArrayItem(ms, k));
    if (!n) return json_bad(c, at, "must name two materials");
    uint32_t i = 0;
    const cJSON *e = c->mats ? c->mats->child : NULL;
    while (e && strcmp(e->string, n)) e = e->next, i++;
    char msg[200];
    snprintf(msg, sizeof msg, "no material is named \"%.80s\"", n);
    if (!e || e == o) return json_bad(c, at, e ? "a blend cannot hold itself" : msg);
    const char *t = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(e, "type"));
    static const char *const own[] = {"emission", "normal_map", "bump_map", "alpha_map", "opacity", NULL};
    for (int q = 0; own[q]; q++)
      if (cJSON_GetObjectItemCaseSensitive(e, own[q])) {
        snprintf(msg, sizeof msg, "\"%.80s\" has its own %s: give it to the blend", n, own[q]);
        return json_bad(c, at, msg);
      }
    if (t && (!strcmp(t, "blend") || !strcmp(t, "sided") || !strcmp(t, "null"))) {
      snprintf(msg, sizeof msg, "\"%.80s\" is a %s material, which a blend cannot hold", n, t);
      return json_bad(c, at, msg);
    }
    m->blend[k] = (int)(c->mfirst + i);
  }
  return VALO_OK;
}

valo_status json_parse_material(jctx *c, const cJSON *o, const char *name, material *m) {
  char where[256];
  snprintf(where, sizeof where, "materials.%s", name);
  if (!cJSON_IsObject(o)) return json_bad(c, where, "must be an object");
  const char *type = NULL;
  TRY(json_get_str(c, o, "type", where, &type));
  if (!type) return json_bad(c, where, "needs a \"type\" (diffuse, phong, mirror, dielectric, thindielectric, conductor, pbr, plastic, principled, blend, sided, null)");
  *m = material_default();
  snprintf(m->name, sizeof m->name, "%s", name);
  static const char *const k_diffuse[] = {"type", "reflectance", "normal_map", "alpha_map", "alpha_cutoff", "opacity", "opacity_raw", "emission", "two_sided", "black_back", "vertex_colors", "bump_map", "bump_scale", "map_style", "map_back", NULL};
  static const char *const k_phong[] = {"type", "diffuse", "specular", "exponent", "normal_map", "alpha_map", "alpha_cutoff", "opacity", "opacity_raw", "emission", "two_sided", "black_back", "vertex_colors", "bump_map", "bump_scale", "map_style", "map_back", NULL};
  static const char *const k_mirror[] = {"type", "reflectance", "diffuse", "normal_map", "alpha_map", "alpha_cutoff", "opacity", "opacity_raw", "emission", "two_sided", "black_back", "bump_map", "bump_scale", "map_style", "map_back", NULL};
  static const char *const k_dielectric[] = {"type", "ior", "dispersion", "transmittance", "roughness", "roughness_u", "roughness_v", "distribution", "normal_map", "alpha_map", "alpha_cutoff", "opacity", "opacity_raw", "emission", "two_sided", "black_back", "bump_map", "bump_scale", "map_style", "map_back", "roughness_map", "roughness_map_is_alpha", "smith", NULL};
  static const char *const k_thin[] = {"type", "ior", "transmittance", "normal_map", "alpha_map", "alpha_cutoff", "opacity", "opacity_raw", "emission", "two_sided", "black_back", "bump_map", "bump_scale", "map_style", "map_back", NULL};
  static const char *const k_conductor[] = {"type", "preset", "eta", "k", "spectrum", "reflectance", "roughness", "roughness_u", "roughness_v", "distribution", "normal_map", "alpha_map", "alpha_cutoff", "opacity", "opacity_raw", "emission", "two_sided", "black_back", "bump_map", "bump_scale", "map_style", "map_back", "roughness_map", "roughness_map_is_alpha", "smith", NULL};
  static const char *const k_plastic[] = {"type", "diffuse", "specular", "ior", "roughness", "distribution", "nonlinear", "normal_map", "alpha_map", "alpha_cutoff", "opacity", "opacity_raw",
                                          "emission", "two_sided", "black_back", "vertex_colors", "bump_map", "bump_scale", "map_style", "map_back", "smith", NULL};
  /* (a sided material takes the same keys but type, weight and weight_raw) */
  static const char *const k_blend[] = {"weight", "weight_raw", "type", "materials", "normal_map", "alpha_map", "alpha_cutoff", "opacity", "opacity_raw",
                                        "bump_map", "bump_scale", "map_style", "map_back", NULL};
  static const char *const k_principled[] = {"type", "base_color", "metallic", "roughness", "specular", "ior", "spec_tint", "sheen", "sheen_tint", "flatness",
                                             "clearcoat", "clearcoat_gloss", "spec_trans", "anisotropic", "normal_map", "alpha_map", "alpha_cutoff", "opacity", "opacity_raw",
                                             "emission", "two_sided", "black_back", "vertex_colors", "bump_map", "bump_scale", "map_style", "map_back", "roughness_map", "roughness_map_is_alpha", "metallic_map", NULL};
  static const char *const k_pbr[] = {"type", "base_color", "metallic", "roughness", "ior", "specular", "specular_color", "clearcoat", "clearcoat_roughness", "clearcoat_map", "clearcoat_roughness_map", "sheen_color", "sheen_roughness", "sheen_map", "metallic_roughness_map", "normal_map", "alpha_map", "alpha_cutoff", "opacity", "opacity_raw", "emission",
                                      "two_sided", "black_back", "vertex_colors", "bump_map", "bump_scale", "map_style", "map_back", "roughness_map", "roughness_map_is_alpha", "metallic_map", NULL};
  if (!strcmp(type, "null")) {
    /* No surface at all: rays pass through (a medium's boundary); nothing else to set. */
    static const char *const k_null[] = {"type", NULL};
    TRY(json_check_keys(c, o, where, k_null));
    m->type = MAT_NULL;
    return VALO_OK;
  }
  if (!strcmp(type, "pbr")) {
    TRY(json_check_keys(c, o, where, k_pbr));
    m->type = MAT_PBR;
    m->roughness = 0.5f;
    TRY(get_rgb_tex(c, o, "base_color", where, &m->kd, &m->tex_kd));
    double metal = 0;
    TRY(json_get_num(c, o, "metallic", where, 0, 1, &metal));
    m->metallic = (float)metal;
    TRY(get_data_map(c, o, "metallic_roughness_map", where, "metallic-roughness map", &m->tex_mr));
    double ior = 1.5, spec = 1; /* the dielectric's Fresnel: glTF's KHR_materials_ior and _specular */
    rgb spec_color = c3(1, 1, 1);
    TRY(json_get_num(c, o, "ior", where, 1.0, 10.0, &ior));
    TRY(json_get_num(c, o, "specular", where, 0, 1, &spec));
    TRY(json_get_rgb(c, o, "specular_color", where, &spec_color));
    m->ior = (float)ior;
    material_pbr_specular(m, m->ior, (float)spec, spec_color);
    double cc = 0, ccr = 0; /* glTF's KHR_materials_clearcoat */
    TRY(json_get_num(c, o, "clearcoat", where, 0, 1, &cc));
    TRY(json_get_num(c, o, "clearcoat_roughness", where, 0, 1, &ccr));
    m->clearcoat = (float)cc;
    m->clearcoat_roughness = (float)ccr;
    TRY(get_data_map(c, o, "clearcoat_map", where, "clearcoat map", &m->tex_cc));
    TRY(get_data_map(c, o, "clearcoat_roughness_map", where, "clearcoat roughness map", &m->tex_ccr));
    double shr = 0; /* glTF's KHR_materials_sheen */
    TRY(json_get_rgb(c, o, "sheen_color", where, &m->sheen_color));
    TRY(json_get_num(c, o, "sheen_roughness", where, 0, 1, &shr));
    if (m->sheen_color.r > 1 || m->sheen_color.g > 1 || m->sheen_color.b > 1) return json_bad(c, where, "sheen_color must be at most 1");
    m->sheen_roughness = (float)shr;
    TRY(get_map(c, o, "sheen_map", where, "colour map", 0, &m->tex_sheen));
    if (c3_max(m->sheen_color) > 0) sheen_prepare(m);
  } else if (!strcmp(type, "diffuse")) {
    TRY(json_check_keys(c, o, where, k_diffuse));
    m->type = MAT_DIFFUSE;
    TRY(get_rgb_tex(c, o, "reflectance", where, &m->kd, &m->tex_kd));
  } else if (!strcmp(type, "phong")) {
    TRY(json_check_keys(c, o, where, k_phong));
    m->type = MAT_PHONG;
    m->kd = c3(0.5f, 0.5f, 0.5f); m->ks = c3(0.2f, 0.2f, 0.2f); m->exponent = 20;
    TRY(get_rgb_tex(c, o, "diffuse", where, &m->kd, &m->tex_kd));
    TRY(get_rgb_tex(c, o, "specular", where, &m->ks, &m->tex_ks));
    double e = m->exponent;
    TRY(json_get_num(c, o, "exponent", where, 0, 1e6, &e));
    m->exponent = (float)e;
  } else if (!strcmp(type, "mirror")) {
    TRY(json_check_keys(c, o, where, k_mirror));
    m->type = MAT_MIRROR;
    m->kd = c3(0, 0, 0); m->ks = c3(1, 1, 1);
    TRY(json_get_rgb(c, o, "reflectance", where, &m->ks));
    TRY(json_get_rgb(c, o, "diffuse", where, &m->kd));
  } else if (!strcmp(type, "dielectric") || !strcmp(type, "thindielectric")) {
    int thin = type[0] == 't'; /* a pane: no dispersion, no roughness */
    TRY(json_check_keys(c, o, where, thin ? k_thin : k_dielectric));
    m->type = thin ? MAT_THIN_DIELECTRIC : MAT_DIELECTRIC;
    double ior = 1.5;
    TRY(json_get_num(c, o, "ior", where, 1.0, 10.0, &ior));
    m->ior = (float)ior;
    TRY(json_get_rgb(c, o, "transmittance", where, &m->transmittance)); /* tints what it transmits, at each crossing */
    const char *disp = NULL;
    TRY(json_get_str(c, o, "dispersion", where, &disp));
    if (disp) {
      dispersion d;
      if (dispersion_parse(disp, &d)) return json_bad(c, where, "unknown dispersion (fused_silica, sapphire, water, cauchy_glass, dense_flint)");
      m->dispersion = (int)d;
      m->ior = dispersion_ior(d, 589.3f); /* RGB mode renders at the sodium d line */
    }
  } else if (!strcmp(type, "principled")) {
    TRY(json_check_keys(c, o, where, k_principled));
    TRY(parse_principled(c, o, where, m));
  } else if (!strcmp(type, "blend") || !strcmp(type, "sided")) {
    TRY(json_check_keys(c, o, where, type[0] == 'b' ? k_blend : k_blend + 2));
    TRY(parse_blend(c, o, where, type[0] == 's', m));
  } else if (!strcmp(type, "plastic")) {
    TRY(json_check_keys(c, o, where, k_plastic));
    m->type = MAT_PLASTIC;
    m->kd = c3(0.5f, 0.5f, 0.5f); m->ks = c3(1, 1, 1);
    TRY(get_rgb_tex(c, o, "diffuse", where, &m->kd, &m->tex_kd));
    TRY(json_get_rgb(c, o, "specular", where, &m->ks));
    double ior = 1.49; /* polypropylene, Mitsuba's default */
    TRY(json_get_num(c, o, "ior", where, 1.0, 10.0, &ior));
    m->ior = (float)ior;
    TRY(json_get_bool(c, o, "nonlinear", where, &m->nonlinear));
  } else if (!strcmp(type, "conductor")) {
    TRY(json_check_keys(c, o, where, k_conductor));
    m->type = MAT_CONDUCTOR;
    const char *preset = NULL;
    TRY(json_get_str(c, o, "preset", where, &preset));
    if (cJSON_GetObjectItemCaseSensitive(o, "spectrum")) {
      if (preset || cJSON_GetObjectItemCaseSensitive(o, "eta") || cJSON_GetObjectItemCaseSensitive(o, "k"))
        return json_bad(c, where, "give either \"spectrum\" or \"preset\" / \"eta\" and \"k\", not both");
      TRY(parse_nk_spectrum(c, cJSON_GetObjectItemCaseSensitive(o, "spectrum"), where, m));
    } else if (preset) {
      if (conductor_preset(preset, &m->eta, &m->k))
        return json_bad(c, where, "unknown conductor preset (Mitsuba's names: Au, Ag, Cu, Al, Cr, Ni_palik, W, ...; docs/scene-format.md lists them)");
    } else {
      if (!cJSON_GetObjectItemCaseSensitive(o, "eta") || !cJSON_GetObjectItemCaseSensitive(o, "k"))
        return json_bad(c, where, "a conductor needs \"preset\" or both \"eta\" and \"k\"");
    }
    TRY(json_get_rgb(c, o, "eta", where, &m->eta));
    TRY(json_get_rgb(c, o, "k", where, &m->k));
    TRY(json_get_rgb(c, o, "reflectance", where, &m->tint));
  } else {
    return json_bad(c, where, "unknown material type (diffuse, phong, mirror, dielectric, thindielectric, conductor, pbr, plastic, principled, blend, sided, null)");
  }
  TRY(get_data_map(c, o, "normal_map", where, "normal map", &m->tex_normal));
  TRY(get_data_map(c, o, "bump_map", where, "bump (height) map", &m->tex_bump));
  /* a cutout: the surface is there where the map's alpha channel (its first channel when it
   * has none) reaches alpha_cutoff */
  TRY(get_data_map(c, o, "alpha_map", where, "alpha map", &m->tex_alpha));
  if (m->tex_alpha >= 0) m->alpha_channel = c->s->tex[m->tex_alpha].has_alpha;
  double cutoff = m->alpha_cutoff;
  TRY(json_get_num(c, o, "alpha_cutoff", where, 0, 1, &cutoff));
  m->alpha_cutoff = (float)cutoff;
  TRY(get_opacity(c, o, where, m));
  double bscale = 1;
  TRY(json_get_num(c, o, "bump_scale", where, -1e6, 1e6, &bscale));
  m->bump_scale = (float)bscale;
  /* how normal and bump maps are read: Mitsuba 3's conventions (the default), or the mesh's
   * tangents with their handedness (glTF's); seen from behind, the whole frame turned or
   * only its normal (Mitsuba's twosided around the map) */
  const char *style = "mitsuba", *back = "turn";
  TRY(json_get_str(c, o, "map_style", where, &style));
  if (strcmp(style, "mitsuba") && strcmp(style, "tangents")) return json_bad(c, where, "map_style must be \"mitsuba\" or \"tangents\"");
  m->map_tangents = !strcmp(style, "tangents");
  TRY(json_get_str(c, o, "map_back", where, &back));
  if (strcmp(back, "turn") && strcmp(back, "mirror")) return json_bad(c, where, "map_back must be \"turn\" or \"mirror\"");
  m->map_back_mirror = !strcmp(back, "mirror");
  double rough = m->roughness;
  TRY(json_get_num(c, o, "roughness", where, 0, 1, &rough));
  m->roughness = (float)rough;
  /* anisotropic: roughness along the surface's u direction and along v */
  int has_u = cJSON_GetObjectItemCaseSensitive(o, "roughness_u") != NULL, has_v = cJSON_GetObjectItemCaseSensitive(o, "roughness_v") != NULL;
  if (has_u || has_v) {
    if (!has_u || !has_v) return json_bad(c, where, "give both roughness_u and roughness_v");
    if (cJSON_GetObjectItemCaseSensitive(o, "roughness")) return json_bad(c, where, "give roughness, or roughness_u and roughness_v, not both");
    double ru = 0, rv = 0;
    TRY(json_get_num(c, o, "roughness_u", where, 0, 1, &ru));
    TRY(json_get_num(c, o, "roughness_v", where, 0, 1, &rv));
    m->roughness = (float)ru;
    m->roughness_v = (float)rv;
    m->anisotropic = ru != rv;
  }
  /* maps (linear unless they say otherwise) multiplying roughness (or alpha, its square)
   * and metallic by their value, the mean of their channels */
  TRY(get_data_map(c, o, "roughness_map", where, "roughness map", &m->tex_rough));
  TRY(json_get_bool(c, o, "roughness_map_is_alpha", where, &m->rough_is_alpha));
  TRY(get_data_map(c, o, "metallic_map", where, "metallic map", &m->tex_metal));
  const char *dist = NULL;
  TRY(json_get_str(c, o, "distribution", where, &dist));
  if (dist && strcmp(dist, "ggx") && strcmp(dist, "beckmann")) return json_bad(c, where, "distribution must be \"ggx\" or \"beckmann\"");
  m->beckmann = dist && !strcmp(dist, "beckmann");
  const char *smith = NULL;
  TRY(json_get_str(c, o, "smith", where, &smith));
  if (smith && strcmp(smith, "correlated") && strcmp(smith, "separable")) return json_bad(c, where, "smith must be \"correlated\" or \"separable\"");
  m->smith_separable = smith && !strcmp(smith, "separable");
  TRY(get_rgb_tex(c, o, "emission", where, &m->emission, &m->tex_ke));
  /* light sampling would see such a light whole, while rays that meet it see it in part */
  if ((m->opacity < 1 || m->alpha_stochastic) && !c3_black(m->emission))
    return json_bad(c, where, "an emitting material cannot have an opacity: give the emission a darker colour instead");
  TRY(json_get_bool(c, o, "two_sided", where, &m->two_sided));
  TRY(json_get_bool(c, o, "black_back", where, &m->black_back));
  TRY(json_get_bool(c, o, "vertex_colors", where, &m->vertex_colors)); /* kd times the mesh's vertex colours */
  if (m->type == MAT_PLASTIC) { /* a coat already tabulated for the same index and roughness is reused (15-60 ms each) */
    const material *same = NULL;
    for (uint32_t i = 0; i < c->s->nmats && !same; i++) {
      const material *o2 = &c->s->mats[i];
      if (o2->type == MAT_PLASTIC && o2->ior == m->ior && o2->roughness == m->roughness && o2->beckmann == m->beckmann) same = o2;
    }
    if (same) {
      memcpy(m->coat_t, same->coat_t, sizeof m->coat_t);
      m->coat_ri = same->coat_ri;
    } else {
      plastic_prepare(m);
    }
  }
  return VALO_OK;
}


/* A grid medium's density: "file" (Mitsuba's .vol) placed in its own box or in
 * [bounds_min, bounds_max]. */
static valo_status parse_grid(jctx *c, const cJSON *e, const char *where, medium *m) {
  const char *file = NULL;
  TRY(json_get_str(c, e, "file", where, &file));
  if (!file) return json_bad(c, where, "a grid medium needs \"file\" (a .vol density grid)");
  char full[2048];
  json_resolve_path(c, file, full, sizeof full);
  valo_error gerr;
  if (density_grid_load(full, &m->grid, &gerr)) {
    char w[300];
    snprintf(w, sizeof w, "%s.file", where);
    return json_bad(c, w, gerr.message);
  }
  vec3 lo = m->grid->box.lo, hi = m->grid->box.hi;
  valo_status st = json_get_vec(c, e, "bounds_min", where, 0, &lo);
  if (!st) st = json_get_vec(c, e, "bounds_max", where, 0, &hi);
  if (!st && !(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z)) st = json_bad(c, where, "the grid's box needs bounds_min < bounds_max on every axis");
  if (st) { density_grid_free(m->grid); m->grid = NULL; return st; }
  m->grid->box.lo = lo;
  m->grid->box.hi = hi;
  return VALO_OK;
}

valo_status json_parse_media(jctx *c, const cJSON *o) {
  if (!cJSON_IsObject(o)) return json_bad(c, "media", "must be an object of named media");
  for (const cJSON *e = o->child; e; e = e->next) {
    char where[256];
    snprintf(where, sizeof where, "media.%s", e->string);
    if (!cJSON_IsObject(e)) return json_bad(c, where, "must be an object");
    const char *type = NULL;
    TRY(json_get_str(c, e, "type", where, &type));
    int grid = type && !strcmp(type, "grid");
    if (!type || (!grid && strcmp(type, "homogeneous"))) return json_bad(c, where, "needs a \"type\": \"homogeneous\" or \"grid\"");
    static const char *const keys[] = {"type", "sigma_a", "sigma_s", "scale", "g", "emission", NULL};
    static const char *const gkeys[] = {"type", "sigma_a", "sigma_s", "scale", "g", "emission", "file", "bounds_min", "bounds_max", NULL};
    TRY(json_check_keys(c, e, where, grid ? gkeys : keys));
    for (uint32_t i = 0; i < c->s->nmedia; i++)
      if (!strcmp(c->s->media[i].name, e->string)) return json_bad(c, where, "a medium of this name is already defined");
    medium m;
    memset(&m, 0, sizeof m);
    snprintf(m.name, sizeof m.name, "%s", e->string);
    m.sigma_a = c3(1, 1, 1);
    m.sigma_s = c3(1, 1, 1);
    double scale = 1, g = 0;
    TRY(json_get_rgb(c, e, "sigma_a", where, &m.sigma_a));
    TRY(json_get_rgb(c, e, "sigma_s", where, &m.sigma_s));
    TRY(json_get_num(c, e, "scale", where, 0, 1e9, &scale));
    TRY(json_get_num(c, e, "g", where, -0.999, 0.999, &g));
    TRY(json_get_rgb(c, e, "emission", where, &m.Le));
    m.sigma_a = c3_scale(m.sigma_a, (float)scale);
    m.sigma_s = c3_scale(m.sigma_s, (float)scale);
    m.g = (float)g;
    if (!c3_finite(m.sigma_a) || !c3_finite(m.sigma_s)) return json_bad(c, where, "sigma_a and sigma_s times scale must be finite");
    if (grid) TRY(parse_grid(c, e, where, &m));
    medium *q = grow_for(c->s->media, c->s->nmedia, sizeof *q);
    if (!q) { density_grid_free(m.grid); return err_set(c->err, VALO_ERR_NOMEM, "out of memory"); }
    c->s->media = q;
    q[c->s->nmedia++] = m;
  }
  return VALO_OK;
}

valo_status json_get_medium(jctx *c, const cJSON *o, const char *key, const char *where, int32_t *med) {
  const char *name = NULL;
  TRY(json_get_str(c, o, key, where, &name));
  if (!name) return VALO_OK;
  for (uint32_t i = 0; i < c->s->nmedia; i++)
    if (!strcmp(c->s->media[i].name, name)) { *med = (int32_t)i; return VALO_OK; }
  char w[300], msg[200];
  snprintf(w, sizeof w, "%s.%s", where, key);
  snprintf(msg, sizeof msg, "medium \"%.100s\" is not defined in \"media\"", name);
  return json_bad(c, w, msg);
}
