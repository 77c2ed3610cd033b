/* distrib.c — see distrib.h. */
#include "core/distrib.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

void bilin2d_free(bilin2d *d) {
  free(d->x); free(d->y); free(d->f); free(d->cum); free(d->ycum);
  memset(d, 0, sizeof *d);
}

static int positions_ok(const float *p, uint32_t n) {
  if (n < 2 || p[0] != 0 || p[n - 1] != 1) return 0;
  for (uint32_t i = 1; i < n; i++)
    if (!(p[i] >= p[i - 1])) return 0;
  return 1;
}

int bilin2d_init(bilin2d *d, const float *x, uint32_t nx, const float *y, uint32_t ny, const float *f) {
  memset(d, 0, sizeof *d);
  if (!positions_ok(x, nx) || !positions_ok(y, ny)) return -1;
  size_t n = (size_t)nx * ny;
  d->x = malloc(nx * sizeof(float));
  d->y = malloc(ny * sizeof(float));
  d->f = malloc(n * sizeof(float));
  d->cum = malloc(n * sizeof(float));
  d->ycum = malloc(ny * sizeof(float));
  if (!d->x || !d->y || !d->f || !d->cum || !d->ycum) { bilin2d_free(d); return -1; }
  d->nx = nx; d->ny = ny;
  memcpy(d->x, x, nx * sizeof(float));
  memcpy(d->y, y, ny * sizeof(float));
  int any = 0;
  for (size_t i = 0; i < n; i++) {
    d->f[i] = f[i] >= 0 && isfinite(f[i]) ? f[i] : 0;
    any |= d->f[i] > 0;
  }
  if (!any)
    for (size_t i = 0; i < n; i++) d->f[i] = 1;
  double yacc = 0, prev_row = 0;
  for (uint32_t j = 0; j < ny; j++) {
    const float *fr = d->f + (size_t)j * nx;
    float *cr = d->cum + (size_t)j * nx;
    double acc = 0;
    cr[0] = 0;
    for (uint32_t i = 1; i < nx; i++) {
      acc += 0.5 * ((double)fr[i - 1] + fr[i]) * ((double)x[i] - x[i - 1]);
      cr[i] = (float)acc;
    }
    if (j > 0) yacc += 0.5 * (prev_row + acc) * ((double)y[j] - y[j - 1]);
    d->ycum[j] = (float)yacc;
    prev_row = acc;
  }
  d->total = (float)yacc;
  if (!(yacc > 0)) { bilin2d_free(d); return -1; } /* e.g. every positive value on a zero-width row */
  return 0;
}

/* t in [0,1] with integral_0^t of the line from f0 to f1 equal to s times its whole
 * integral: the root of f0 t + (f1 - f0) t^2 / 2 = s (f0 + f1) / 2 in the form that
 * stays exact when f1 = f0 or f0 = 0. */
static float solve_linear(float f0, float f1, float s) {
  float den = f0 + sqrtf(fmaxf(f0 * f0 * (1 - s) + f1 * f1 * s, 0));
  float t = den > 0 ? s * (f0 + f1) / den : s;
  return t < 0 ? 0 : (t > 1 ? 1 : t);
}

/* Largest i in [0, n-2] with c(i) <= target for a non-decreasing c. */
static uint32_t find_cell(const float *a, const float *b, float wa, float wb, uint32_t n, float target) {
  uint32_t lo = 0, hi = n - 1;
  while (hi - lo > 1) {
    uint32_t mid = (lo + hi) / 2;
    float c = wa * a[mid] + (b ? wb * b[mid] : 0);
    if (c <= target) lo = mid; else hi = mid;
  }
  return lo;
}

void bilin2d_sample(const bilin2d *d, float u1, float u2, float *u, float *v, float *pdf) {
  uint32_t nx = d->nx;
  /* v: the marginal, piecewise linear between the rows' integrals. */
  float target = u2 * d->total;
  uint32_t j = find_cell(d->ycum, NULL, 1, 0, d->ny, target);
  float r0 = d->cum[(size_t)j * nx + nx - 1], r1 = d->cum[(size_t)(j + 1) * nx + nx - 1];
  float m = d->ycum[j + 1] - d->ycum[j];
  float s = m > 0 ? (target - d->ycum[j]) / m : 0.5f;
  float t = solve_linear(r0, r1, s < 0 ? 0 : (s > 1 ? 1 : s));
  *v = d->y[j] + t * (d->y[j + 1] - d->y[j]);
  /* u: the conditional at that v, the rows' functions blended by t. */
  const float *c0 = d->cum + (size_t)j * nx, *c1 = c0 + nx, *f0 = d->f + (size_t)j * nx, *f1 = f0 + nx;
  float rt = (1 - t) * c0[nx - 1] + t * c1[nx - 1];
  float tu = u1 * rt;
  uint32_t i = find_cell(c0, c1, 1 - t, t, nx, tu);
  float g0 = (1 - t) * f0[i] + t * f1[i], g1 = (1 - t) * f0[i + 1] + t * f1[i + 1];
  float ci = (1 - t) * c0[i] + t * c1[i], mi = 0.5f * (g0 + g1) * (d->x[i + 1] - d->x[i]);
  float su = mi > 0 ? (tu - ci) / mi : 0.5f;
  float tau = solve_linear(g0, g1, su < 0 ? 0 : (su > 1 ? 1 : su));
  *u = d->x[i] + tau * (d->x[i + 1] - d->x[i]);
  *pdf = ((1 - tau) * g0 + tau * g1) / d->total;
}

float bilin2d_pdf(const bilin2d *d, float u, float v) {
  if (!(u >= 0 && u <= 1 && v >= 0 && v <= 1)) return 0;
  uint32_t i = find_cell(d->x, NULL, 1, 0, d->nx, u), j = find_cell(d->y, NULL, 1, 0, d->ny, v);
  float wx = d->x[i + 1] - d->x[i], wy = d->y[j + 1] - d->y[j];
  float a = wx > 0 ? (u - d->x[i]) / wx : 0, b = wy > 0 ? (v - d->y[j]) / wy : 0;
  const float *f0 = d->f + (size_t)j * d->nx, *f1 = f0 + d->nx;
  float top = (1 - a) * f0[i] + a * f0[i + 1], bot = (1 - a) * f1[i] + a * f1[i + 1];
  return ((1 - b) * top + b * bot) / d->total;
}
