/* sheen.c — see sheen.h. */
#include "material/sheen.h"
#include <math.h>

float sheen_alpha(float roughness) { return fminf(fmaxf(roughness, 0.07f), 1.0f); }

/* The exponent's fit l(x) of the Charlie visibility, between its two fitted roughnesses. */
static double fit_l(double x, double alpha) {
  double t = (1 - alpha) * (1 - alpha);
  double a = 21.5473 + (25.3245 - 21.5473) * t, b = 3.82987 + (3.32435 - 3.82987) * t, c = 0.19823 + (0.16801 - 0.19823) * t;
  double d = -1.97760 + (-1.27393 + 1.97760) * t, e = -4.32054 + (-4.85967 + 4.32054) * t;
  return a / (1 + b * pow(x, c)) + d * x + e;
}
static double lambda(double cos_t, double alpha) {
  return cos_t < 0.5 ? exp(fit_l(cos_t, alpha)) : exp(2 * fit_l(0.5, alpha) - fit_l(1 - cos_t, alpha));
}

float sheen_eval(float alpha, float cos_o, float cos_i, float cos_h) {
  if (!(cos_o > 0 && cos_i > 0)) return 0;
  double inv = 1.0 / alpha, sin2 = fmax(0.0, 1.0 - (double)cos_h * cos_h);
  double D = (2 + inv) * pow(sin2, 0.5 * inv) / (2 * M_PI);
  double V = 1 / ((1 + lambda(cos_o, alpha) + lambda(cos_i, alpha)) * 4 * (double)cos_o * cos_i);
  return (float)(D * V);
}

void sheen_prepare(material *m) {
  double a = sheen_alpha(m->sheen_roughness), inv = 1 / a, norm = (2 + inv) / (2 * M_PI);
  enum { NT = 64, NP = 128 };
  double cp[NP], sp[NP];
  for (int j = 0; j < NP; j++) { /* phi in [0, pi], doubled by symmetry */
    cp[j] = cos(M_PI * (j + 0.5) / NP);
    sp[j] = sin(M_PI * (j + 0.5) / NP);
  }
  for (int k = 0; k < SHEEN_RES; k++) {
    double mu = fmax((double)k / (SHEEN_RES - 1), 1e-4), so = sqrt(1 - mu * mu), lo = lambda(mu, a), sum = 0;
    for (int i = 0; i < NT; i++) { /* cos_i uniform: d(omega) cos_i = d(cos_i) d(phi) cos_i */
      double ci = (i + 0.5) / NT, si = sqrt(1 - ci * ci), d = 0;
      for (int j = 0; j < NP; j++) {
        double hx = si * cp[j] + so, hy = si * sp[j], hz = ci + mu, h2 = hx * hx + hy * hy + hz * hz;
        d += pow(fmax(0.0, 1 - hz * hz / h2), 0.5 * inv); /* D's sin(h)^(1/a), as sheen_eval */
      }
      sum += norm * d / ((1 + lo + lambda(ci, a)) * 4 * mu * ci) * ci;
    }
    m->sheen_E[k] = (float)fmin(sum * (1.0 / NT) * (2 * M_PI / NP), 1.0);
  }
}

float sheen_albedo(const float *E, float cos_t) {
  float x = fminf(fmaxf(cos_t, 0), 1) * (SHEEN_RES - 1);
  int i = (int)x;
  if (i >= SHEEN_RES - 1) return E[SHEEN_RES - 1];
  float w = x - (float)i;
  return (1 - w) * E[i] + w * E[i + 1];
}
