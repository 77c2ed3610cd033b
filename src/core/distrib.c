/* distrib.c — see distrib.h. */
#include "core/distrib.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

int distrib1d_init(distrib1d *d, const float *f, uint32_t n) {
  memset(d, 0, sizeof *d);
  if (n == 0) return -1;
  d->func = malloc(n * sizeof(float));
  d->cdf = malloc((n + 1) * sizeof(float));
  if (!d->func || !d->cdf) { distrib1d_free(d); return -1; }
  d->n = n;
  double acc = 0;
  d->cdf[0] = 0;
  for (uint32_t i = 0; i < n; i++) {
    float v = f[i];
    d->func[i] = (v >= 0 && isfinite(v)) ? v : 0;
    acc += d->func[i] / (double)n;
    d->cdf[i + 1] = (float)acc;
  }
  d->integral = (float)acc;
  if (!(acc > 0)) { /* all zero: uniform */
    for (uint32_t i = 0; i <= n; i++) d->cdf[i] = (float)i / (float)n;
  } else {
    for (uint32_t i = 1; i <= n; i++) d->cdf[i] = (float)(d->cdf[i] / acc);
  }
  d->cdf[n] = 1;
  return 0;
}

void distrib1d_free(distrib1d *d) { free(d->func); free(d->cdf); d->func = d->cdf = NULL; d->n = 0; }

float distrib1d_sample(const distrib1d *d, float u, float *pdf, uint32_t *bin) {
  /* Largest i with cdf[i] <= u. */
  uint32_t lo = 0, hi = d->n;
  while (hi - lo > 1) {
    uint32_t mid = (lo + hi) / 2;
    if (d->cdf[mid] <= u) lo = mid; else hi = mid;
  }
  float width = d->cdf[lo + 1] - d->cdf[lo];
  float du = width > 0 ? (u - d->cdf[lo]) / width : 0.5f;
  if (pdf) *pdf = d->integral > 0 ? d->func[lo] / d->integral : 1.0f;
  if (bin) *bin = lo;
  float x = ((float)lo + du) / (float)d->n;
  return x < 1.0f ? x : 0x1.fffffep-1f;
}

int distrib2d_init(distrib2d *d, const float *f, uint32_t nu, uint32_t nv) {
  memset(d, 0, sizeof *d);
  d->rows = calloc(nv, sizeof *d->rows);
  float *marg = malloc(nv * sizeof(float));
  if (!d->rows || !marg) { free(marg); distrib2d_free(d); return -1; }
  d->nu = nu; d->nv = nv;
  for (uint32_t v = 0; v < nv; v++) {
    if (distrib1d_init(&d->rows[v], f + (size_t)v * nu, nu)) { free(marg); distrib2d_free(d); return -1; }
    marg[v] = d->rows[v].integral;
  }
  int rc = distrib1d_init(&d->marginal, marg, nv);
  free(marg);
  if (rc) { distrib2d_free(d); return -1; }
  return 0;
}

void distrib2d_free(distrib2d *d) {
  if (d->rows)
    for (uint32_t v = 0; v < d->nv; v++) distrib1d_free(&d->rows[v]);
  free(d->rows);
  d->rows = NULL;
  distrib1d_free(&d->marginal);
}

void distrib2d_sample(const distrib2d *d, float u1, float u2, float *u, float *v, float *pdf) {
  float pv, pu;
  uint32_t row;
  *v = distrib1d_sample(&d->marginal, u2, &pv, &row);
  *u = distrib1d_sample(&d->rows[row], u1, &pu, NULL);
  *pdf = pu * pv;
}

float distrib2d_pdf(const distrib2d *d, float u, float v) {
  int iu = (int)(u * (float)d->nu), iv = (int)(v * (float)d->nv);
  if (iu < 0) iu = 0;
  if (iu >= (int)d->nu) iu = (int)d->nu - 1;
  if (iv < 0) iv = 0;
  if (iv >= (int)d->nv) iv = (int)d->nv - 1;
  if (!(d->marginal.integral > 0)) return 1.0f;
  return d->rows[iv].func[iu] / d->marginal.integral;
}
