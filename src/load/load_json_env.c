/* load_json_env.c — owns the JSON scene format's "environment" (docs/scene-format.md,
 * "environment"): a constant radiance, an equirectangular map or six cube faces, scaled
 * and turned. */
#include "load/load_json_internal.h"
#include "scene/envmap.h"
#include "core/error.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

/* "matrix": nine numbers, row by row, turning the map's frame into the world's (instead
 * of "rotation"), orthonormal: applied to the map just made. */
static valo_status env_frame(jctx *c, const cJSON *env) {
  const cJSON *a = cJSON_GetObjectItemCaseSensitive(env, "matrix");
  if (!a) return VALO_OK;
  if (cJSON_GetObjectItemCaseSensitive(env, "rotation")) return json_bad(c, "environment", "give \"rotation\" or \"matrix\", not both");
  double m[9];
  int n = 0;
  if (cJSON_IsArray(a))
    for (const cJSON *e = a->child; e && n < 10; e = e->next) m[n < 9 ? n : 8] = cJSON_IsNumber(e) ? e->valuedouble : NAN, n++;
  if (n != 9) return json_bad(c, "environment.matrix", "must be an array of 9 numbers (3 rows)");
  if (envmap_set_frame(c->s->env_map, m)) return json_bad(c, "environment.matrix", "must be orthonormal (a turn, or a mirror), within 1e-3");
  return VALO_OK;
}

valo_status json_parse_environment(jctx *c, const cJSON *env) {
  const char *type = "constant";
  TRY(json_get_str(c, env, "type", "environment", &type));
  if (!strcmp(type, "constant")) {
    static const char *const ek[] = {"type", "radiance", NULL};
    TRY(json_check_keys(c, env, "environment", ek));
    c->s->env_radiance = c3(1, 1, 1);
    TRY(json_get_rgb(c, env, "radiance", "environment", &c->s->env_radiance));
  } else if (!strcmp(type, "map")) {
    static const char *const ek[] = {"type", "file", "scale", "rotation", "matrix", "mitsuba_rows", NULL};
    TRY(json_check_keys(c, env, "environment", ek));
    const char *file = NULL;
    double scale = 1, rot = 0;
    TRY(json_get_str(c, env, "file", "environment", &file));
    if (!file) return json_bad(c, "environment", "a map needs \"file\" (an equirectangular .exr, .hdr or .pfm)");
    TRY(json_get_num(c, env, "scale", "environment", 0, 1e9, &scale));
    TRY(json_get_num(c, env, "rotation", "environment", -1e6, 1e6, &rot));
    char full[2048];
    json_resolve_path(c, file, full, sizeof full);
    TRY(envmap_create(full, (float)scale, (float)rot, &c->s->env_map, c->err));
    TRY(env_frame(c, env));
    int mrows = 0;
    TRY(json_get_bool(c, env, "mitsuba_rows", "environment", &mrows));
    if (envmap_set_mitsuba_rows(c->s->env_map, mrows)) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  } else if (!strcmp(type, "cube")) {
    static const char *const ek[] = {"type", "faces", "scale", "rotation", "matrix", NULL};
    TRY(json_check_keys(c, env, "environment", ek));
    const cJSON *faces = cJSON_GetObjectItemCaseSensitive(env, "faces");
    if (!cJSON_IsArray(faces) || cJSON_GetArraySize(faces) != 6) {
      return json_bad(c, "environment.faces", "must be an array of six image files: +x, -x, +y, -y, +z, -z");
    }
    char full[6][2048];
    const char *paths[6];
    int i = 0;
    for (const cJSON *fe = faces->child; fe; fe = fe->next, i++) {
      if (!cJSON_IsString(fe)) return json_bad(c, "environment.faces", "must hold file names (strings)");
      json_resolve_path(c, fe->valuestring, full[i], sizeof full[i]);
      paths[i] = full[i];
    }
    double scale = 1, rot = 0;
    TRY(json_get_num(c, env, "scale", "environment", 0, 1e9, &scale));
    TRY(json_get_num(c, env, "rotation", "environment", -1e6, 1e6, &rot));
    TRY(envmap_create_cube(paths, (float)scale, (float)rot, &c->s->env_map, c->err));
    TRY(env_frame(c, env));
  } else {
    return json_bad(c, "environment.type", "unknown environment type (constant, map, cube)");
  }
  c->s->has_env = 1;
  return VALO_OK;
}
