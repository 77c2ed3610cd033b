/* load_json.c — owns the JSON scene format (docs/scene-format.md): camera, film, render
 * settings, shapes (mesh files and spheres) with transforms, named materials, lights
 * and the environment. Strict: unknown keys and wrong types are errors that name the
 * file and the JSON path; syntax errors give line:column. */
#include "load/load_json_internal.h"
#include "core/error.h"
#include "core/spectrum.h"
#include "core/options.h"
#include "core/strutil.h"
#include "load/serialized.h"
#include "core/strmap.h"
#include "core/grow.h"
#include <cjson/cJSON.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A view is usable: position and look_at differ, up is not along the view direction. */
static valo_status check_view(jctx *c, const char *where, vec3 pos, vec3 look_at, vec3 up) {
  vec3 fwd = v3_sub(look_at, pos);
  if (!(v3_len2(fwd) > 0)) return json_bad(c, where, "position and look_at must differ");
  char w[96];
  snprintf(w, sizeof w, "%s.up", where);
  if (!(v3_len2(v3_cross(v3_norm(fwd), v3_norm(up))) > 1e-12f)) return json_bad(c, w, "must not be parallel to the view direction");
  return VALO_OK;
}

/* The camera's field of view or height, whichever its kind takes (a spherical camera
 * neither): another is an error naming what the kind takes. */
static valo_status get_view_size(jctx *c, const cJSON *o, const char *where, const camera *kind, float *fov_deg, float *height) {
  int ortho = kind->ortho_height > 0;
  for (int k = 0; k < 2; k++) {
    const char *key = k ? "height" : "fov";
    if (!cJSON_GetObjectItemCaseSensitive(o, key) || (!kind->spherical && ortho == k)) continue;
    char w[96];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return json_bad(c, w, kind->spherical ? "a spherical camera sees every direction: it has no field of view or height"
                          : ortho         ? "an orthographic camera has no field of view; give its \"height\" in scene units"
                                          : "\"height\" is an orthographic camera's; a perspective camera takes \"fov\" (or give \"type\": \"orthographic\")");
  }
  if (kind->spherical) return VALO_OK;
  double d = ortho ? *height : *fov_deg;
  if (ortho) { TRY(json_get_num(c, o, "height", where, 1e-6, 1e9, &d)); *height = (float)d; }
  else { TRY(json_get_num(c, o, "fov", where, 1e-3, 179.9, &d)); *fov_deg = (float)d; }
  return VALO_OK;
}

/* camera.keyframes: [{"frame": F, "position", "look_at", "up", "fov" or "height"}, ...],
 * frames increasing; a key's missing fields take the camera's. */
static valo_status parse_keyframes(jctx *c, const cJSON *a, const camera *cam) {
  if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) < 1) return json_bad(c, "camera.keyframes", "must be a non-empty array of objects");
  int n = cJSON_GetArraySize(a);
  if (n > 100000) return json_bad(c, "camera.keyframes", "more than 100000 keyframes");
  cam_key *k = calloc((size_t)n, sizeof *k);
  if (!k) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  c->s->cam_keys = k;
  c->s->ncam_keys = (uint32_t)n;
  static const char *const keys[] = {"frame", "position", "look_at", "up", "fov", "height", NULL};
  int i = 0;
  for (const cJSON *e = a->child; e; e = e->next, i++) {
    char where[64];
    snprintf(where, sizeof where, "camera.keyframes[%d]", i);
    TRY(json_check_keys(c, e, where, keys));
    if (!cJSON_GetObjectItemCaseSensitive(e, "frame")) return json_bad(c, where, "needs \"frame\"");
    double d = 0;
    TRY(json_get_num(c, e, "frame", where, -1e9, 1e9, &d));
    k[i].frame = (float)d;
    if (i > 0 && !(k[i].frame > k[i - 1].frame)) return json_bad(c, where, "frames must increase from key to key");
    k[i].pos = cam->pos; k[i].look_at = cam->look_at; k[i].up = cam->up;
    k[i].fov_deg = cam->fov_deg; k[i].ortho_height = cam->ortho_height;
    TRY(json_get_vec(c, e, "position", where, 0, &k[i].pos));
    TRY(json_get_vec(c, e, "look_at", where, 0, &k[i].look_at));
    TRY(json_get_vec(c, e, "up", where, 0, &k[i].up));
    TRY(get_view_size(c, e, where, cam, &k[i].fov_deg, &k[i].ortho_height));
    TRY(check_view(c, where, k[i].pos, k[i].look_at, k[i].up));
  }
  return VALO_OK;
}

