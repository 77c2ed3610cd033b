/* filter.h — owns the pixel reconstruction filter: the box, the tent, a windowed
 * Gaussian (Mitsuba 3's: standard deviation radius/4, less its value at the radius) or
 * the Blackman-Harris window over [-radius, radius] (Cycles' default filter: Cycles'
 * filter width is this radius), separable in x and y. It is sampled, not splatted (filter importance sampling): a
 * camera sample lands at an offset from its pixel's centre drawn from the filter and counts
 * for that pixel alone with weight 1, so the film stays a per-pixel average (the same
 * image for any thread count, adaptive sampling and checkpoints unchanged) and its
 * expectation is the image convolved with the normalised filter. The Gaussian and
 * Blackman-Harris are tabulated: piecewise constant on FILTER_BINS steps over [-radius,
 * radius], which is the filter valo uses. */
#ifndef VALO_FILTER_H
#define VALO_FILTER_H

#define FILTER_BINS 1024

typedef enum { FILTER_BOX, FILTER_TENT, FILTER_GAUSSIAN, FILTER_BLACKMAN_HARRIS } filter_kind;

typedef struct pixel_filter {
  filter_kind kind;
  float radius;                /* pixels: the filter is 0 beyond it */
  float cdf[FILTER_BINS + 1];  /* a tabulated filter's: cdf[i] = integral up to bin i, cdf[BINS] = 1 */
} pixel_filter;

/* The filter named "box", "tent", "gaussian" or "blackman-harris" of this radius in
 * pixels (<= 0: the filter's default: 0.5, 1 and 2 as Mitsuba's, 1.5 as Cycles'); -1 for
 * another name. */
int pixel_filter_make(pixel_filter *f, const char *name, double radius);
/* The normalised 1D filter at offset x (its integral over [-radius, radius] is 1): the
 * density of pixel_filter_sample. */
float pixel_filter_pdf(const pixel_filter *f, float x);
/* An offset from the pixel's centre along one axis, distributed as pixel_filter_pdf, from
 * u in [0, 1) (monotone in u, so stratified u stay stratified). */
float pixel_filter_sample(const pixel_filter *f, float u);
#endif
