/* filter.c — see filter.h. */
#include "scene/filter.h"
#include <math.h>
#include <string.h>

double pixel_filter_default_radius(const char *name) {
  return !strcmp(name, "box") ? 0.5 : !strcmp(name, "tent") ? 1.0 : !strcmp(name, "gaussian") ? 2.0 : 0.0;
}

/* The windowed Gaussian, unnormalised, at x. */
static double gaussian(double x, double radius) {
  double s = radius / 4, a = -1 / (2 * s * s);
  return fmax(0.0, exp(a * x * x) - exp(a * radius * radius));
}

int pixel_filter_make(pixel_filter *f, const char *name, double radius) {
  double def = pixel_filter_default_radius(name);
  if (!(def > 0)) return -1;
  memset(f, 0, sizeof *f);
  f->kind = !strcmp(name, "box") ? FILTER_BOX : !strcmp(name, "tent") ? FILTER_TENT : FILTER_GAUSSIAN;
  f->radius = (float)(radius > 0 ? radius : def);
  if (f->kind == FILTER_GAUSSIAN) {
    double sum = 0, step = 2.0 * f->radius / FILTER_BINS, acc[FILTER_BINS + 1];
    acc[0] = 0;
    for (int i = 0; i < FILTER_BINS; i++) acc[i + 1] = (sum += gaussian(-f->radius + (i + 0.5) * step, f->radius));
    for (int i = 0; i <= FILTER_BINS; i++) f->cdf[i] = (float)(acc[i] / sum);
    f->cdf[FILTER_BINS] = 1;
  }
  return 0;
}

float pixel_filter_pdf(const pixel_filter *f, float x) {
  float r = f->radius, ax = fabsf(x);
  if (!(ax <= r)) return 0;
  switch (f->kind) {
    case FILTER_BOX: return 0.5f / r;
    case FILTER_TENT: return (1 - ax / r) / r;
    case FILTER_GAUSSIAN: break;
  }
  int i = (int)((x + r) / (2 * r) * FILTER_BINS);
  i = i < 0 ? 0 : i >= FILTER_BINS ? FILTER_BINS - 1 : i;
  return (f->cdf[i + 1] - f->cdf[i]) * FILTER_BINS / (2 * r);
}

float pixel_filter_sample(const pixel_filter *f, float u) {
  float r = f->radius;
  switch (f->kind) {
    case FILTER_BOX: return (2 * u - 1) * r;
    case FILTER_TENT: return u < 0.5f ? r * (sqrtf(2 * u) - 1) : r * (1 - sqrtf(2 - 2 * u));
    case FILTER_GAUSSIAN: break;
  }
  int lo = 0, hi = FILTER_BINS; /* the bin with cdf[lo] <= u < cdf[lo + 1] */
  while (hi - lo > 1) {
    int m = (lo + hi) / 2;
    if (f->cdf[m] <= u) lo = m;
    else hi = m;
  }
  float w = f->cdf[lo + 1] - f->cdf[lo], t = w > 0 ? fminf((u - f->cdf[lo]) / w, 1.0f) : 0.5f;
  return -r + ((float)lo + t) * (2 * r / FILTER_BINS);
}
