/* denoise.h — owns the still-image denoiser: a joint non-local-means filter (Rousselle,
 * Manzi, Zwicker 2013) on the radiance divided by the albedo of the first hit, its weights
 * the product of a colour term (3x3 patch distances, corrected and scaled by the pixels'
 * own variance estimates, so noise alone does not separate pixels) and feature terms
 * (albedo, shading normal, depth: what the AOVs say of the surface), then multiplied by
 * the albedo again so texture and edges in albedo come back at full resolution. Each
 * pixel's result depends on its window alone: images are the same for any thread count.
 * What it biases: it averages pixels whose features and radiance agree within their noise,
 * so detail below the noise in radiance (soft shadows at a few samples, caustics) is
 * blurred across a window of (2 * DENOISE_RADIUS + 1)^2 pixels; where features do not
 * tell surfaces apart (the same albedo and normal at the same depth) nor does light. */
#ifndef VALO_DENOISE_H
#define VALO_DENOISE_H

#define DENOISE_RADIUS 8

typedef struct denoise_in {
  int w, h;
  const float *color;   /* 3 per pixel: the image */
  const float *var;     /* 3 per pixel: the variance of each pixel's mean (NULL: unknown, estimated) */
  const float *albedo;  /* 3 per pixel (NULL: none) */
  const float *normal;  /* 3 per pixel (NULL: none) */
  const float *depth;   /* 1 per pixel (NULL: none) */
} denoise_in;

/* Writes the filtered image (3 per pixel) to out. Returns 0, or -1 when out of memory. */
int denoise_image(const denoise_in *in, float *out, int threads);
#endif