static valo_status parse_camera(jctx *c, const cJSON *o) {
  static const char *const keys[] = {"type", "position", "look_at", "up", "fov", "height", "aperture_radius", "focus_distance",
                                     "from_file", "keyframes", "medium", NULL};
  TRY(json_check_keys(c, o, "camera", keys));
  TRY(json_get_medium(c, o, "medium", "camera", &c->s->cam_medium));
  camera *cam = &c->s->cam;
  const cJSON *ff = cJSON_GetObjectItemCaseSensitive(o, "from_file");
  if (ff && !cJSON_IsBool(ff)) return json_bad(c, "camera.from_file", "must be true or false");
  if (cJSON_IsTrue(ff)) {
    /* The first shape file with a camera supplies its type, position, orientation and fov
     * (or height); the lens (and optionally fov or height) come from here. */
    if (cJSON_GetObjectItemCaseSensitive(o, "position") || cJSON_GetObjectItemCaseSensitive(o, "look_at") ||
        cJSON_GetObjectItemCaseSensitive(o, "up") || cJSON_GetObjectItemCaseSensitive(o, "type"))
      return json_bad(c, "camera", "\"from_file\" takes the type, position, look_at and up from the file; give only fov (or an "
                                   "orthographic camera's height), aperture_radius, focus_distance");
    double d = -1;
    TRY(json_get_num(c, o, "fov", "camera", 1e-3, 179.9, &d)); c->cam_fov = (float)d;
    d = -1; TRY(json_get_num(c, o, "height", "camera", 1e-6, 1e9, &d)); c->cam_height = (float)d;
    d = 0; TRY(json_get_num(c, o, "aperture_radius", "camera", 0, 1e6, &d)); c->cam_aperture = (float)d;
    d = -1; TRY(json_get_num(c, o, "focus_distance", "camera", 1e-6, 1e9, &d)); c->cam_focus = (float)d;
    c->cam_from_file = 1;
    return VALO_OK;
  }
  cam->pos = v3(0, 0, 5); cam->look_at = v3(0, 0, 0); cam->up = v3(0, 1, 0);
  cam->fov_deg = 40; cam->ortho_height = 0; cam->spherical = 0; cam->aperture_radius = 0; cam->focus_distance = -1;
  const char *type = "perspective";
  TRY(json_get_str(c, o, "type", "camera", &type));
  int ortho = !strcmp(type, "orthographic");
  cam->spherical = !strcmp(type, "spherical");
  if (!ortho && !cam->spherical && strcmp(type, "perspective"))
    return json_bad(c, "camera.type", "must be \"perspective\", \"orthographic\" or \"spherical\"");
  if (ortho) cam->ortho_height = 2; /* the view from -1 to 1, as pbrt's default screen window */
  if (cam->spherical && cJSON_GetObjectItemCaseSensitive(o, "aperture_radius"))
    return json_bad(c, "camera.aperture_radius", "a spherical camera has no lens");
  double d;
  TRY(json_get_vec(c, o, "position", "camera", 0, &cam->pos));
  TRY(json_get_vec(c, o, "look_at", "camera", 0, &cam->look_at));
  TRY(json_get_vec(c, o, "up", "camera", 0, &cam->up));
  TRY(get_view_size(c, o, "camera", cam, &cam->fov_deg, &cam->ortho_height));
  d = 0; TRY(json_get_num(c, o, "aperture_radius", "camera", 0, 1e6, &d)); cam->aperture_radius = (float)d;
  d = -1; TRY(json_get_num(c, o, "focus_distance", "camera", 1e-6, 1e9, &d)); cam->focus_distance = (float)d;
  TRY(check_view(c, "camera", cam->pos, cam->look_at, cam->up));
  vec3 fwd = v3_sub(cam->look_at, cam->pos);
  if (cam->focus_distance <= 0) cam->focus_distance = v3_len(fwd);
  c->s->has_camera = 1;
  const cJSON *kf = cJSON_GetObjectItemCaseSensitive(o, "keyframes");
  if (kf) TRY(parse_keyframes(c, kf, cam));
  return VALO_OK;
}

