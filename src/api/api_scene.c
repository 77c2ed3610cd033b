/* api_scene.c — owns the public scene handle: valo_scene is a committed scene model plus
 * the render settings its file asked for. Loading goes through the loaders' front door
 * (src/load/load.h). */
#include "valo/valo.h"
#include "api/api.h"
#include "load/load.h"
#include "core/error.h"
#include <stdlib.h>
#include <string.h>
#include <strings.h>

VALO_API const char *valo_version(void) { return VALO_VERSION_STRING; }

VALO_API valo_status valo_scene_load_with(const char *path, const valo_load_options *lo, valo_scene **out, valo_error *err) {
  *out = NULL;
  if (err) { err->status = VALO_OK; err->message[0] = 0; }
  log_scope scope;
  log_scope_enter(&scope, lo ? lo->on_warning : NULL, lo ? lo->on_warning_user : NULL);
  valo_scene *vs = calloc(1, sizeof *vs);
  valo_status st = vs ? VALO_OK : err_set(err, VALO_ERR_NOMEM, "out of memory");
  if (vs) {
    valo_options_init(&vs->file_opts);
    if (lo) { vs->warn_fn = lo->on_warning; vs->warn_user = lo->on_warning_user; }
    st = scene_load(path, lo, &vs->s, &vs->file_opts, err);
    if (st) { free(vs); vs = NULL; }
  }
  log_scope_leave(&scope);
  *out = vs;
  return st;
}

VALO_API valo_status valo_scene_convert(const char *path, const valo_load_options *lo, const char *out, valo_error *err) {
  if (err) { err->status = VALO_OK; err->message[0] = 0; }
  if (!path || !out) return err_set(err, VALO_ERR_INVALID, "valo convert needs a scene and an output file");
  size_t n = strlen(path), m = strlen(out);
  if (n < 4 || strcasecmp(path + n - 4, ".xml")) return err_set(err, VALO_ERR_INVALID, "%s: valo converts Mitsuba scene files (.xml)", path);
  if (m < 5 || strcasecmp(out + m - 5, ".json")) return err_set(err, VALO_ERR_INVALID, "%s: the output is a JSON scene file (.json)", out);
  log_scope scope;
  log_scope_enter(&scope, lo ? lo->on_warning : NULL, lo ? lo->on_warning_user : NULL);
  valo_status st = mitsuba_to_json(path, lo ? lo->defines : NULL, out, err);
  log_scope_leave(&scope);
  return st;
}

VALO_API valo_status valo_scene_load(const char *path, valo_scene **out, valo_error *err) {
  return valo_scene_load_with(path, NULL, out, err);
}

VALO_API int valo_scene_has_light(const valo_scene *vs) {
  for (uint32_t i = 0; i < vs->s->nmedia; i++)
    if (medium_glows(&vs->s->media[i])) return 1;
  return vs->s->nlights > 0;
}

VALO_API unsigned valo_scene_overlapping_lights(const valo_scene *vs) {
  unsigned n = 0;
  for (uint32_t i = 0; i < vs->s->nlights; i++) n += vs->s->lights[i].shares_plane != 0;
  return n;
}

VALO_API void valo_scene_destroy(valo_scene *vs) {
  if (!vs) return;
  scene_free(vs->s);
  free(vs);
}
VALO_API void valo_scene_file_options(const valo_scene *vs, valo_options *out) { *out = vs->file_opts; }
VALO_API uint64_t valo_scene_triangle_count(const valo_scene *vs) { return vs->s->ntris; }
