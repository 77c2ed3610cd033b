/* distrib.h — owns piecewise-bilinear 2D distributions: a density proportional to the
 * bilinear interpolant of non-negative values given at the vertices of a rectilinear
 * grid over [0,1]^2 (vertex positions need not be uniform), sampled exactly by
 * inverting its marginal over v (piecewise linear) and then the conditional over u
 * (piecewise linear at the sampled v), each within a cell by the closed-form root of a
 * quadratic. Used to importance-sample environment maps, whose radiance is looked up
 * bilinearly (Mitsuba's Marginal2D and pbrt-v4's SampleBilinear sample the same kind of
 * density). */
#ifndef VALO_DISTRIB_H
#define VALO_DISTRIB_H
#include <stdint.h>

typedef struct bilin2d {
  uint32_t nx, ny;  /* vertices per row, rows of vertices (each >= 2) */
  float *x, *y;     /* vertex positions, increasing, from 0 to 1 */
  float *f;         /* ny * nx vertex values, row-major */
  float *cum;       /* ny * nx: integral of row j's piecewise-linear function over [0, x[i]] */
  float *ycum;      /* ny: integral of the density's marginal over [0, y[j]] */
  float total;      /* integral over the square */
} bilin2d;

/* x: nx positions, y: ny positions (0 first, 1 last, increasing), f: ny*nx values
 * (negative or non-finite ones taken as 0; all zero gives the uniform density). All
 * copied. Returns 0, or -1 on bad input or out of memory. */
int bilin2d_init(bilin2d *d, const float *x, uint32_t nx, const float *y, uint32_t ny, const float *f);
void bilin2d_free(bilin2d *d);
/* Samples (u, v) in [0,1]^2 from (u1, u2) in [0,1)^2; *pdf is its density w.r.t. du dv. */
void bilin2d_sample(const bilin2d *d, float u1, float u2, float *u, float *v, float *pdf);
float bilin2d_pdf(const bilin2d *d, float u, float v);
#endif
