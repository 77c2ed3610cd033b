/* load_json.c — owns the JSON scene format (docs/scene-format.md): camera, film, render
 * settings, shapes (mesh files and spheres) with transforms, named materials, lights
 * and the environment. Strict: unknown keys and wrong types are errors that name the
 * file and the JSON path; syntax errors give line:column. */
#include "scene/scene.h"
#include "core/error.h"
#include "light/envmap.h"
#include "core/spectrum.h"
#include <cjson/cJSON.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct jctx {
  scene *s; const char *path; char dir[1024]; valo_error *err;
  int cam_from_file;           /* camera.from_file: take the first shape file's camera */
  float cam_fov, cam_aperture, cam_focus; /* its overrides (fov <= 0: keep the file's) */
} jctx;

static void resolve_path(const struct jctx *c, const char *rel, char *out, size_t n);

static valo_status bad(jctx *c, const char *where, const char *what) {
  return err_set(c->err, VALO_ERR_INVALID, "%s: %s: %s", c->path, where, what);
}

static valo_status check_keys(jctx *c, const cJSON *obj, const char *where, const char *const *allowed) {
  if (!cJSON_IsObject(obj)) return bad(c, where, "must be an object");
  for (const cJSON *it = obj->child; it; it = it->next) {
    int ok = 0;
    for (const char *const *a = allowed; *a; a++)
      if (!strcmp(it->string, *a)) { ok = 1; break; }
    if (!ok) {
      char msg[512];
      int n = snprintf(msg, sizeof msg, "unknown key \"%s\" (allowed:", it->string);
      for (const char *const *a = allowed; *a && n < (int)sizeof msg - 40; a++) n += snprintf(msg + n, sizeof msg - n, " %s", *a);
      snprintf(msg + n, sizeof msg - n, ")");
      return bad(c, where, msg);
    }
  }
  return VALO_OK;
}

static valo_status get_num(jctx *c, const cJSON *o, const char *key, const char *where, double lo, double hi, double *out) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!v) return VALO_OK;
  char w[300];
  snprintf(w, sizeof w, "%s.%s", where, key);
  if (!cJSON_IsNumber(v)) return bad(c, w, "must be a number");
  if (!isfinite(v->valuedouble) || v->valuedouble < lo || v->valuedouble > hi) {
    char msg[160];
    snprintf(msg, sizeof msg, "%g is out of range [%g, %g]", v->valuedouble, lo, hi);
    return bad(c, w, msg);
  }
  *out = v->valuedouble;
  return VALO_OK;
}
static valo_status get_int(jctx *c, const cJSON *o, const char *key, const char *where, double lo, double hi, int *out) {
  double d = *out;
  valo_status st = get_num(c, o, key, where, lo, hi, &d);
  if (st) return st;
  if (d != floor(d)) {
    char w[300];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return bad(c, w, "must be a whole number");
  }
  *out = (int)d;
  return VALO_OK;
}
static valo_status get_vec(jctx *c, const cJSON *o, const char *key, const char *where, int allow_scalar, vec3 *out) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!v) return VALO_OK;
  char w[300];
  snprintf(w, sizeof w, "%s.%s", where, key);
  if (allow_scalar && cJSON_IsNumber(v)) {
    if (!isfinite(v->valuedouble)) return bad(c, w, "must be finite");
    *out = v3((float)v->valuedouble, (float)v->valuedouble, (float)v->valuedouble);
    return VALO_OK;
  }
  if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
    return bad(c, w, allow_scalar ? "must be a number or an array of 3 numbers" : "must be an array of 3 numbers");
  float f[3];
  for (int i = 0; i < 3; i++) {
    const cJSON *e = cJSON_GetArrayItem(v, i);
    if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble)) return bad(c, w, "must hold 3 finite numbers");
    f[i] = (float)e->valuedouble;
  }
  *out = v3(f[0], f[1], f[2]);
  return VALO_OK;
}
static valo_status get_rgb(jctx *c, const cJSON *o, const char *key, const char *where, rgb *out) {
  vec3 v = v3(out->r, out->g, out->b);
  valo_status st = get_vec(c, o, key, where, 1, &v);
  if (st) return st;
  if (v.x < 0 || v.y < 0 || v.z < 0) {
    char w[300];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return bad(c, w, "must not be negative");
  }
  *out = c3(v.x, v.y, v.z);
  return VALO_OK;
}
static valo_status get_str(jctx *c, const cJSON *o, const char *key, const char *where, const char **out) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!v) return VALO_OK;
  if (!cJSON_IsString(v)) {
    char w[300];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return bad(c, w, "must be a string");
  }
  *out = v->valuestring;
  return VALO_OK;
}
static valo_status get_bool(jctx *c, const cJSON *o, const char *key, const char *where, int *out) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!v) return VALO_OK;
  if (!cJSON_IsBool(v)) {
    char w[300];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return bad(c, w, "must be true or false");
  }
  *out = cJSON_IsTrue(v);
  return VALO_OK;
}

#define TRY(x) do { valo_status st_ = (x); if (st_) return st_; } while (0)

