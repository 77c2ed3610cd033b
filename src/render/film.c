/* film.c — see film.h. */
#include "render/film.h"
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
  f->sum = NULL; f->count = NULL; f->sq = NULL; f->aov = NULL;
}

void film_clear(film *f) {
  size_t np = film_pixels(f);
  memset(f->sum, 0, np * 3 * sizeof *f->sum);
  memset(f->count, 0, np * sizeof *f->count);
}

void film_add(film *f, size_t pix, rgb L, float w, thread_stats *ts) {
  f->count[pix]++;
  if (!sample_usable(ts, L)) return;
  if (w != 1) L = c3_scale(L, w);
  double *acc = &f->sum[3 * pix];
  acc[0] += L.r; acc[1] += L.g; acc[2] += L.b;
  if (f->sq) {
    double *q = &f->sq[4 * pix], l = c3_lum(L);
    q[0] += (double)L.r * L.r; q[1] += (double)L.g * L.g; q[2] += (double)L.b * L.b; q[3] += l * l;
  }
}

void film_resolve(const film *f, float *rgb_out) {
  size_t n = film_pixels(f);
  for (size_t i = 0; i < n; i++) {
    double inv = f->count[i] > 0 ? 1.0 / f->count[i] : 0;
    for (int c = 0; c < 3; c++) rgb_out[3 * i + c] = (float)(f->sum[3 * i + c] * inv);
  }
}
