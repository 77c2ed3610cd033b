/* alias.c — Vose's alias method (see alias.h). */
#include "core/alias.h"
#include <stdlib.h>
#include <math.h>

int alias_build(alias_table *t, const float *w, uint32_t n) {
  t->bins = NULL; t->n = 0;
  if (n == 0) return -1;
  double sum = 0;
  for (uint32_t i = 0; i < n; i++) {
    if (!(w[i] >= 0) || !isfinite(w[i])) return -1;
    sum += w[i];
  }
  if (!(sum > 0)) return -1;
  alias_bin *bins = calloc(n, sizeof *bins);
  uint32_t *small = malloc(n * sizeof *small), *large = malloc(n * sizeof *large);
  double *scaled = malloc(n * sizeof *scaled);
  if (!bins || !small || !large || !scaled) { free(bins); free(small); free(large); free(scaled); return -1; }
  uint32_t ns = 0, nl = 0;
  for (uint32_t i = 0; i < n; i++) {
    bins[i].p = (float)(w[i] / sum);
    scaled[i] = w[i] / sum * n;
    if (scaled[i] < 1.0) small[ns++] = i; else large[nl++] = i;
  }
  while (ns && nl) {
    uint32_t s = small[--ns], l = large[--nl];
    bins[s].q = (float)scaled[s];
    bins[s].alias = l;
    scaled[l] = (scaled[l] + scaled[s]) - 1.0;
    if (scaled[l] < 1.0) small[ns++] = l; else large[nl++] = l;
  }
  while (nl) { uint32_t l = large[--nl]; bins[l].q = 1.0f; bins[l].alias = l; }
  while (ns) { uint32_t s = small[--ns]; bins[s].q = 1.0f; bins[s].alias = s; }
  free(small); free(large); free(scaled);
  t->bins = bins; t->n = n;
  return 0;
}

void alias_free(alias_table *t) { free(t->bins); t->bins = NULL; t->n = 0; }

uint32_t alias_sample(const alias_table *t, float u, float *pmf) {
  float x = u * (float)t->n;
  uint32_t i = (uint32_t)x;
  if (i >= t->n) i = t->n - 1;
  float up = x - (float)i;
  uint32_t r = up < t->bins[i].q ? i : t->bins[i].alias;
  if (pmf) *pmf = t->bins[r].p;
  return r;
}

uint32_t alias_sample_rest(const alias_table *t, float u, float *pmf, float *rest) {
  double x = (double)u * t->n;
  uint32_t i = (uint32_t)x;
  if (i >= t->n) i = t->n - 1;
  double up = x - i, q = t->bins[i].q;
  uint32_t r = up < q ? i : t->bins[i].alias;
  double f = up < q ? up / q : (up - q) / (1 - q);
  *rest = (float)fmin(fmax(f, 0.0), 0x1.fffffep-1);
  if (pmf) *pmf = t->bins[r].p;
  return r;
}