/* A view is usable: position and look_at differ, up is not along the view direction. */
static valo_status check_view(jctx *c, const char *where, vec3 pos, vec3 look_at, vec3 up) {
  vec3 fwd = v3_sub(look_at, pos);
  if (!(v3_len2(fwd) > 0)) return bad(c, where, "position and look_at must differ");
  char w[96];
  snprintf(w, sizeof w, "%s.up", where);
  if (!(v3_len2(v3_cross(v3_norm(fwd), v3_norm(up))) > 1e-12f)) return bad(c, w, "must not be parallel to the view direction");
  return VALO_OK;
}

/* camera.keyframes: [{"frame": F, "position", "look_at", "up", "fov"}, ...], frames
 * increasing; a key's missing fields take the camera's. */
static valo_status parse_keyframes(jctx *c, const cJSON *a, const camera *cam) {
  if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) < 1) return bad(c, "camera.keyframes", "must be a non-empty array of objects");
  int n = cJSON_GetArraySize(a);
  if (n > 100000) return bad(c, "camera.keyframes", "more than 100000 keyframes");
  cam_key *k = calloc((size_t)n, sizeof *k);
  if (!k) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  c->s->cam_keys = k;
  c->s->ncam_keys = (uint32_t)n;
  static const char *const keys[] = {"frame", "position", "look_at", "up", "fov", NULL};
  int i = 0;
  for (const cJSON *e = a->child; e; e = e->next, i++) {
    char where[64];
    snprintf(where, sizeof where, "camera.keyframes[%d]", i);
    TRY(check_keys(c, e, where, keys));
    if (!cJSON_GetObjectItemCaseSensitive(e, "frame")) return bad(c, where, "needs \"frame\"");
    double d = 0;
    TRY(get_num(c, e, "frame", where, -1e9, 1e9, &d));
    k[i].frame = (float)d;
    if (i > 0 && !(k[i].frame > k[i - 1].frame)) return bad(c, where, "frames must increase from key to key");
    k[i].pos = cam->pos; k[i].look_at = cam->look_at; k[i].up = cam->up; k[i].fov_deg = cam->fov_deg;
    TRY(get_vec(c, e, "position", where, 0, &k[i].pos));
    TRY(get_vec(c, e, "look_at", where, 0, &k[i].look_at));
    TRY(get_vec(c, e, "up", where, 0, &k[i].up));
    d = k[i].fov_deg; TRY(get_num(c, e, "fov", where, 1e-3, 179.9, &d)); k[i].fov_deg = (float)d;
    TRY(check_view(c, where, k[i].pos, k[i].look_at, k[i].up));
  }
  return VALO_OK;
}

static valo_status parse_camera(jctx *c, const cJSON *o) {
  static const char *const keys[] = {"position", "look_at", "up", "fov", "aperture_radius", "focus_distance", "from_file", "keyframes", NULL};
  TRY(check_keys(c, o, "camera", keys));
  camera *cam = &c->s->cam;
  const cJSON *ff = cJSON_GetObjectItemCaseSensitive(o, "from_file");
  if (ff && !cJSON_IsBool(ff)) return bad(c, "camera.from_file", "must be true or false");
  if (cJSON_IsTrue(ff)) {
    /* The first shape file with a camera supplies position, orientation and fov; the
     * lens (and optionally fov) come from here. */
    if (cJSON_GetObjectItemCaseSensitive(o, "position") || cJSON_GetObjectItemCaseSensitive(o, "look_at") ||
        cJSON_GetObjectItemCaseSensitive(o, "up"))
      return bad(c, "camera", "\"from_file\" takes position, look_at and up from the file; give only fov, aperture_radius, focus_distance");
    double d = -1;
    TRY(get_num(c, o, "fov", "camera", 1e-3, 179.9, &d)); c->cam_fov = (float)d;
    d = 0; TRY(get_num(c, o, "aperture_radius", "camera", 0, 1e6, &d)); c->cam_aperture = (float)d;
    d = -1; TRY(get_num(c, o, "focus_distance", "camera", 1e-6, 1e9, &d)); c->cam_focus = (float)d;
    c->cam_from_file = 1;
    return VALO_OK;
  }
  cam->pos = v3(0, 0, 5); cam->look_at = v3(0, 0, 0); cam->up = v3(0, 1, 0);
  cam->fov_deg = 40; cam->aperture_radius = 0; cam->focus_distance = -1;
  double d;
  TRY(get_vec(c, o, "position", "camera", 0, &cam->pos));
  TRY(get_vec(c, o, "look_at", "camera", 0, &cam->look_at));
  TRY(get_vec(c, o, "up", "camera", 0, &cam->up));
  d = cam->fov_deg; TRY(get_num(c, o, "fov", "camera", 1e-3, 179.9, &d)); cam->fov_deg = (float)d;
  d = 0; TRY(get_num(c, o, "aperture_radius", "camera", 0, 1e6, &d)); cam->aperture_radius = (float)d;
  d = -1; TRY(get_num(c, o, "focus_distance", "camera", 1e-6, 1e9, &d)); cam->focus_distance = (float)d;
  TRY(check_view(c, "camera", cam->pos, cam->look_at, cam->up));
  vec3 fwd = v3_sub(cam->look_at, cam->pos);
  if (cam->focus_distance <= 0) cam->focus_distance = v3_len(fwd);
  c->s->has_camera = 1;
  const cJSON *kf = cJSON_GetObjectItemCaseSensitive(o, "keyframes");
  if (kf) TRY(parse_keyframes(c, kf, cam));
  return VALO_OK;
}

