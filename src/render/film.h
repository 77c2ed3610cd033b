/* film.h — owns the film: per pixel the sum of its samples' radiance (double, summed in
 * sample order, so images are the same for any thread count), their count, for adaptive
 * sampling the sums of squares, and the AOV sums of the first camera hits. A sample counts
 * for its own pixel (its offset drawn from the filter: filter importance sampling), or,
 * splatting, is added to each pixel the filter reaches with the filter's weight there. */
#ifndef VALO_FILM_H
#define VALO_FILM_H
#include "core/stats.h"
#include <stddef.h>
#include <stdint.h>

/* The AOV sums of one pixel, AOV_FLOATS floats at film.aov + AOV_FLOATS * pixel. */
enum {
  AOV_ALBEDO = 0,   /* 3: albedo rgb */
  AOV_NORMAL = 3,   /* 3: shading normal facing the camera */
  AOV_DEPTH = 6,    /* 1: hit distance */
  AOV_AO = 7,       /* 1: unoccluded ao rays */
  AOV_BENT = 8,     /* 3: sum of their directions (the bent normal) */
  AOV_EMIT = 11,    /* 3: radiance the hit emits toward the camera (the live denoiser leaves it unfiltered) */
  AOV_FLOATS = 14
};

typedef struct film {
  int width, height;
  double *sum;      /* 3 per pixel */
  uint32_t *count;  /* samples per pixel */
  double *sq;       /* adaptive sampling: sums of squares of r, g, b and luminance, or NULL */
  float *aov;       /* AOV_FLOATS per pixel, or NULL */
  double *wsum;     /* splatting (film_add_splat): the filter weights each pixel received, or NULL */
} film;

/* Allocates a black film; with_sq / with_aov add those arrays. -1 on out of memory (the
 * film is then freed). */
int film_init(film *f, int width, int height, int with_sq, int with_aov);
void film_free(film *f);
/* Zeroes the film: sums, counts, squares, AOVs and splat weights (a new frame of a
 * sequence, a restarted step). */
void film_clear(film *f);
/* Adds one sample's radiance to pixel pix times its filter weight w (camera_ray): NaN,
 * infinite and negative radiances count as taken but are dropped (counted by cause in
 * ts); a negative weight (a filter's negative lobe) is not a loss. */
void film_add(film *f, size_t pix, rgb L, float w, thread_stats *ts);
/* Splatting: allocates wsum (-1 on out of memory). */
int film_enable_splat(film *f);
/* A sample taken in pixel pix at film position (fx, fy) (pixel (x, y) spans [x, x + 1) x
 * [y, y + 1)): counted for pix (with its squares, for adaptive sampling), its radiance
 * added to every pixel whose centre lies within the filter's radius, weighted by the
 * filter there (pixel_filter_pdf in x times in y), the weight added to that pixel's wsum.
 * The caller keeps pixels that two threads could reach apart (tiles.c). */
struct pixel_filter;
void film_add_splat(film *f, size_t pix, float fx, float fy, rgb L, const struct pixel_filter *pf, thread_stats *ts);
/* The mean radiance of every pixel (splatting: its weighted sum over its weights' sum) (black where no sample landed), rgb_out w*h*3. */
void film_resolve(const film *f, float *rgb_out);
static inline size_t film_pixels(const film *f) { return (size_t)f->width * (size_t)f->height; }
#endif
