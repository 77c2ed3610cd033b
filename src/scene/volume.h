/* volume.h — owns density grids for heterogeneous media: reading Mitsuba's .vol format
 * (version 3, one channel of float32 or uint8 values, x fastest, then y, then z), and
 * trilinear lookup with texel centres at (i + 0.5) / n of the grid's box and values
 * clamped to the edge texels inside it, as Mitsuba 3's gridvolume looks a grid up;
 * outside the box the density is 0. */
#ifndef VALO_VOLUME_H
#define VALO_VOLUME_H
#include "core/vec.h"
#include "valo/valo.h"

typedef struct density_grid {
  int nx, ny, nz;
  float *d;     /* nx * ny * nz densities, d[(z * ny + y) * nx + x] */
  bbox box;     /* where the grid lies in the scene (the file's box unless the scene gives one) */
  float dmax;   /* the largest density: the majorant's factor */
} density_grid;

/* Reads a .vol file; negative or non-finite values, a truncated file, another version,
 * encoding or channel count are errors naming the file. */
valo_status density_grid_load(const char *path, density_grid **out, valo_error *err);
void density_grid_free(density_grid *g);
/* The density at world point p (0 outside the box). */
float density_grid_at(const density_grid *g, vec3 p);
#endif
