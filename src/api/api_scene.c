/* api_scene.c — owns the public scene handle: valo_scene is a committed scene model plus
 * the render settings its file asked for. Loading goes through the loaders' front door
 * (src/load/load.h). */
#include "valo/valo.h"
#include "api/api.h"
#include "load/load.h"
#include "core/error.h"
#include <stdlib.h>

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

VALO_API valo_status valo_scene_load(const char *path, valo_scene **out, valo_error *err) {
  return valo_scene_load_with(path, NULL, out, err);
}

VALO_API int valo_scene_has_light(const valo_scene *vs) {
  for (uint32_t i = 0; i < vs->s->nmedia; i++)
    if (medium_glows(&vs->s->media[i])) return 1;
  return vs->s->nlights > 0;
}

VALO_API void valo_scene_destroy(valo_scene *vs) {
  if (!vs) return;
  scene_free(vs->s);
  free(vs);
}
VALO_API void valo_scene_file_options(const valo_scene *vs, valo_options *out) { *out = vs->file_opts; }
VALO_API uint64_t valo_scene_triangle_count(const valo_scene *vs) { return vs->s->ntris; }