static valo_status parse_render(jctx *c, const cJSON *o) {
  valo_options *op = &c->s->file_opts;
  if (!cJSON_IsObject(o)) return bad(c, "render", "must be an object");
  /* An object under "render" holds an integrator's parameters ("photon": {"count":
   * 100000}); they become the options' parameter text "photon.count=100000", checked
   * against that integrator's table (and its name against the registry) when rendering. */
  for (const cJSON *it = o->child; it; it = it->next) {
    if (!cJSON_IsObject(it)) continue;
    char w[96];
    snprintf(w, sizeof w, "render.%s", it->string);
    for (const cJSON *p = it->child; p; p = p->next) {
      char w2[160];
      snprintf(w2, sizeof w2, "%s.%s", w, p->string);
      if (!cJSON_IsNumber(p) && !cJSON_IsBool(p)) return bad(c, w2, "must be a number");
      double v = cJSON_IsBool(p) ? (cJSON_IsTrue(p) ? 1 : 0) : p->valuedouble;
      size_t used = strlen(op->params);
      int n = snprintf(op->params + used, sizeof op->params - used, "%s%s.%s=%.17g", used ? " " : "", it->string, p->string, v);
      if (n < 0 || (size_t)n >= sizeof op->params - used) return bad(c, w, "too many parameters");
    }
  }
  static const char *const keys[] = {"integrator", "spp", "seed", "max_depth", "accel", "time", "sampler", "light_sampler", NULL};
  for (const cJSON *it = o->child; it; it = it->next) {
    int ok = cJSON_IsObject(it);
    for (const char *const *a = keys; *a && !ok; a++) ok = !strcmp(it->string, *a);
    if (!ok) {
      char msg[400];
      snprintf(msg, sizeof msg, "unknown key \"%s\" (allowed: integrator spp seed max_depth accel time sampler light_sampler, or an "
                                "integrator's name with an object of its parameters)", it->string);
      return bad(c, "render", msg);
    }
  }
  const char *s = NULL;
  TRY(get_str(c, o, "integrator", "render", &s));
  if (s) snprintf(op->integrator, sizeof op->integrator, "%s", s);
  s = NULL;
  TRY(get_str(c, o, "accel", "render", &s));
  if (s) snprintf(op->accel, sizeof op->accel, "%s", s);
  s = NULL;
  TRY(get_str(c, o, "sampler", "render", &s));
  if (s && strcmp(s, "sobol") && strcmp(s, "independent")) return bad(c, "render.sampler", "must be \"sobol\" or \"independent\"");
  if (s) snprintf(op->sampler, sizeof op->sampler, "%s", s);
  s = NULL;
  TRY(get_str(c, o, "light_sampler", "render", &s));
  if (s && strcmp(s, "grid") && strcmp(s, "power")) return bad(c, "render.light_sampler", "must be \"grid\" or \"power\"");
  if (s) snprintf(op->light_sampler, sizeof op->light_sampler, "%s", s);
  TRY(get_int(c, o, "spp", "render", 1, 1048576, &op->spp));
  double seed = -1;
  TRY(get_num(c, o, "seed", "render", 0, 9007199254740992.0, &seed));
  if (seed >= 0) op->seed = (int64_t)seed;
  TRY(get_int(c, o, "max_depth", "render", -1, 100000, &op->max_depth));
  TRY(get_num(c, o, "time", "render", 0, 1e9, &op->time_budget));
  return VALO_OK;
}

/* A colour parameter may be a texture file name (sRGB-decoded colour map); the colour
 * then multiplies 1. */
/* An optional data map (linear, not sRGB) named by `key`: *tex stays -1 when absent. */
static valo_status get_data_map(jctx *c, const cJSON *o, const char *key, const char *where, const char *what, int *tex) {
  const char *file = NULL;
  valo_status st = get_str(c, o, key, where, &file);
  if (st || !file) return st;
  char full[2048];
  resolve_path(c, file, full, sizeof full);
  valo_error terr;
  *tex = scene_texture_file(c->s, full, 0, &terr);
  if (*tex >= 0) return VALO_OK;
  char w[300], msg[sizeof terr.message + 200];
  snprintf(w, sizeof w, "%s.%s", where, key);
  snprintf(msg, sizeof msg, "cannot read the %s: %s", what, terr.message);
  return bad(c, w, msg);
}

static valo_status get_rgb_tex(jctx *c, const cJSON *o, const char *key, const char *where, rgb *out, int *tex) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (v && cJSON_IsString(v)) {
    char full[2048];
    resolve_path(c, v->valuestring, full, sizeof full);
    FILE *f = fopen(full, "rb");
    if (!f) {
      char w[300];
      snprintf(w, sizeof w, "%s.%s", where, key);
      char msg[2200];
      snprintf(msg, sizeof msg, "cannot open texture %s: %s", full, strerror(errno));
      return bad(c, w, msg);
    }
    fclose(f);
    valo_error terr;
    *tex = scene_texture_file(c->s, full, 1, &terr);
    if (*tex < 0) {
      char w[300], msg[sizeof terr.message + 40];
      snprintf(w, sizeof w, "%s.%s", where, key);
      snprintf(msg, sizeof msg, "texture could not be decoded: %s", terr.message);
      return bad(c, w, msg);
    }
    *out = c3(1, 1, 1);
    return VALO_OK;
  }
  return get_rgb(c, o, key, where, out);
}

