/* load_json_internal.h — owns what the JSON loader's files share: the parse context
 * and the typed getters that name the file and the JSON path in every message. */
#ifndef VALO_LOAD_JSON_INTERNAL_H
#define VALO_LOAD_JSON_INTERNAL_H
#include "load/load.h"
#include "core/strmap.h"
#include <cjson/cJSON.h>

typedef struct jctx {
  scene *s; const char *path; char dir[1024]; valo_error *err;
  valo_options *file;          /* the render settings the file asks for ("film", "render") */
  int cam_from_file;           /* camera.from_file: take the first shape file's camera */
  float cam_fov, cam_height, cam_aperture, cam_focus; /* its overrides (fov, height <= 0: keep
                                                         the file's) */
  mesh_cache *meshes;          /* the mesh files imported so far (load_mesh_cached) */
  const cJSON *mats;           /* the "materials" object, whose k-th material is mfirst + k */
  uint32_t mfirst;
  strmap mat_names;            /* their names (the "materials" keys) -> scene material index */
} jctx;

/* The getters: a missing key leaves *out as it is; a present one of the wrong type or
 * out of [lo, hi] is an error "file: where.key: what". */
valo_status json_bad(jctx *c, const char *where, const char *what);
valo_status json_check_keys(jctx *c, const cJSON *obj, const char *where, const char *const *allowed);
valo_status json_get_num(jctx *c, const cJSON *o, const char *key, const char *where, double lo, double hi, double *out);
valo_status json_get_int(jctx *c, const cJSON *o, const char *key, const char *where, double lo, double hi, int *out);
valo_status json_get_vec(jctx *c, const cJSON *o, const char *key, const char *where, int allow_scalar, vec3 *out);
valo_status json_get_rgb(jctx *c, const cJSON *o, const char *key, const char *where, rgb *out);
valo_status json_get_str(jctx *c, const cJSON *o, const char *key, const char *where, const char **out);
valo_status json_get_bool(jctx *c, const cJSON *o, const char *key, const char *where, int *out);
/* A texture value v at w ("where.key"): a file name or a texture object (load_json_texture.c);
 * srgb: decode 8-bit images from sRGB unless the object says "raw"; what names it in errors. */
valo_status json_get_texture(jctx *c, const cJSON *v, int srgb, const char *w, const char *what, int *tex);
void json_resolve_path(const jctx *c, const char *rel, char *out, size_t n);
void json_line_col(const char *text, const char *at, int *line, int *col);
/* Materials (load_json_material.c): the material object `o` named `name`. */
valo_status json_parse_material(jctx *c, const cJSON *o, const char *name, material *m);
/* The top-level "media" object: adds each named medium to the scene. */
valo_status json_parse_media(jctx *c, const cJSON *o);
/* The "environment" object (load_json_env.c). */
valo_status json_parse_environment(jctx *c, const cJSON *env);
/* The medium named by key `key` of o (a string naming one of "media"): *med stays as it
 * is when the key is absent. */
valo_status json_get_medium(jctx *c, const cJSON *o, const char *key, const char *where, int32_t *med);

/* A scene file's whole text (at most 64 MiB), NUL-ended (free it): *len bytes. */
valo_status scene_text_read(const char *path, char **text, size_t *len, valo_error *err);
/* A shape's "transform" object into xf (3x4 row-major). */
valo_status json_parse_transform(jctx *c, const cJSON *o, const char *where, float xf[12]);
/* The JSON scene format's reader over a parsed tree (load_json reads the text first);
 * path names the file in messages and resolves relative file names. On an error, at
 * (may be NULL; -1 each first) gets the index of the shape and of the light being read. */
valo_status load_json_tree(scene *s, const char *path, const cJSON *root, valo_options *settings, int at[2], valo_error *err);

#define TRY(x) do { valo_status st_ = (x); if (st_) return st_; } while (0)

#endif