/* The keys of `section` ("render", "film") that the declared options table names
 * ("render.spp", ...): each value, a number or a string, is set through the same
 * declaration the command line uses (core/options.h), so ranges and names agree. Objects
 * (an integrator's parameters) are left to the caller. */
static valo_status json_settings(jctx *c, const cJSON *o, const char *section) {
  for (const cJSON *it = o->child; it; it = it->next) {
    if (cJSON_IsObject(it)) continue;
    char key[160];
    snprintf(key, sizeof key, "%s.%s", section, it->string);
    const option_decl *d = option_find_json(key);
    if (!d) {
      char allowed[600] = "";
      size_t n = strlen(section);
      for (const option_decl *e = option_table; e->info.flag || e->info.json; e++)
        if (e->info.json && !strncmp(e->info.json, section, n) && e->info.json[n] == '.') {
          strncat(allowed, " ", sizeof allowed - strlen(allowed) - 1);
          strncat(allowed, e->info.json + n + 1, sizeof allowed - strlen(allowed) - 1);
        }
      char msg[900];
      snprintf(msg, sizeof msg, "unknown key \"%s\" (allowed:%s%s)", it->string, allowed,
               strcmp(section, "render") ? "" : ", or an integrator's name with an object of its parameters");
      return json_bad(c, section, msg);
    }
    char text[256];
    int name = d->type == OPT_NAME || d->type == OPT_CHOICE;
    if (d->type == OPT_FLAG) {
      if (!cJSON_IsBool(it)) return json_bad(c, key, "must be true or false");
      snprintf(text, sizeof text, "%d", cJSON_IsTrue(it) ? 1 : 0);
    } else if (!name && cJSON_IsNumber(it)) snprintf(text, sizeof text, "%.17g", it->valuedouble);
    else if (name && cJSON_IsString(it)) snprintf(text, sizeof text, "%s", it->valuestring);
    else return json_bad(c, key, name ? "must be a string" : "must be a number");
    valo_error e;
    if (option_set(d, text, c->file, NULL, NULL, &e)) return json_bad(c, key, e.message);
  }
  return VALO_OK;
}

static valo_status parse_render(jctx *c, const cJSON *o) {
  valo_options *op = c->file;
  if (!cJSON_IsObject(o)) return json_bad(c, "render", "must be an object");
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
      if (!cJSON_IsNumber(p) && !cJSON_IsBool(p)) return json_bad(c, w2, "must be a number");
      double v = cJSON_IsBool(p) ? (cJSON_IsTrue(p) ? 1 : 0) : p->valuedouble;
      size_t used = strlen(op->params);
      int n = snprintf(op->params + used, sizeof op->params - used, "%s%s.%s=%.17g", used ? " " : "", it->string, p->string, v);
      if (n < 0 || (size_t)n >= sizeof op->params - used) return json_bad(c, w, "too many parameters");
    }
  }
  return json_settings(c, o, "render");
}

/* "matrix": 16 numbers, row-major, the last row 0 0 0 1 (or 12: the first three rows). */
static valo_status parse_matrix(jctx *c, const cJSON *a, const char *where, float xf[12]) {
  char w[96];
  snprintf(w, sizeof w, "%s.matrix", where);
  int n = cJSON_IsArray(a) ? cJSON_GetArraySize(a) : 0;
  if (n != 16 && n != 12) return json_bad(c, w, "must be an array of 16 numbers (a 4x4 matrix, row by row) or 12 (its first three rows)");
  double m[16] = {0};
  int i = 0;
  for (const cJSON *e = a->child; e; e = e->next, i++) {
    if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble)) return json_bad(c, w, "must hold finite numbers");
    m[i] = e->valuedouble;
  }
  if (n == 16 && (m[12] != 0 || m[13] != 0 || m[14] != 0 || m[15] != 1))
    return json_bad(c, w, "the last row must be 0 0 0 1 (no projective transforms)");
  for (i = 0; i < 12; i++) xf[i] = (float)m[i];
  double det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) + m[2] * (m[4] * m[9] - m[5] * m[8]);
  if (!(fabs(det) > 0)) return json_bad(c, w, "is singular (it flattens the shape)");
  return VALO_OK;
}

