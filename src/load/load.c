/* load.c — see load.h: file kind by extension, the --env replacement, the no-light
 * policy, then scene_commit. */
#include "load/load.h"
#include "scene/envmap.h"
#include "core/error.h"
#include "core/strutil.h"
#include "load/serialized.h"
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* Lights a scene could have before commit: emissive triangles, lights, an environment. */
static int scene_has_any_light(const scene *s) {
  if (s->nlights > 0) return 1;
  if (s->has_env && (s->env_map || !c3_black(s->env_radiance))) return 1;
  for (uint32_t t = 0; t < s->ntris; t++)
    if (!c3_black(s->mats[s->tri_mat[t]].emission)) return 1;
  for (uint32_t i = 0; i < s->nmedia; i++)
    if (medium_glows(&s->media[i])) return 1;
  return 0;
}

valo_status scene_load(const char *path, const valo_load_options *lo, scene **out, valo_options *file, valo_error *err) {
  *out = NULL;
  valo_load_options def;
  valo_load_options_init(&def);
  if (!lo) lo = &def;
  if (!path || !*path) return err_set(err, VALO_ERR_INVALID, "no scene file given");
  if (strcmp(lo->up, "y") && strcmp(lo->up, "z") && lo->up[0]) return err_set(err, VALO_ERR_INVALID, "up axis \"%s\" (y or z)", lo->up);
  scene *s = scene_new(path);
  if (!s) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  int xml = str_ends_with(path, ".xml"), json = xml || str_ends_with(path, ".json");
  if (lo->defines[0] && !xml) {
    scene_free(s);
    return err_set(err, VALO_ERR_INVALID, "--define sets a Mitsuba scene's <default> values; %s is not a Mitsuba scene (.xml)", path);
  }
  s->up_z = !strcmp(lo->up, "z");
  valo_status st;
  if (xml) st = load_mitsuba(s, path, lo->defines, file, err);
  else if (json) st = load_json(s, path, file, err);
  else if (str_ends_with(path, ".serialized")) st = load_serialized(s, path, -1, NULL, UINT32_MAX, LOAD_MESH_SMOOTH, err); /* every shape */
  else st = load_mesh(s, path, NULL, UINT32_MAX, LOAD_MESH_CAMERA, file, err);
  if (st == VALO_OK && lo->env_file[0]) {
    /* --env replaces whatever environment the scene had. */
    envmap_destroy(s->env_map);
    s->env_map = NULL;
    st = envmap_create(lo->env_file, (float)lo->env_scale, (float)lo->env_rotation, &s->env_map, err);
    s->has_env = st == VALO_OK;
  }
  if (st == VALO_OK && !scene_has_any_light(s)) {
    if (!json) {
      s->has_env = 1;
      s->env_radiance = c3(1, 1, 1);
      log_note("%s has no light of its own (no emissive material, no light): it is lit by a uniform white environment "
               "(radiance 1), as model viewers do; --env FILE lights it by an environment map instead", path);
    } else {
      log_warning("%s has no light (no emissive material, no light, no environment): the image will be black", path);
    }
  }
  if (st == VALO_OK) st = scene_commit(s, err);
  if (st) { scene_free(s); return st; }
  *out = s;
  return VALO_OK;
}
