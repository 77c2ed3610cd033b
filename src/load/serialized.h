/* serialized.h — owns Mitsuba's .serialized mesh files (Mitsuba 0.6 and 3): indexed
 * triangle meshes, each a zlib stream after a 4-byte header, several to a file, found
 * through the table of offsets at the file's end. */
#ifndef VALO_SERIALIZED_H
#define VALO_SERIALIZED_H
#include "load/load.h"

/* Appends shape shape_index of the file at path (< 0: every shape) to s, placed by xf
 * (3x4 row-major, NULL = identity), of material mat (UINT32_MAX: a default one);
 * mesh_flags: LOAD_MESH_FLAT, shade with the triangles' own normals (the file's
 * face-normal flag asks for it too); LOAD_MESH_SMOOTH, compute normals where it has none.
 * Texture coordinates are turned to valo's v up. Errors name the file and the shape. */
valo_status load_serialized(scene *s, const char *path, int shape_index, const float *xf, uint32_t mat, int mesh_flags, valo_error *err);
/* The number of shapes in the file at path (0 with err set when it is not one). */
uint32_t serialized_count(const char *path, valo_error *err);
#endif
