/* load.h — owns the loaders' front door: a scene file (JSON, or any mesh file Assimp
 * reads) becomes a committed scene model plus the render settings the file asks for.
 * The only module that knows file formats; the API calls it, nothing below does. */
#ifndef VALO_LOAD_H
#define VALO_LOAD_H
#include "scene/scene.h"
#include "valo/valo.h"

/* Loads path (".json": the JSON scene format; anything else: a mesh file) with the load
 * options lo (NULL: defaults): --env replaces the environment, `up` frames mesh files;
 * a mesh file without any light is lit by a uniform white environment (a note says so),
 * a JSON scene without one renders black (a warning says so). Then commits the scene.
 * file receives the settings the file carries (valo_options_init first; unset fields
 * stay VALO_UNSET). On error *out is NULL and err names the file. */
valo_status scene_load(const char *path, const valo_load_options *lo, scene **out, valo_options *file, valo_error *err);

/* The two loaders, appending to s; file (may be NULL) receives the settings they find. */
valo_status load_json(scene *s, const char *path, valo_options *file, valo_error *err);
/* A Mitsuba scene (.xml, Mitsuba 3 or 0.6), translated into the JSON scene format;
 * defines ("NAME=VALUE ...", may be NULL) replace its <default> values. */
valo_status load_mitsuba(scene *s, const char *path, const char *defines, valo_options *file, valo_error *err);
/* Writes the JSON scene the Mitsuba scene at path means to out (atomically), its file
 * names made absolute (valo convert). */
valo_status mitsuba_to_json(const char *path, const char *defines, const char *out, valo_error *err);
/* Loads a mesh file into s with transform xf (4x3 row-major, NULL = identity);
 * override_mat: material index for every triangle, or UINT32_MAX to keep the file's;
 * mesh_flags: LOAD_MESH_CAMERA, use the file's camera (its aspect sets the file's film
 * size); LOAD_MESH_FLAT, shade with the triangles' own normals, not the file's;
 * LOAD_MESH_SMOOTH, a file without normals is shaded with normals computed from its faces
 * (angle-weighted over the vertices its faces share, as Mitsuba does); LOAD_MESH_FLIP_V, the
 * file's v runs down its images (a PLY in a Mitsuba scene): turned up, v' = 1 - v. */
enum { LOAD_MESH_CAMERA = 1, LOAD_MESH_FLAT = 2, LOAD_MESH_SMOOTH = 4, LOAD_MESH_FLIP_V = 8 };
valo_status load_mesh(scene *s, const char *path, const float *xf, uint32_t override_mat, int mesh_flags, valo_options *file,
                      valo_error *err);
/* load_mesh, with each file's import kept in *cache (made on first use; NULL: none kept)
 * by path and LOAD_MESH_SMOOTH, so that a file placed again (a JSON scene naming it twice,
 * Mitsuba's instances) is not read again: the same import, placed by its own xf, exactly
 * as a second reading would place it. Free with mesh_cache_free. */
typedef struct mesh_cache mesh_cache;
valo_status load_mesh_cached(scene *s, const char *path, const float *xf, uint32_t override_mat, int mesh_flags, valo_options *file,
                             mesh_cache **cache, valo_error *err);
void mesh_cache_free(mesh_cache *cache);
#endif
