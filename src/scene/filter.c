/* filter.c — see filter.h. */
#include "scene/filter.h"
#include <math.h>
#include <string.h>

static const struct { const char *name; filter_kind kind; double radius; } kinds[] = {
    {"box", FILTER_BOX, 0.5}, {"tent", FILTER_TENT, 1.0}, {"gaussian", FILTER_GAUSSIAN, 2.0}, {"blackman-harris", FILTER_BLACKMAN_HARRIS, 1.5}};

/* The table's entry for a filter's name, or -1. */
static int find_kind(const char *name) {
  for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++)
    if (!strcmp(name, kinds[i].name)) return (int)i;
  return -1;
}

/* A tabulated filter, unnormalised, at x in [-radius, radius]: the windowed Gaussian, or
 * the four-term Blackman-Harris window across the whole width. */
static double tabulated(filter_kind kind, double x, double radius) {
  if (kind == FILTER_GAUSSIAN) {
    double s = radius / 4, a = -1 / (2 * s * s);
    return fmax(0.0, exp(a * x * x) - exp(a * radius * radius));
  }
  double t = 2 * M_PI * (x / (2 * radius) + 0.5);
  return fmax(0.0, 0.35875 - 0.48829 * cos(t) + 0.14128 * cos(2 * t) - 0.01168 * cos(3 * t));
}

int pixel_filter_make(pixel_filter *f, const char *name, double radius) {
  int k = find_kind(name);
  if (k < 0) return -1;
  memset(f, 0, sizeof *f);
  f->kind = kinds[k].kind;
  f->radius = (float)(radius > 0 ? radius : kinds[k].radius);
  if (f->kind == FILTER_GAUSSIAN || f->kind == FILTER_BLACKMAN_HARRIS) {
    double sum = 0, step = 2.0 * f->radius / FILTER_BINS, acc[FILTER_BINS + 1];
    acc[0] = 0;
    for (int i = 0; i < FILTER_BINS; i++) acc[i + 1] = (sum += tabulated(f->kind, -f->radius + (i + 0.5) * step, f->radius));
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
    case FILTER_GAUSSIAN: case FILTER_BLACKMAN_HARRIS: break;
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
    case FILTER_GAUSSIAN: case FILTER_BLACKMAN_HARRIS: break;
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
