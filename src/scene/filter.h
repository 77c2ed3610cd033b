/* filter.h — owns the pixel reconstruction filter: the box, the tent, a windowed
 * Gaussian (Mitsuba 3's: standard deviation radius/4, less its value at the radius), the
 * Blackman-Harris window over [-radius, radius] (Cycles' default filter: Cycles' filter
 * width is this radius), and three with negative lobes: Mitchell-Netravali (B = C = 1/3),
 * Catmull-Rom (B = 0, C = 1/2), both cubics stretched over [-radius, radius] as pbrt's
 * (Mitsuba's, fixed at radius 2), and Lanczos (sinc(x) sinc(x/radius), Mitsuba's of
 * radius "lobes"); all separable in x and y. By default it is sampled (filter
 * importance sampling, as pbrt-v4; film.splat splats through it instead, render/film.h): a camera sample lands at an offset from its pixel's
 * centre drawn in proportion to |filter| and counts for that pixel alone, with weight 1
 * where the filter is positive and, for the filters with negative lobes, sign(filter) x
 * integral |filter| / integral filter per axis. The film stays a per-pixel average (the
 * same image for any thread count, adaptive sampling and checkpoints unchanged) and its
 * expectation is the image convolved with the normalised filter. All but the box and
 * tent are tabulated: piecewise constant on FILTER_BINS steps over [-radius, radius],
 * which is the filter valo uses. */
#ifndef VALO_FILTER_H
#define VALO_FILTER_H

#define FILTER_BINS 1024

typedef enum { FILTER_BOX, FILTER_TENT, FILTER_GAUSSIAN, FILTER_BLACKMAN_HARRIS, FILTER_MITCHELL, FILTER_CATMULL_ROM, FILTER_LANCZOS } filter_kind;

typedef struct pixel_filter {
  filter_kind kind;
  float radius;                /* pixels: the filter is 0 beyond it */
  float cdf[FILTER_BINS + 1];  /* a tabulated filter's |filter|: cdf[i] = integral up to bin i, cdf[BINS] = 1 */
  float weight;                /* a sample's weight where the filter is positive: 1, or with negative
                                  lobes integral |filter| / integral filter (per axis) */
  unsigned char neg[FILTER_BINS]; /* 1 in the bins where the filter is negative */
} pixel_filter;

/* The filter named "box", "tent", "gaussian", "blackman-harris", "mitchell", "catmull-rom"
 * or "lanczos" of this radius in pixels (<= 0: the filter's default: 0.5, 1, 2, 2, 2 and 3
 * as Mitsuba's, 1.5 as Cycles'); -1 for another name. */
int pixel_filter_make(pixel_filter *f, const char *name, double radius);
/* The normalised 1D |filter| at offset x (its integral over [-radius, radius] is 1): the
 * density of pixel_filter_sample. */
float pixel_filter_pdf(const pixel_filter *f, float x);
/* An offset from the pixel's centre along one axis, distributed as pixel_filter_pdf, from
 * u in [0, 1) (monotone in u, so stratified u stay stratified); *w (when not NULL) gets
 * its weight, filter / pdf over the filter's integral: 1 but where a filter is negative. */
float pixel_filter_sample(const pixel_filter *f, float u, float *w);
#endif