/* "spectrum": {"wavelengths": [nm...], "eta": [...], "k": [...]}, e.g. a table of
 * measured optical constants: stored in the scene for --spectral; RGB mode takes their
 * colourimetric projection (tab_to_rgb). */
static valo_status parse_nk_spectrum(jctx *c, const cJSON *o, const char *where0, material *m) {
  char where[300];
  snprintf(where, sizeof where, "%s.spectrum", where0);
  static const char *const keys[] = {"wavelengths", "eta", "k", NULL};
  TRY(check_keys(c, o, where, keys));
  nk_curve cv = {0};
  float *dst[3] = {cv.nm, cv.eta, cv.k};
  for (int a = 0; a < 3; a++) {
    const cJSON *arr = cJSON_GetObjectItemCaseSensitive(o, keys[a]);
    char msg[200];
    int n = cJSON_GetArraySize(arr);
    if (!cJSON_IsArray(arr) || n < 2 || n > NK_MAX) {
      snprintf(msg, sizeof msg, "\"%s\" must be an array of 2 to %d numbers", keys[a], NK_MAX);
      return bad(c, where, msg);
    }
    if (a > 0 && n != cv.n) {
      snprintf(msg, sizeof msg, "\"%s\" has %d values for %d wavelengths", keys[a], n, cv.n);
      return bad(c, where, msg);
    }
    cv.n = n;
    int i = 0;
    for (const cJSON *e = arr->child; e; e = e->next, i++) {
      double v = cJSON_IsNumber(e) ? e->valuedouble : NAN;
      int ok = isfinite(v) && (a == 0 ? v >= 100 && v <= 20000 && (i == 0 || v > dst[0][i - 1]) : a == 1 ? v > 0 : v >= 0);
      if (!ok) {
        snprintf(msg, sizeof msg, "\"%s\"[%d] %s", keys[a], i,
                 a == 0 ? "must be a wavelength in nm (100 to 20000), increasing" : a == 1 ? "must be a number > 0" : "must be a number >= 0");
        return bad(c, where, msg);
      }
      dst[a][i] = (float)v;
    }
  }
  nk_curve *q = realloc(c->s->nk, (c->s->nnk + 1) * sizeof *q);
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

static valo_status parse_material(jctx *c, const cJSON *o, const char *name, material *m) {
  char where[256];
  snprintf(where, sizeof where, "materials.%s", name);
  if (!cJSON_IsObject(o)) return bad(c, where, "must be an object");
  const char *type = NULL;
  TRY(get_str(c, o, "type", where, &type));
  if (!type) return bad(c, where, "needs a \"type\" (diffuse, phong, mirror, dielectric, conductor, pbr)");
  *m = material_default();
  snprintf(m->name, sizeof m->name, "%s", name);
  static const char *const k_diffuse[] = {"type", "reflectance", "normal_map", "emission", "two_sided", "bump_map", "bump_scale", NULL};
  static const char *const k_phong[] = {"type", "diffuse", "specular", "exponent", "normal_map", "emission", "two_sided", "bump_map", "bump_scale", NULL};
  static const char *const k_mirror[] = {"type", "reflectance", "diffuse", "normal_map", "emission", "two_sided", "bump_map", "bump_scale", NULL};
  static const char *const k_dielectric[] = {"type", "ior", "dispersion", "roughness", "normal_map", "emission", "two_sided", "bump_map", "bump_scale", NULL};
  static const char *const k_conductor[] = {"type", "preset", "eta", "k", "spectrum", "roughness", "normal_map", "emission", "two_sided", "bump_map", "bump_scale", NULL};
  static const char *const k_pbr[] = {"type", "base_color", "metallic", "roughness", "metallic_roughness_map", "normal_map", "emission",
                                      "two_sided", "bump_map", "bump_scale", NULL};
  if (!strcmp(type, "pbr")) {
    TRY(check_keys(c, o, where, k_pbr));
    m->type = MAT_PBR;
    m->roughness = 0.5f;
    TRY(get_rgb_tex(c, o, "base_color", where, &m->kd, &m->tex_kd));
    double metal = 0;
    TRY(get_num(c, o, "metallic", where, 0, 1, &metal));
    m->metallic = (float)metal;
    TRY(get_data_map(c, o, "metallic_roughness_map", where, "metallic-roughness map", &m->tex_mr));
  } else if (!strcmp(type, "diffuse")) {
    TRY(check_keys(c, o, where, k_diffuse));
    m->type = MAT_DIFFUSE;
    TRY(get_rgb_tex(c, o, "reflectance", where, &m->kd, &m->tex_kd));
  } else if (!strcmp(type, "phong")) {
    TRY(check_keys(c, o, where, k_phong));
    m->type = MAT_PHONG;
    m->kd = c3(0.5f, 0.5f, 0.5f); m->ks = c3(0.2f, 0.2f, 0.2f); m->exponent = 20;
    TRY(get_rgb_tex(c, o, "diffuse", where, &m->kd, &m->tex_kd));
    TRY(get_rgb_tex(c, o, "specular", where, &m->ks, &m->tex_ks));
    double e = m->exponent;
    TRY(get_num(c, o, "exponent", where, 0, 1e6, &e));
    m->exponent = (float)e;
  } else if (!strcmp(type, "mirror")) {
    TRY(check_keys(c, o, where, k_mirror));
    m->type = MAT_MIRROR;
    m->kd = c3(0, 0, 0); m->ks = c3(1, 1, 1);
    TRY(get_rgb(c, o, "reflectance", where, &m->ks));
    TRY(get_rgb(c, o, "diffuse", where, &m->kd));
  } else if (!strcmp(type, "dielectric")) {
    TRY(check_keys(c, o, where, k_dielectric));
    m->type = MAT_DIELECTRIC;
    double ior = 1.5;
    TRY(get_num(c, o, "ior", where, 1.0, 10.0, &ior));
    m->ior = (float)ior;
    const char *disp = NULL;
    TRY(get_str(c, o, "dispersion", where, &disp));
    if (disp) {
      dispersion d;
      if (dispersion_parse(disp, &d)) return bad(c, where, "unknown dispersion (fused_silica, sapphire, water, cauchy_glass, dense_flint)");
      m->dispersion = (int)d;
      m->ior = dispersion_ior(d, 589.3f); /* RGB mode renders at the sodium d line */
    }
  } else if (!strcmp(type, "conductor")) {
    TRY(check_keys(c, o, where, k_conductor));
    m->type = MAT_CONDUCTOR;
    const char *preset = NULL;
    TRY(get_str(c, o, "preset", where, &preset));
    if (cJSON_GetObjectItemCaseSensitive(o, "spectrum")) {
      if (preset || cJSON_GetObjectItemCaseSensitive(o, "eta") || cJSON_GetObjectItemCaseSensitive(o, "k"))
        return bad(c, where, "give either \"spectrum\" or \"preset\" / \"eta\" and \"k\", not both");
      TRY(parse_nk_spectrum(c, cJSON_GetObjectItemCaseSensitive(o, "spectrum"), where, m));
    } else if (preset) {
      if (conductor_preset(preset, &m->eta, &m->k)) return bad(c, where, "unknown conductor preset (Au, Ag, Cu, Al)");
    } else {
      if (!cJSON_GetObjectItemCaseSensitive(o, "eta") || !cJSON_GetObjectItemCaseSensitive(o, "k"))
        return bad(c, where, "a conductor needs \"preset\" or both \"eta\" and \"k\"");
    }
    TRY(get_rgb(c, o, "eta", where, &m->eta));
    TRY(get_rgb(c, o, "k", where, &m->k));
  } else {
    return bad(c, where, "unknown material type (diffuse, phong, mirror, dielectric, conductor, pbr)");
  }
  TRY(get_data_map(c, o, "normal_map", where, "normal map", &m->tex_normal));
  TRY(get_data_map(c, o, "bump_map", where, "bump (height) map", &m->tex_bump));
  double bscale = 1;
  TRY(get_num(c, o, "bump_scale", where, -1e6, 1e6, &bscale));
  m->bump_scale = (float)bscale;
  double rough = m->roughness;
  TRY(get_num(c, o, "roughness", where, 0, 1, &rough));
  m->roughness = (float)rough;
  TRY(get_rgb_tex(c, o, "emission", where, &m->emission, &m->tex_ke));
  TRY(get_bool(c, o, "two_sided", where, &m->two_sided));
  return VALO_OK;
}

static valo_status parse_transform(jctx *c, const cJSON *o, const char *where, float xf[12]) {
  static const char *const keys[] = {"scale", "rotate_x", "rotate_y", "rotate_z", "translate", NULL};
  TRY(check_keys(c, o, where, keys));
  vec3 sc = v3(1, 1, 1), tr = v3(0, 0, 0);
  TRY(get_vec(c, o, "scale", where, 1, &sc));
  TRY(get_vec(c, o, "translate", where, 0, &tr));
  double ang[3] = {0, 0, 0};
  TRY(get_num(c, o, "rotate_x", where, -1e6, 1e6, &ang[0]));
  TRY(get_num(c, o, "rotate_y", where, -1e6, 1e6, &ang[1]));
  TRY(get_num(c, o, "rotate_z", where, -1e6, 1e6, &ang[2]));
  if (sc.x == 0 || sc.y == 0 || sc.z == 0) return bad(c, where, "scale must not be zero");
  /* M = T * Rz * Ry * Rx * S (scale first, then x, y, z rotations, then translation). */
  double m[3][3] = {{sc.x, 0, 0}, {0, sc.y, 0}, {0, 0, sc.z}};
  for (int axis = 0; axis < 3; axis++) {
    double a = ang[axis] * M_PI / 180.0, cs = cos(a), sn = sin(a), r[3][3];
    if (axis == 0) { double t[3][3] = {{1, 0, 0}, {0, cs, -sn}, {0, sn, cs}}; memcpy(r, t, sizeof r); }
    else if (axis == 1) { double t[3][3] = {{cs, 0, sn}, {0, 1, 0}, {-sn, 0, cs}}; memcpy(r, t, sizeof r); }
    else { double t[3][3] = {{cs, -sn, 0}, {sn, cs, 0}, {0, 0, 1}}; memcpy(r, t, sizeof r); }
    double n[3][3];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) n[i][j] = r[i][0] * m[0][j] + r[i][1] * m[1][j] + r[i][2] * m[2][j];
    memcpy(m, n, sizeof m);
  }
  for (int i = 0; i < 3; i++) {
    for (int j = 0; j < 3; j++) xf[4 * i + j] = (float)m[i][j];
    xf[4 * i + 3] = v3_get(tr, i);
  }
  return VALO_OK;
}

