/* film.c — see film.h. */
#include "render/film.h"
#include "scene/filter.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

int film_init(film *f, int width, int height, int with_sq, int with_aov) {
  memset(f, 0, sizeof *f);
  f->width = width;
  f->height = height;
  size_t np = film_pixels(f);
  f->sum = calloc(np * 3, sizeof(double));
  f->count = calloc(np, sizeof(uint32_t));
  if (with_sq) f->sq = calloc(np * 4, sizeof(double));
  if (with_aov) f->aov = calloc(np * AOV_FLOATS, sizeof(float));
  if (!f->sum || !f->count || (with_sq && !f->sq) || (with_aov && !f->aov)) { film_free(f); return -1; }
  return 0;
}

void film_free(film *f) {
  free(f->sum);
  free(f->count);
  free(f->sq);
  free(f->aov);
  free(f->wsum);
  f->sum = NULL; f->count = NULL; f->sq = NULL; f->aov = NULL; f->wsum = NULL;
}

void film_clear(film *f) {
  size_t np = film_pixels(f);
  memset(f->sum, 0, np * 3 * sizeof *f->sum);
  memset(f->count, 0, np * sizeof *f->count);
  if (f->sq) memset(f->sq, 0, np * 4 * sizeof *f->sq);
  if (f->aov) memset(f->aov, 0, np * AOV_FLOATS * sizeof *f->aov);
  if (f->wsum) memset(f->wsum, 0, np * sizeof *f->wsum);
}

int film_enable_splat(film *f) {
  if (!f->wsum) f->wsum = calloc(film_pixels(f), sizeof(double));
  return f->wsum ? 0 : -1;
}

/* Adaptive sampling's sums of squares of pixel pix's own samples. */
static void add_squares(film *f, size_t pix, rgb L) {
  if (!f->sq) return;
  double *q = &f->sq[4 * pix], l = c3_lum(L);
  q[0] += (double)L.r * L.r; q[1] += (double)L.g * L.g; q[2] += (double)L.b * L.b; q[3] += l * l;
}

void film_add(film *f, size_t pix, rgb L, float w, thread_stats *ts) {
  f->count[pix]++;
  if (!sample_usable(ts, L)) return;
  if (w != 1) L = c3_scale(L, w);
  double *acc = &f->sum[3 * pix];
  acc[0] += L.r; acc[1] += L.g; acc[2] += L.b;
  add_squares(f, pix, L);
}

void film_add_splat(film *f, size_t pix, float fx, float fy, rgb L, const pixel_filter *pf, thread_stats *ts) {
  f->count[pix]++;
  if (!sample_usable(ts, L)) return;
  add_squares(f, pix, L);
  float r = pf->radius;
  int x0 = (int)ceilf(fx - 0.5f - r), x1 = (int)floorf(fx - 0.5f + r), y0 = (int)ceilf(fy - 0.5f - r), y1 = (int)floorf(fy - 0.5f + r);
  if (x0 < 0) x0 = 0;
  if (y0 < 0) y0 = 0;
  if (x1 > f->width - 1) x1 = f->width - 1;
  if (y1 > f->height - 1) y1 = f->height - 1;
  float wx[64];
  for (int x = x0; x <= x1 && x - x0 < 64; x++) wx[x - x0] = pixel_filter_pdf(pf, (float)x + 0.5f - fx);
  for (int y = y0; y <= y1; y++) {
    float wy = pixel_filter_pdf(pf, (float)y + 0.5f - fy);
    if (!(wy > 0)) continue;
    for (int x = x0; x <= x1 && x - x0 < 64; x++) {
      double w = (double)wx[x - x0] * wy;
      if (!(w > 0)) continue;
      size_t p = (size_t)y * (size_t)f->width + (size_t)x;
      double *acc = &f->sum[3 * p];
      acc[0] += w * L.r; acc[1] += w * L.g; acc[2] += w * L.b;
      f->wsum[p] += w;
    }
  }
}

void film_resolve(const film *f, float *rgb_out) {
  size_t n = film_pixels(f);
  for (size_t i = 0; i < n; i++) {
    double inv = f->wsum ? (f->wsum[i] > 0 ? 1.0 / f->wsum[i] : 0) : f->count[i] > 0 ? 1.0 / f->count[i] : 0;
    for (int c = 0; c < 3; c++) rgb_out[3 * i + c] = (float)(f->sum[3 * i + c] * inv);
  }
}