valo_status json_parse_transform(jctx *c, const cJSON *o, const char *where, float xf[12]) {
  static const char *const keys[] = {"scale", "rotate_x", "rotate_y", "rotate_z", "translate", "matrix", NULL};
  TRY(json_check_keys(c, o, where, keys));
  const cJSON *mx = cJSON_GetObjectItemCaseSensitive(o, "matrix");
  if (mx) {
    if (cJSON_GetArraySize(o) != 1) return json_bad(c, where, "\"matrix\" is the whole transform: give it alone");
    return parse_matrix(c, mx, where, xf);
  }
  vec3 sc = v3(1, 1, 1), tr = v3(0, 0, 0);
  TRY(json_get_vec(c, o, "scale", where, 1, &sc));
  TRY(json_get_vec(c, o, "translate", where, 0, &tr));
  double ang[3] = {0, 0, 0};
  TRY(json_get_num(c, o, "rotate_x", where, -1e6, 1e6, &ang[0]));
  TRY(json_get_num(c, o, "rotate_y", where, -1e6, 1e6, &ang[1]));
  TRY(json_get_num(c, o, "rotate_z", where, -1e6, 1e6, &ang[2]));
  if (sc.x == 0 || sc.y == 0 || sc.z == 0) return json_bad(c, where, "scale must not be zero");
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

/* The material named name in the file's "materials" (the first of that name), or UINT32_MAX. */
static uint32_t find_material(const jctx *c, const char *name) {
  long i = strmap_get(&c->mat_names, name);
  return i < 0 ? UINT32_MAX : (uint32_t)i;
}


static valo_status parse_shape_geometry(jctx *c, const cJSON *o, const char *where);
static valo_status parse_shape(jctx *c, const cJSON *o, int index) {
  char where[64];
  snprintf(where, sizeof where, "shapes[%d]", index);
  static const char *const keys[] = {"type", "file", "transform", "material", "center", "radius", "p0", "p1", "subdivisions", "exact_area", "flip_normals", "smooth",
                                     "proximity", "interior", "exterior", "face_normals", "smooth_normals", "shape_index", "mitsuba_uv", "flip_v", "uv_frame", NULL};
  TRY(json_check_keys(c, o, where, keys));
  uint32_t first = c->s->ntris;
  int32_t inside = MEDIUM_KEEP, outside = MEDIUM_KEEP;
  TRY(json_get_medium(c, o, "interior", where, &inside));
  TRY(json_get_medium(c, o, "exterior", where, &outside));
  valo_status st = parse_shape_geometry(c, o, where);
  if (st) return st;
  if (inside != MEDIUM_KEEP || outside != MEDIUM_KEEP) {
    /* A medium boundary: the side not named is vacuum. */
    if (scene_add_shape_media(c->s, first, inside == MEDIUM_KEEP ? MEDIUM_NONE : inside, outside == MEDIUM_KEEP ? MEDIUM_NONE : outside))
      return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  }
  const cJSON *px = cJSON_GetObjectItemCaseSensitive(o, "proximity");
  if (!px) return VALO_OK;
  char w2[96];
  snprintf(w2, sizeof w2, "%s.proximity", where);
  if (!cJSON_IsObject(px)) return json_bad(c, w2, "must be an object with spacing, radius, strength");
  static const char *const pkeys[] = {"spacing", "radius", "strength", NULL};
  TRY(json_check_keys(c, px, w2, pkeys));
  double sp = -1, rad = -1, m = -1; /* -1: not given, the integrator's parameter applies */
  TRY(json_get_num(c, px, "spacing", w2, 1e-9, 1e9, &sp));
  TRY(json_get_num(c, px, "radius", w2, 1e-9, 1e9, &rad));
  TRY(json_get_num(c, px, "strength", w2, 0, 1e9, &m));
  shape_ao *na = grow_for(c->s->shape_ao, c->s->nshape_ao, sizeof *na);
  if (!na) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  c->s->shape_ao = na;
  shape_ao sa = {first, c->s->ntris, (float)sp, (float)rad, (float)m};
  na[c->s->nshape_ao++] = sa;
  return VALO_OK;
}

/* A shape's "transform" (identity when absent). */
static valo_status shape_transform(jctx *c, const cJSON *o, const char *where, float xf[12]) {
  static const float id[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  memcpy(xf, id, sizeof id);
  const cJSON *t = cJSON_GetObjectItemCaseSensitive(o, "transform");
  if (!t) return VALO_OK;
  char w2[80];
  snprintf(w2, sizeof w2, "%s.transform", where);
  return json_parse_transform(c, t, w2, xf);
}

static valo_status parse_shape_geometry(jctx *c, const cJSON *o, const char *where) {
  const char *type = "mesh", *file = NULL, *mname = NULL;
  TRY(json_get_str(c, o, "type", where, &type));
  TRY(json_get_str(c, o, "file", where, &file));
  TRY(json_get_str(c, o, "material", where, &mname));
  uint32_t mat = UINT32_MAX;
  if (mname) {
    mat = find_material(c, mname);
    if (mat == UINT32_MAX) {
      char msg[200];
      snprintf(msg, sizeof msg, "material \"%.100s\" is not defined in \"materials\"", mname);
      return json_bad(c, where, msg);
    }
  }
  /* Keys another kind of shape takes are errors, not silently ignored. */
  int mesh = !strcmp(type, "mesh"), sphere = !strcmp(type, "sphere");
  static const char *const sphere_only[] = {"center", "radius", "subdivisions", "exact_area", "smooth", NULL};
  for (int j = 0; (mesh || sphere) && sphere_only[j]; j++)
    if (mesh && cJSON_GetObjectItemCaseSensitive(o, sphere_only[j])) {
      char msg[160];
      snprintf(msg, sizeof msg, "\"%s\" is a sphere's; a mesh is placed by \"transform\"", sphere_only[j]);
      return json_bad(c, where, msg);
    }
  if (mesh && cJSON_GetObjectItemCaseSensitive(o, "flip_normals")) return json_bad(c, where, "\"flip_normals\" is not read for a mesh (its file's winding sets its front side)");
  if (!mesh && cJSON_GetObjectItemCaseSensitive(o, "face_normals")) return json_bad(c, where, "\"face_normals\" is a mesh's");
  if (!mesh && cJSON_GetObjectItemCaseSensitive(o, "shape_index")) return json_bad(c, where, "\"shape_index\" is a mesh's");
  if (!mesh && cJSON_GetObjectItemCaseSensitive(o, "smooth_normals")) return json_bad(c, where, "\"smooth_normals\" is a mesh's");
  if (mesh && cJSON_GetObjectItemCaseSensitive(o, "mitsuba_uv")) return json_bad(c, where, "\"mitsuba_uv\" is a sphere's, rectangle's, cube's, disk's or cylinder's");
  if (!sphere && cJSON_GetObjectItemCaseSensitive(o, "uv_frame")) return json_bad(c, where, "\"uv_frame\" is a sphere's");
  if (strcmp(type, "cylinder") && (cJSON_GetObjectItemCaseSensitive(o, "p0") || cJSON_GetObjectItemCaseSensitive(o, "p1")))
    return json_bad(c, where, "\"p0\" and \"p1\" are a cylinder's");
  if (!mesh && cJSON_GetObjectItemCaseSensitive(o, "flip_v")) return json_bad(c, where, "\"flip_v\" is a mesh file's");
  if (sphere && (cJSON_GetObjectItemCaseSensitive(o, "transform") || cJSON_GetObjectItemCaseSensitive(o, "file")))
    return json_bad(c, where, "a sphere is placed by \"center\" and \"radius\" (no \"transform\" or \"file\")");
  if (mesh) {
    if (!file) return json_bad(c, where, "a mesh shape needs \"file\"");
    float xf[12];
    TRY(shape_transform(c, o, where, xf));
    char full[2048];
    json_resolve_path(c, file, full, sizeof full);
    int flat = 0, smooth = 0, flip_v = 0;
    TRY(json_get_bool(c, o, "face_normals", where, &flat));
    TRY(json_get_bool(c, o, "smooth_normals", where, &smooth));
    TRY(json_get_bool(c, o, "flip_v", where, &flip_v));
    int mflags = (flat ? LOAD_MESH_FLAT : 0) | (smooth ? LOAD_MESH_SMOOTH : 0);
    int index = -1;
    TRY(json_get_int(c, o, "shape_index", where, 0, INT_MAX, &index));
    if (flip_v && str_ends_with(full, ".serialized"))
      return json_bad(c, where, "\"flip_v\" is not read for a .serialized file (its v is turned up as it is read)");
    mflags |= flip_v ? LOAD_MESH_FLIP_V : 0;
    if (str_ends_with(full, ".serialized")) return load_serialized(c->s, full, index < 0 ? 0 : index, xf, mat, mflags, c->err);
    if (index >= 0) return json_bad(c, where, "\"shape_index\" picks a shape of a Mitsuba .serialized file");
    int flags = (c->cam_from_file && !c->s->has_camera ? LOAD_MESH_CAMERA : 0) | mflags;
    return load_mesh_cached(c->s, full, xf, mat, flags, c->file, &c->meshes, c->err);
  }
  if (!strcmp(type, "sphere")) {
    vec3 center = v3(0, 0, 0);
    double r = 1;
    int sub = 4, flip = 0, smooth = 1;
    TRY(json_get_bool(c, o, "smooth", where, &smooth));
    TRY(json_get_vec(c, o, "center", where, 0, &center));
    TRY(json_get_num(c, o, "radius", where, 1e-9, 1e9, &r));
    TRY(json_get_int(c, o, "subdivisions", where, 0, 7, &sub));
    TRY(json_get_bool(c, o, "flip_normals", where, &flip));
    if (mat == UINT32_MAX) {
      material d = material_default();
      mat = scene_add_material(c->s, &d);
      if (mat == UINT32_MAX) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    }
    int mitsuba_uv = 0;
    TRY(json_get_bool(c, o, "mitsuba_uv", where, &mitsuba_uv));
    float rot[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    const cJSON *fr = cJSON_GetObjectItemCaseSensitive(o, "uv_frame");
    if (fr) {
      if (!mitsuba_uv) return json_bad(c, where, "\"uv_frame\" turns Mitsuba's layout (\"mitsuba_uv\": true)");
      int n = 0;
      for (const cJSON *e = cJSON_IsArray(fr) ? fr->child : NULL; e; e = e->next, n++)
        if (n < 9) rot[n] = cJSON_IsNumber(e) ? (float)e->valuedouble : NAN;
      double off = 0; /* rot^T rot - I */
      for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
          off += fabs((double)rot[a] * rot[b] + (double)rot[3 + a] * rot[3 + b] + (double)rot[6 + a] * rot[6 + b] - (a == b));
      if (n != 9 || !(off < 1e-3)) return json_bad(c, where, "\"uv_frame\" must be 9 numbers, a 3x3 rotation (row-major, local to world)");
    }
    int exact_area = 0;
    TRY(json_get_bool(c, o, "exact_area", where, &exact_area));
    TRY(scene_add_sphere(c->s, center, (float)r, sub, flip, smooth, mat, c->err));
    if (exact_area) scene_sphere_exact_area(c->s, c->s->nspheres - 1);
    return mitsuba_uv ? scene_sphere_uv(c->s, c->s->nspheres - 1, rot) : VALO_OK;
  }
  static const char *const prims[] = {"rectangle", "cube", "disk", "cylinder"};
  for (int k = 0; k < 4; k++) {
    if (strcmp(type, prims[k])) continue;
    float xf[12];
    TRY(shape_transform(c, o, where, xf));
    int flip = 0, mitsuba_uv = 0, cyl = k == PRIM_CYLINDER;
    TRY(json_get_bool(c, o, "flip_normals", where, &flip));
    TRY(json_get_bool(c, o, "mitsuba_uv", where, &mitsuba_uv));
    if (cyl) { /* the unit cylinder from p0 to p1 of radius r, then the transform (Mitsuba's order) */
      vec3 p0 = v3(0, 0, 0), p1 = v3(0, 0, 1);
      double r = 1;
      TRY(json_get_vec(c, o, "p0", where, 0, &p0));
      TRY(json_get_vec(c, o, "p1", where, 0, &p1));
      TRY(json_get_num(c, o, "radius", where, 1e-9, 1e9, &r));
      if (!(v3_len(v3_sub(p1, p0)) > 0)) return json_bad(c, where, "a cylinder's p0 and p1 must differ");
      scene_cylinder_place(p0, p1, (float)r, xf);
    }
    static const char *const own[] = {"center", "radius", "subdivisions", "smooth", "exact_area", "file", "p0", "p1"};
    for (int j = 0; j < 8; j++)
      if (!(cyl && (j == 1 || j > 5)) && cJSON_GetObjectItemCaseSensitive(o, own[j])) {
        char msg[160];
        snprintf(msg, sizeof msg, "a %s takes no \"%s\": it is the unit shape placed by \"transform\"", type, own[j]);
        return json_bad(c, where, msg);
      }
    if (mat == UINT32_MAX) {
      material d = material_default();
      mat = scene_add_material(c->s, &d);
      if (mat == UINT32_MAX) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    }
    return scene_add_primitive(c->s, (primitive_kind)k, xf, flip, mitsuba_uv, mat, c->err);
  }
  return json_bad(c, where, "unknown shape type (mesh, sphere, rectangle, cube, disk, cylinder)");
}

static valo_status parse_light(jctx *c, const cJSON *o, int index) {
  char where[64];
  snprintf(where, sizeof where, "lights[%d]", index);
  if (!cJSON_IsObject(o)) return json_bad(c, where, "must be an object");
  const char *type = NULL;
  TRY(json_get_str(c, o, "type", where, &type));
  if (!type) return json_bad(c, where, "needs a \"type\" (point, spot, directional)");
  light l;
  memset(&l, 0, sizeof l);
  l.L = c3(1, 1, 1);
  if (!strcmp(type, "point")) {
    static const char *const keys[] = {"type", "position", "intensity", NULL};
    TRY(json_check_keys(c, o, where, keys));
    l.type = LIGHT_POINT;
    TRY(json_get_vec(c, o, "position", where, 0, &l.p));
    TRY(json_get_rgb(c, o, "intensity", where, &l.L));
  } else if (!strcmp(type, "spot")) {
    static const char *const keys[] = {"type", "position", "look_at", "intensity", "cone_angle", "cone_delta_angle", "falloff", NULL};
    TRY(json_check_keys(c, o, where, keys));
    l.type = LIGHT_SPOT;
    vec3 at = v3(0, 0, 0);
    double cone = 30, delta = 5;
    TRY(json_get_vec(c, o, "position", where, 0, &l.p));
    TRY(json_get_vec(c, o, "look_at", where, 0, &at));
    TRY(json_get_rgb(c, o, "intensity", where, &l.L));
    TRY(json_get_num(c, o, "cone_angle", where, 0.01, 180, &cone));
    TRY(json_get_num(c, o, "cone_delta_angle", where, 0, 180, &delta));
    if (delta > cone) delta = cone;
    if (!(v3_len2(v3_sub(at, l.p)) > 0)) return json_bad(c, where, "position and look_at must differ");
    l.dir = v3_norm(v3_sub(at, l.p));
    l.cos_outer = cosf((float)(cone * M_PI / 180));
    l.cos_inner = cosf((float)((cone - delta) * M_PI / 180));
    const char *fall = NULL; /* across cone_delta_angle: smoothstep in the cosine (pbrt's) or linear in the angle (Mitsuba's) */
    TRY(json_get_str(c, o, "falloff", where, &fall));
    if (fall && strcmp(fall, "smoothstep") && strcmp(fall, "linear")) return json_bad(c, where, "falloff must be \"smoothstep\" or \"linear\"");
    l.spot_linear = fall && !strcmp(fall, "linear");
    l.ang_outer = (float)(cone * M_PI / 180);
    l.ang_inner = (float)((cone - delta) * M_PI / 180);
  } else if (!strcmp(type, "directional")) {
    static const char *const keys[] = {"type", "direction", "irradiance", NULL};
    TRY(json_check_keys(c, o, where, keys));
    l.type = LIGHT_DIRECTIONAL;
    l.dir = v3(0, -1, 0);
    TRY(json_get_vec(c, o, "direction", where, 0, &l.dir));
    TRY(json_get_rgb(c, o, "irradiance", where, &l.L));
    if (!(v3_len2(l.dir) > 0)) return json_bad(c, where, "direction must not be zero");
    l.dir = v3_norm(l.dir);
  } else {
    return json_bad(c, where, "unknown light type (point, spot, directional)");
  }
  if (scene_add_light(c->s, &l)) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  return VALO_OK;
}


valo_status load_json(scene *s, const char *path, valo_options *settings, valo_error *err) {
  char *text;
  size_t len;
  TRY(scene_text_read(path, &text, &len, err));
  if (strlen(text) != len) { free(text); return err_set(err, VALO_ERR_PARSE, "%s: contains a NUL byte: not a JSON text file", path); }
  const char *end = NULL;
  cJSON *root = cJSON_ParseWithOpts(text, &end, 1);
  if (!root) {
    int line, col;
    const char *at = end ? end : cJSON_GetErrorPtr();
    if (!at) at = text + len;
    json_line_col(text, at, &line, &col);
    free(text);
    return err_set(err, VALO_ERR_PARSE, "%s:%d:%d: JSON syntax error", path, line, col);
  }
  free(text);
  valo_status st = load_json_tree(s, path, root, settings, NULL, err);
  cJSON_Delete(root);
  return st;
}

valo_status load_json_tree(scene *s, const char *path, const cJSON *root, valo_options *settings, int at[2], valo_error *err) {
  valo_options unused;
  valo_options_init(&unused);
  jctx c = {.s = s, .path = path, .err = err, .file = settings ? settings : &unused};
  const char *slash = strrchr(path, '/');
  if (slash) snprintf(c.dir, sizeof c.dir, "%.*s", (int)(slash - path), path);
  valo_status st = VALO_OK;
  static const char *const keys[] = {"camera", "film", "render", "shapes", "materials", "media", "lights", "environment", NULL};
#undef TRY
#define TRY(x) do { st = (x); if (st) goto done; } while (0)
  TRY(json_check_keys(&c, root, "(top level)", keys));
  const cJSON *media = cJSON_GetObjectItemCaseSensitive(root, "media");
  if (media) TRY(json_parse_media(&c, media));
  const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
  if (cam) TRY(parse_camera(&c, cam));
  const cJSON *film = cJSON_GetObjectItemCaseSensitive(root, "film");
  if (film) {
    if (!cJSON_IsObject(film)) { st = json_bad(&c, "film", "must be an object"); goto done; }
    TRY(json_settings(&c, film, "film"));
  }
  const cJSON *render = cJSON_GetObjectItemCaseSensitive(root, "render");
  if (render) TRY(parse_render(&c, render));
  c.mfirst = s->nmats;
  const cJSON *mats = c.mats = cJSON_GetObjectItemCaseSensitive(root, "materials");
  if (mats) {
    if (!cJSON_IsObject(mats)) { st = json_bad(&c, "materials", "must be an object of named materials"); goto done; }
    for (const cJSON *m = mats->child; m; m = m->next) {
      material mm;
      TRY(json_parse_material(&c, m, m->string, &mm));
      uint32_t k = scene_add_material(s, &mm);
      if (k == UINT32_MAX || strmap_put(&c.mat_names, m->string, k)) { st = err_set(err, VALO_ERR_NOMEM, "out of memory"); goto done; }
    }
  }
  const cJSON *shapes = cJSON_GetObjectItemCaseSensitive(root, "shapes");
  if (shapes) {
    if (!cJSON_IsArray(shapes)) { st = json_bad(&c, "shapes", "must be an array"); goto done; }
    int i = 0;
    for (const cJSON *sh = shapes->child; sh; sh = sh->next, i++) {
      if (at) at[0] = i;
      TRY(parse_shape(&c, sh, i));
    }
    if (at) at[0] = -1;
  }
  if (c.cam_from_file) {
    if (!s->has_camera) { st = json_bad(&c, "camera.from_file", "no shape file has a camera"); goto done; }
    int ortho = s->cam.ortho_height > 0;
    if (ortho ? c.cam_fov > 0 : c.cam_height > 0) {
      st = json_bad(&c, ortho ? "camera.fov" : "camera.height",
                    ortho ? "the file's camera is orthographic: give its \"height\" in scene units, not a field of view"
                          : "the file's camera is a perspective camera: give its \"fov\", not a height");
      goto done;
    }
    if (c.cam_fov > 0) s->cam.fov_deg = c.cam_fov;
    if (c.cam_height > 0) s->cam.ortho_height = c.cam_height;
    s->cam.aperture_radius = c.cam_aperture;
    s->cam.focus_distance = c.cam_focus; /* <= 0: autofocus */
  }
  const cJSON *lights = cJSON_GetObjectItemCaseSensitive(root, "lights");
  if (lights) {
    if (!cJSON_IsArray(lights)) { st = json_bad(&c, "lights", "must be an array"); goto done; }
    int i = 0;
    for (const cJSON *l = lights->child; l; l = l->next, i++) {
      if (at) at[1] = i;
      TRY(parse_light(&c, l, i));
    }
    if (at) at[1] = -1;
  }
  const cJSON *env = cJSON_GetObjectItemCaseSensitive(root, "environment");
  if (env) TRY(json_parse_environment(&c, env));
done:
  mesh_cache_free(c.meshes);
  strmap_free(&c.mat_names);
  return st;
}