static uint32_t find_material(const scene *s, const char *name, uint32_t first_named, uint32_t end_named) {
  for (uint32_t i = first_named; i < end_named; i++)
    if (!strcmp(s->mats[i].name, name)) return i;
  return UINT32_MAX;
}

static void resolve_path(const jctx *c, const char *rel, char *out, size_t n) {
  if (rel[0] == '/' || !c->dir[0]) snprintf(out, n, "%s", rel);
  else snprintf(out, n, "%s/%s", c->dir, rel);
}

static valo_status parse_shape_geometry(jctx *c, const cJSON *o, const char *where, uint32_t mfirst, uint32_t mend);
static valo_status parse_shape(jctx *c, const cJSON *o, int index, uint32_t mfirst, uint32_t mend) {
  char where[64];
  snprintf(where, sizeof where, "shapes[%d]", index);
  static const char *const keys[] = {"type", "file", "transform", "material", "center", "radius", "subdivisions", "flip_normals", "smooth",
                                     "proximity", NULL};
  TRY(check_keys(c, o, where, keys));
  uint32_t first = c->s->ntris;
  valo_status st = parse_shape_geometry(c, o, where, mfirst, mend);
  if (st) return st;
  const cJSON *px = cJSON_GetObjectItemCaseSensitive(o, "proximity");
  if (!px) return VALO_OK;
  char w2[96];
  snprintf(w2, sizeof w2, "%s.proximity", where);
  if (!cJSON_IsObject(px)) return bad(c, w2, "must be an object with spacing, radius, strength");
  static const char *const pkeys[] = {"spacing", "radius", "strength", NULL};
  TRY(check_keys(c, px, w2, pkeys));
  double sp = -1, rad = -1, m = -1; /* -1: not given, the integrator's parameter applies */
  TRY(get_num(c, px, "spacing", w2, 1e-9, 1e9, &sp));
  TRY(get_num(c, px, "radius", w2, 1e-9, 1e9, &rad));
  TRY(get_num(c, px, "strength", w2, 0, 1e9, &m));
  shape_ao *na = realloc(c->s->shape_ao, (c->s->nshape_ao + 1) * sizeof *na);
  if (!na) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  c->s->shape_ao = na;
  shape_ao sa = {first, c->s->ntris, (float)sp, (float)rad, (float)m};
  na[c->s->nshape_ao++] = sa;
  return VALO_OK;
}

