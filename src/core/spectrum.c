/* spectrum.c — see spectrum.h. */
#include "core/spectrum.h"
#include <pthread.h>
#include <string.h>

static float lobe(float l, float mu, float s1, float s2) {
  float t = (l - mu) / (l < mu ? s1 : s2);
  return expf(-0.5f * t * t);
}
void cie_xyz(float l, float *x, float *y, float *z) {
  *x = 1.056f * lobe(l, 599.8f, 37.9f, 31.0f) + 0.362f * lobe(l, 442.0f, 16.0f, 26.7f) - 0.065f * lobe(l, 501.1f, 20.4f, 26.2f);
  *y = 0.821f * lobe(l, 568.8f, 46.9f, 40.5f) + 0.286f * lobe(l, 530.9f, 16.3f, 31.1f);
  *z = 1.217f * lobe(l, 437.0f, 11.8f, 36.0f) + 0.681f * lobe(l, 459.0f, 26.0f, 13.8f);
}

static const float XYZ_TO_SRGB[3][3] = {{3.2404542f, -1.5371385f, -0.4985314f},
                                        {-0.9692660f, 1.8760108f, 0.0415560f},
                                        {0.0556434f, -0.2040259f, 1.0572252f}};

static float smooth01(float t) { t = t < 0 ? 0 : (t > 1 ? 1 : t); return t * t * (3 - 2 * t); }
/* Three bands: blue below ~490 nm, green to ~590 nm, red above; they sum to 1. */
static void basis(float l, float b[3]) {
  float e1 = smooth01((l - 470) / 40), e2 = smooth01((l - 570) / 40);
  b[0] = e2;          /* red */
  b[1] = e1 - e2;     /* green */
  b[2] = 1 - e1;      /* blue */
}

static float g_rgb_to_basis[3][3]; /* A: rgb -> basis coefficients */
static float g_white[3];           /* W: per-channel white balance (flat spectrum -> 1,1,1) */
static float g_y_integral;
static pthread_once_t g_once = PTHREAD_ONCE_INIT;

