/* filter.c — see filter.h. */
#include "scene/filter.h"
#include <math.h>
#include <string.h>

static const struct { const char *name; filter_kind kind; double radius; } kinds[] = {
    {"box", FILTER_BOX, 0.5}, {"tent", FILTER_TENT, 1.0}, {"gaussian", FILTER_GAUSSIAN, 2.0}, {"blackman-harris", FILTER_BLACKMAN_HARRIS, 1.5},
    {"mitchell", FILTER_MITCHELL, 2.0}, {"catmull-rom", FILTER_CATMULL_ROM, 2.0}, {"lanczos", FILTER_LANCZOS, 3.0}};

/* The table's entry for a filter's name, or -1. */
static int find_kind(const char *name) {
  for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++)
    if (!strcmp(name, kinds[i].name)) return (int)i;
  return -1;
}

/* Mitchell and Netravali's cubic of parameters b, c at t in [0, 2], times 6. */
static double cubic(double b, double c, double t) {
  if (t < 1) return (12 - 9 * b - 6 * c) * t * t * t + (-18 + 12 * b + 6 * c) * t * t + (6 - 2 * b);
  return (-b - 6 * c) * t * t * t + (6 * b + 30 * c) * t * t + (-12 * b - 48 * c) * t + (8 * b + 24 * c);
}

/* A tabulated filter, unnormalised (negative in the lobes of the last three), at x in
 * [-radius, radius]: the windowed Gaussian, the four-term Blackman-Harris window across
 * the whole width, the cubics over it, or Lanczos' windowed sinc. */
static double tabulated(filter_kind kind, double x, double radius) {
  if (kind == FILTER_MITCHELL) return cubic(1.0 / 3, 1.0 / 3, fabs(2 * x / radius));
  if (kind == FILTER_CATMULL_ROM) return cubic(0, 0.5, fabs(2 * x / radius));
  if (kind == FILTER_LANCZOS) {
    double t = M_PI * x;
    return fabs(t) < 1e-6 ? 1 : sin(t) * sin(t / radius) / (t * t / radius);
  }
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
  f->weight = 1;
  if (f->kind != FILTER_BOX && f->kind != FILTER_TENT) {
    double sum = 0, signed_sum = 0, step = 2.0 * f->radius / FILTER_BINS, acc[FILTER_BINS + 1];
    acc[0] = 0;
    for (int i = 0; i < FILTER_BINS; i++) {
      double v = tabulated(f->kind, -f->radius + (i + 0.5) * step, f->radius);
      f->neg[i] = v < 0;
      signed_sum += v;
      acc[i + 1] = (sum += fabs(v));
    }
    for (int i = 0; i <= FILTER_BINS; i++) f->cdf[i] = (float)(acc[i] / sum);
    f->cdf[FILTER_BINS] = 1;
    f->weight = (float)(sum / signed_sum);
  }
  return 0;
}

float pixel_filter_pdf(const pixel_filter *f, float x) {
  float r = f->radius, ax = fabsf(x);
  if (!(ax <= r)) return 0;
  if (f->kind == FILTER_BOX) return 0.5f / r;
  if (f->kind == FILTER_TENT) return (1 - ax / r) / r;
  int i = (int)((x + r) / (2 * r) * FILTER_BINS);
  i = i < 0 ? 0 : i >= FILTER_BINS ? FILTER_BINS - 1 : i;
  return (f->cdf[i + 1] - f->cdf[i]) * FILTER_BINS / (2 * r);
}

float pixel_filter_sample(const pixel_filter *f, float u, float *wt) {
  float r = f->radius;
  if (wt) *wt = 1;
  if (f->kind == FILTER_BOX) return (2 * u - 1) * r;
  if (f->kind == FILTER_TENT) return u < 0.5f ? r * (sqrtf(2 * u) - 1) : r * (1 - sqrtf(2 - 2 * u));
  int lo = 0, hi = FILTER_BINS; /* the bin with cdf[lo] <= u < cdf[lo + 1] */
  while (hi - lo > 1) {
    int m = (lo + hi) / 2;
    if (f->cdf[m] <= u) lo = m;
    else hi = m;
  }
  if (wt) *wt = f->neg[lo] ? -f->weight : f->weight;
  float w = f->cdf[lo + 1] - f->cdf[lo], t = w > 0 ? fminf((u - f->cdf[lo]) / w, 1.0f) : 0.5f;
  return -r + ((float)lo + t) * (2 * r / FILTER_BINS);
}