static valo_status parse_shape_geometry(jctx *c, const cJSON *o, const char *where, uint32_t mfirst, uint32_t mend) {
  const char *type = "mesh", *file = NULL, *mname = NULL;
  TRY(get_str(c, o, "type", where, &type));
  TRY(get_str(c, o, "file", where, &file));
  TRY(get_str(c, o, "material", where, &mname));
  uint32_t mat = UINT32_MAX;
  if (mname) {
    mat = find_material(c->s, mname, mfirst, mend);
    if (mat == UINT32_MAX) {
      char msg[200];
      snprintf(msg, sizeof msg, "material \"%.100s\" is not defined in \"materials\"", mname);
      return bad(c, where, msg);
    }
  }
  if (!strcmp(type, "mesh")) {
    if (!file) return bad(c, where, "a mesh shape needs \"file\"");
    float xf[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(o, "transform");
    if (t) {
      char w2[80];
      snprintf(w2, sizeof w2, "%s.transform", where);
      TRY(parse_transform(c, t, w2, xf));
    }
    char full[2048];
    resolve_path(c, file, full, sizeof full);
    return load_mesh(c->s, full, xf, mat, c->cam_from_file && !c->s->has_camera, c->err);
  }
  if (!strcmp(type, "sphere")) {
    vec3 center = v3(0, 0, 0);
    double r = 1;
    int sub = 4, flip = 0, smooth = 1;
    TRY(get_bool(c, o, "smooth", where, &smooth));
    TRY(get_vec(c, o, "center", where, 0, &center));
    TRY(get_num(c, o, "radius", where, 1e-9, 1e9, &r));
    TRY(get_int(c, o, "subdivisions", where, 0, 7, &sub));
    TRY(get_bool(c, o, "flip_normals", where, &flip));
    if (mat == UINT32_MAX) {
      material d = material_default();
      mat = scene_add_material(c->s, &d);
      if (mat == UINT32_MAX) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    }
    if (material_has_maps(&c->s->mats[mat]))
      log_warning("%s: %s: a sphere has no texture coordinates, so the maps of material '%s' are ignored", c->s->path, where, c->s->mats[mat].name);
    return scene_add_sphere(c->s, center, (float)r, sub, flip, smooth, mat, c->err);
  }
  return bad(c, where, "unknown shape type (mesh, sphere)");
}

static valo_status parse_light(jctx *c, const cJSON *o, int index) {
  char where[64];
  snprintf(where, sizeof where, "lights[%d]", index);
  if (!cJSON_IsObject(o)) return bad(c, where, "must be an object");
  const char *type = NULL;
  TRY(get_str(c, o, "type", where, &type));
  if (!type) return bad(c, where, "needs a \"type\" (point, spot, directional)");
  light l;
  memset(&l, 0, sizeof l);
  l.L = c3(1, 1, 1);
  if (!strcmp(type, "point")) {
    static const char *const keys[] = {"type", "position", "intensity", NULL};
    TRY(check_keys(c, o, where, keys));
    l.type = LIGHT_POINT;
    TRY(get_vec(c, o, "position", where, 0, &l.p));
    TRY(get_rgb(c, o, "intensity", where, &l.L));
  } else if (!strcmp(type, "spot")) {
    static const char *const keys[] = {"type", "position", "look_at", "intensity", "cone_angle", "cone_delta_angle", NULL};
    TRY(check_keys(c, o, where, keys));
    l.type = LIGHT_SPOT;
    vec3 at = v3(0, 0, 0);
    double cone = 30, delta = 5;
    TRY(get_vec(c, o, "position", where, 0, &l.p));
    TRY(get_vec(c, o, "look_at", where, 0, &at));
    TRY(get_rgb(c, o, "intensity", where, &l.L));
    TRY(get_num(c, o, "cone_angle", where, 0.01, 180, &cone));
    TRY(get_num(c, o, "cone_delta_angle", where, 0, 180, &delta));
    if (delta > cone) delta = cone;
    if (!(v3_len2(v3_sub(at, l.p)) > 0)) return bad(c, where, "position and look_at must differ");
    l.dir = v3_norm(v3_sub(at, l.p));
    l.cos_outer = cosf((float)(cone * M_PI / 180));
    l.cos_inner = cosf((float)((cone - delta) * M_PI / 180));
  } else if (!strcmp(type, "directional")) {
    static const char *const keys[] = {"type", "direction", "irradiance", NULL};
    TRY(check_keys(c, o, where, keys));
    l.type = LIGHT_DIRECTIONAL;
    l.dir = v3(0, -1, 0);
    TRY(get_vec(c, o, "direction", where, 0, &l.dir));
    TRY(get_rgb(c, o, "irradiance", where, &l.L));
    if (!(v3_len2(l.dir) > 0)) return bad(c, where, "direction must not be zero");
    l.dir = v3_norm(l.dir);
  } else {
    return bad(c, where, "unknown light type (point, spot, directional)");
  }
  if (scene_add_light(c->s, &l)) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  return VALO_OK;
}

static void line_col(const char *text, const char *at, int *line, int *col) {
  *line = 1; *col = 1;
  for (const char *p = text; p < at && *p; p++) {
    if (*p == '\n') { (*line)++; *col = 1; } else (*col)++;
  }
}

valo_status load_json(scene *s, const char *path, valo_error *err) {
  jctx c = {.s = s, .path = path, .err = err};
  const char *slash = strrchr(path, '/');
  if (slash) snprintf(c.dir, sizeof c.dir, "%.*s", (int)(slash - path), path);
  FILE *f = fopen(path, "rb");
  if (!f) return err_set(err, VALO_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
  char *text = NULL;
  size_t len = 0, cap = 0;
  for (;;) {
    if (len + 4096 + 1 > cap) {
      cap = cap ? cap * 2 : 65536;
      if (cap > (64u << 20)) { fclose(f); free(text); return err_set(err, VALO_ERR_INVALID, "%s: scene file larger than 64 MiB", path); }
      char *t = realloc(text, cap);
      if (!t) { fclose(f); free(text); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
      text = t;
    }
    size_t n = fread(text + len, 1, 4096, f);
    len += n;
    if (n < 4096) break;
  }
  int rerr = ferror(f);
  fclose(f);
  if (rerr) { free(text); return err_set(err, VALO_ERR_IO, "%s: read error", path); }
  text[len] = 0;
  if (strlen(text) != len) { free(text); return err_set(err, VALO_ERR_PARSE, "%s: contains a NUL byte: not a JSON text file", path); }
  const char *end = NULL;
  cJSON *root = cJSON_ParseWithOpts(text, &end, 1);
  if (!root) {
    int line, col;
    const char *at = end ? end : cJSON_GetErrorPtr();
    if (!at) at = text + len;
    line_col(text, at, &line, &col);
    free(text);
    return err_set(err, VALO_ERR_PARSE, "%s:%d:%d: JSON syntax error", path, line, col);
  }
  free(text);
  valo_status st = VALO_OK;
  static const char *const keys[] = {"camera", "film", "render", "shapes", "materials", "lights", "environment", NULL};
#undef TRY
#define TRY(x) do { st = (x); if (st) goto done; } while (0)
  TRY(check_keys(&c, root, "(top level)", keys));
  const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
  if (cam) TRY(parse_camera(&c, cam));
  const cJSON *film = cJSON_GetObjectItemCaseSensitive(root, "film");
  if (film) {
    static const char *const fk[] = {"width", "height", NULL};
    TRY(check_keys(&c, film, "film", fk));
    TRY(get_int(&c, film, "width", "film", 1, 16384, &s->file_opts.width));
    TRY(get_int(&c, film, "height", "film", 1, 16384, &s->file_opts.height));
  }
  const cJSON *render = cJSON_GetObjectItemCaseSensitive(root, "render");
  if (render) TRY(parse_render(&c, render));
  uint32_t mfirst = s->nmats;
  const cJSON *mats = cJSON_GetObjectItemCaseSensitive(root, "materials");
  if (mats) {
    if (!cJSON_IsObject(mats)) { st = bad(&c, "materials", "must be an object of named materials"); goto done; }
    for (const cJSON *m = mats->child; m; m = m->next) {
      material mm;
      TRY(parse_material(&c, m, m->string, &mm));
      if (scene_add_material(s, &mm) == UINT32_MAX) { st = err_set(err, VALO_ERR_NOMEM, "out of memory"); goto done; }
    }
  }
  uint32_t mend = s->nmats;
  const cJSON *shapes = cJSON_GetObjectItemCaseSensitive(root, "shapes");
  if (shapes) {
    if (!cJSON_IsArray(shapes)) { st = bad(&c, "shapes", "must be an array"); goto done; }
    int i = 0;
    for (const cJSON *sh = shapes->child; sh; sh = sh->next, i++) TRY(parse_shape(&c, sh, i, mfirst, mend));
  }
  if (c.cam_from_file) {
    if (!s->has_camera) { st = bad(&c, "camera.from_file", "no shape file has a camera"); goto done; }
    if (c.cam_fov > 0) s->cam.fov_deg = c.cam_fov;
    s->cam.aperture_radius = c.cam_aperture;
    s->cam.focus_distance = c.cam_focus; /* <= 0: autofocus */
  }
  const cJSON *lights = cJSON_GetObjectItemCaseSensitive(root, "lights");
  if (lights) {
    if (!cJSON_IsArray(lights)) { st = bad(&c, "lights", "must be an array"); goto done; }
    int i = 0;
    for (const cJSON *l = lights->child; l; l = l->next, i++) TRY(parse_light(&c, l, i));
  }
  const cJSON *env = cJSON_GetObjectItemCaseSensitive(root, "environment");
  if (env) {
    const char *type = "constant";
    TRY(get_str(&c, env, "type", "environment", &type));
    if (!strcmp(type, "constant")) {
      static const char *const ek[] = {"type", "radiance", NULL};
      TRY(check_keys(&c, env, "environment", ek));
      s->env_radiance = c3(1, 1, 1);
      TRY(get_rgb(&c, env, "radiance", "environment", &s->env_radiance));
    } else if (!strcmp(type, "map")) {
      static const char *const ek[] = {"type", "file", "scale", "rotation", NULL};
      TRY(check_keys(&c, env, "environment", ek));
      const char *file = NULL;
      double scale = 1, rot = 0;
      TRY(get_str(&c, env, "file", "environment", &file));
      if (!file) { st = bad(&c, "environment", "a map needs \"file\" (an equirectangular .exr, .hdr or .pfm)"); goto done; }
      TRY(get_num(&c, env, "scale", "environment", 0, 1e9, &scale));
      TRY(get_num(&c, env, "rotation", "environment", -1e6, 1e6, &rot));
      char full[2048];
      resolve_path(&c, file, full, sizeof full);
      s->env_map = calloc(1, sizeof *s->env_map);
      if (!s->env_map) { st = err_set(err, VALO_ERR_NOMEM, "out of memory"); goto done; }
      TRY(envmap_load(s->env_map, full, (float)scale, (float)rot, err));
    } else if (!strcmp(type, "cube")) {
      static const char *const ek[] = {"type", "faces", "scale", "rotation", NULL};
      TRY(check_keys(&c, env, "environment", ek));
      const cJSON *faces = cJSON_GetObjectItemCaseSensitive(env, "faces");
      if (!cJSON_IsArray(faces) || cJSON_GetArraySize(faces) != 6) {
        st = bad(&c, "environment.faces", "must be an array of six image files: +x, -x, +y, -y, +z, -z");
        goto done;
      }
      char full[6][2048];
      const char *paths[6];
      int i = 0;
      for (const cJSON *fe = faces->child; fe; fe = fe->next, i++) {
        if (!cJSON_IsString(fe)) { st = bad(&c, "environment.faces", "must hold file names (strings)"); goto done; }
        resolve_path(&c, fe->valuestring, full[i], sizeof full[i]);
        paths[i] = full[i];
      }
      double scale = 1, rot = 0;
      TRY(get_num(&c, env, "scale", "environment", 0, 1e9, &scale));
      TRY(get_num(&c, env, "rotation", "environment", -1e6, 1e6, &rot));
      s->env_map = calloc(1, sizeof *s->env_map);
      if (!s->env_map) { st = err_set(err, VALO_ERR_NOMEM, "out of memory"); goto done; }
      TRY(envmap_load_cube(s->env_map, paths, (float)scale, (float)rot, err));
    } else {
      st = bad(&c, "environment.type", "unknown environment type (constant, map, cube)");
      goto done;
    }
    s->has_env = 1;
  }
done:
  cJSON_Delete(root);
  return st;
}