static void inv3(const double m[3][3], double o[3][3]) {
  double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  double id = 1 / det;
  o[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) * id;
  o[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * id;
  o[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * id;
  o[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) * id;
  o[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * id;
  o[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * id;
  o[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) * id;
  o[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * id;
  o[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * id;
}

static void spectrum_setup(void) {
  /* C[i][j] = integral of cmf_i * basis_j; the y integral normalises. */
  double C[3][3] = {{0}}, yint = 0;
  for (float l = LAMBDA_MIN + 0.25f; l < LAMBDA_MAX; l += 0.5f) {
    float x, y, z, b[3];
    cie_xyz(l, &x, &y, &z);
    basis(l, b);
    for (int j = 0; j < 3; j++) { C[0][j] += x * b[j] * 0.5; C[1][j] += y * b[j] * 0.5; C[2][j] += z * b[j] * 0.5; }
    yint += y * 0.5;
  }
  g_y_integral = (float)yint;
  double MC[3][3];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      MC[i][j] = 0;
      for (int k = 0; k < 3; k++) MC[i][j] += XYZ_TO_SRGB[i][k] * C[k][j] / yint;
    }
  /* White balance so that the flat spectrum (coefficients 1,1,1) reads (1,1,1). */
  for (int i = 0; i < 3; i++) {
    double s = MC[i][0] + MC[i][1] + MC[i][2];
    g_white[i] = (float)(1 / s);
    for (int j = 0; j < 3; j++) MC[i][j] /= s;
  }
  double A[3][3];
  inv3(MC, A);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) g_rgb_to_basis[i][j] = (float)A[i][j];
}

wavelengths wavelengths_sample(float u) {
  pthread_once(&g_once, spectrum_setup);
  wavelengths w;
  float range = LAMBDA_MAX - LAMBDA_MIN, hero = LAMBDA_MIN + u * range;
  for (int i = 0; i < N_LAMBDA; i++) {
    float l = hero + i * range / N_LAMBDA;
    if (l >= LAMBDA_MAX) l -= range;
    w.lambda[i] = l;
    w.weight[i] = range; /* 1 / pdf, pdf = 1 / range */
  }
  return w;
}

void wavelengths_terminate_secondary(wavelengths *w) {
  if (w->weight[1] == 0) return;
  for (int i = 1; i < N_LAMBDA; i++) w->weight[i] = 0;
  w->weight[0] *= N_LAMBDA;
}

spec4 spec_from_rgb(rgb c, const wavelengths *w) {
  float coef[3];
  const float in[3] = {c.r, c.g, c.b};
  for (int i = 0; i < 3; i++) coef[i] = g_rgb_to_basis[i][0] * in[0] + g_rgb_to_basis[i][1] * in[1] + g_rgb_to_basis[i][2] * in[2];
  spec4 s;
  for (int k = 0; k < N_LAMBDA; k++) {
    float b[3];
    basis(w->lambda[k], b);
    float v = coef[0] * b[0] + coef[1] * b[1] + coef[2] * b[2];
    s.v[k] = v > 0 ? v : 0;
  }
  return s;
}

rgb spec_to_rgb(spec4 L, const wavelengths *w) {
  float X = 0, Y = 0, Z = 0;
  for (int k = 0; k < N_LAMBDA; k++) {
    if (w->weight[k] == 0) continue;
    float x, y, z;
    cie_xyz(w->lambda[k], &x, &y, &z);
    float f = L.v[k] * w->weight[k] / (N_LAMBDA * g_y_integral);
    X += x * f; Y += y * f; Z += z * f;
  }
  rgb o;
  o.r = g_white[0] * (XYZ_TO_SRGB[0][0] * X + XYZ_TO_SRGB[0][1] * Y + XYZ_TO_SRGB[0][2] * Z);
  o.g = g_white[1] * (XYZ_TO_SRGB[1][0] * X + XYZ_TO_SRGB[1][1] * Y + XYZ_TO_SRGB[1][2] * Z);
  o.b = g_white[2] * (XYZ_TO_SRGB[2][0] * X + XYZ_TO_SRGB[2][1] * Y + XYZ_TO_SRGB[2][2] * Z);
  /* XYZ -> sRGB can leave the gamut for spectral colours (a prism's rainbow): clamp the
   * negative lobes, as a camera's colour matrix would. */
  o.r = o.r > 0 ? o.r : 0; o.g = o.g > 0 ? o.g : 0; o.b = o.b > 0 ? o.b : 0;
  return o;
}

float tab_eval(const float *nm, const float *v, int n, float l) {
  if (l <= nm[0]) return v[0];
  if (l >= nm[n - 1]) return v[n - 1];
  int lo = 0, hi = n - 1; /* nm[lo] < l < nm[hi] */
  while (hi - lo > 1) {
    int mid = (lo + hi) / 2;
    if (nm[mid] <= l) lo = mid; else hi = mid;
  }
  float t = (l - nm[lo]) / (nm[hi] - nm[lo]);
  return v[lo] + t * (v[hi] - v[lo]);
}

rgb tab_to_rgb(const float *nm, const float *v, int n) {
  pthread_once(&g_once, spectrum_setup);
  double X = 0, Y = 0, Z = 0;
  for (float l = LAMBDA_MIN + 0.25f; l < LAMBDA_MAX; l += 0.5f) {
    float x, y, z, f = tab_eval(nm, v, n, l);
    cie_xyz(l, &x, &y, &z);
    X += x * f; Y += y * f; Z += z * f;
  }
  float c[3];
  for (int i = 0; i < 3; i++)
    c[i] = (float)(g_white[i] * (XYZ_TO_SRGB[i][0] * X + XYZ_TO_SRGB[i][1] * Y + XYZ_TO_SRGB[i][2] * Z) * 0.5 / g_y_integral);
  return c3(c[0], c[1], c[2]);
}

/* CIE standard illuminant D65 (CIE 15), every 10 nm from 360 to 830 nm; the CIE's 1 nm
 * values lie on the straight lines between these. */
static const float D65_10NM[48] = {46.6383f, 52.0891f, 49.9755f, 54.6482f, 82.7549f, 91.486f, 93.4318f, 86.6823f, 104.865f, 117.008f,
                                   117.812f, 114.861f, 115.923f, 108.811f, 109.354f, 107.802f, 104.79f, 107.689f, 104.405f, 104.046f,
                                   100.0f, 96.3342f, 95.788f, 88.6856f, 90.0062f, 89.5991f, 87.6987f, 83.2886f, 83.6992f, 80.0268f,
                                   80.2146f, 82.2778f, 78.2842f, 69.7213f, 71.6091f, 74.349f, 61.604f, 69.8856f, 75.087f, 63.5927f,
                                   46.4182f, 66.8054f, 63.3828f, 64.304f, 59.4519f, 51.959f, 57.4406f, 60.3125f};
static float d65(float l) {
  float t = (l - 360) / 10;
  if (t <= 0) return D65_10NM[0];
  if (t >= 47) return D65_10NM[47];
  int i = (int)t;
  return D65_10NM[i] + (t - i) * (D65_10NM[i + 1] - D65_10NM[i]);
}

rgb spectrum_list_to_rgb(const float *nm, const float *v, int n, int emitter) {
  double X = 0, Y = 0, Z = 0, norm = 0;
  for (float l = 360.25f; l < 830; l += 0.5f) {
    float x, y, z, w = emitter ? 1 : d65(l);
    cie_xyz(l, &x, &y, &z);
    norm += (double)y * w;
    if (l < nm[0] || l > nm[n - 1]) continue;
    float f = tab_eval(nm, v, n, l) * w;
    X += (double)x * f; Y += (double)y * f; Z += (double)z * f;
  }
  float c[3];
  for (int i = 0; i < 3; i++) c[i] = (float)((XYZ_TO_SRGB[i][0] * X + XYZ_TO_SRGB[i][1] * Y + XYZ_TO_SRGB[i][2] * Z) / norm);
  return c3(c[0], c[1], c[2]);
}

int dispersion_parse(const char *name, dispersion *d) {
  static const struct { const char *n; dispersion d; } t[] = {
      {"fused_silica", DISP_FUSED_SILICA}, {"sapphire", DISP_SAPPHIRE}, {"water", DISP_WATER}, {"cauchy_glass", DISP_CAUCHY_GLASS},
      {"dense_flint", DISP_DENSE_FLINT}};
  for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
    if (!strcmp(name, t[i].n)) { *d = t[i].d; return 0; }
  return -1;
}

/* Sellmeier n^2 = 1 + sum A_j l^2 / (l^2 - B_j^2), B_j in micrometres (thesis table 2.1;
 * dense flint: Schott's published SF11 coefficients, n_d = 1.7847, Abbe number 25.8);
 * Cauchy n = A + B / l^2 with the thesis' fused-silica fit. */
float dispersion_ior(dispersion d, float lambda_nm) {
  static const float silica[2][3] = {{0.66347f, 0.44065f, 0.89901f}, {0.06652f, 0.11502f, 9.9032f}};
  static const float sapphire[2][3] = {{0.53148f, 1.55060f, 5.28958f}, {0.02179f, 0.10335f, 17.9393f}};
  static const float flint[2][3] = {{1.73759695f, 0.313747346f, 1.89878101f}, {0.114842f, 0.249613f, 12.459385f}};
  static const float water[2][4] = {{0.5689f, 0.17197f, 0.02063f, 0.11240f}, {0.07149f, 0.13510f, 0.16199f, 3.26727f}};
  float l = lambda_nm * 1e-3f, l2 = l * l, n2 = 1;
  switch (d) {
  case DISP_NONE: return 1.5f;
  case DISP_FUSED_SILICA: for (int j = 0; j < 3; j++) n2 += silica[0][j] * l2 / (l2 - silica[1][j] * silica[1][j]); break;
  case DISP_SAPPHIRE: for (int j = 0; j < 3; j++) n2 += sapphire[0][j] * l2 / (l2 - sapphire[1][j] * sapphire[1][j]); break;
  case DISP_WATER: for (int j = 0; j < 4; j++) n2 += water[0][j] * l2 / (l2 - water[1][j] * water[1][j]); break;
  case DISP_CAUCHY_GLASS: return 1.4481f + 0.00354f / l2;
  case DISP_DENSE_FLINT: for (int j = 0; j < 3; j++) n2 += flint[0][j] * l2 / (l2 - flint[1][j] * flint[1][j]); break;
  }
  return sqrtf(n2);
}
