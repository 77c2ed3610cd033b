/* microfacet.h — owns the isotropic microfacet distributions, in the local frame (z =
 * normal):
 * - Trowbridge-Reitz (GGX): D(wm) = 1 / (pi a^2 cos^4 (1 + tan^2/a^2)^2), Smith
 *   Lambda(w) = (sqrt(1 + a^2 tan^2) - 1)/2, sampled by visible normals (Heitz 2018,
 *   "Sampling the GGX distribution of visible normals"), whose density is
 *   D_wo(wm) = G1(wo) / |cos wo| * D(wm) * max(0, wo . wm);
 * - Beckmann: D(wm) = exp(-tan^2/a^2) / (pi a^2 cos^4), Smith Lambda(w) = (erf(b) - 1)/2 +
 *   exp(-b^2) / (2 b sqrt(pi)) with b = 1 / (a tan) (Walter et al. 2007), sampled by the
 *   whole distribution, tan^2 = -a^2 ln(1 - u), density D(wm) cos(wm); a normal facing
 *   away from wo gives a direction whose density and value are 0 (a lost sample).
 * Both use the height-correlated G = 1 / (1 + Lambda(wo) + Lambda(wi)). The mf_ functions
 * choose by `beck`. */
#ifndef VALO_MICROFACET_H
#define VALO_MICROFACET_H
#include "core/vec.h"

static inline float ggx_tan2(vec3 w) { float c2 = w.z * w.z; return fmaxf(0.0f, 1 - c2) / c2; }

static inline float ggx_D(float a, vec3 wm) {
  float c2 = wm.z * wm.z;
  if (!(c2 > 0)) return 0;
  float t2 = fmaxf(0.0f, 1 - c2) / c2;
  float e = 1 + t2 / (a * a);
  return 1 / (PI_F * a * a * c2 * c2 * e * e);
}
static inline float ggx_lambda(float a, vec3 w) {
  float t2 = ggx_tan2(w);
  if (!isfinite(t2)) return 0;
  return (sqrtf(1 + a * a * t2) - 1) * 0.5f;
}
static inline float ggx_G1(float a, vec3 w) { return 1 / (1 + ggx_lambda(a, w)); }
static inline float ggx_G(float a, vec3 wo, vec3 wi) { return 1 / (1 + ggx_lambda(a, wo) + ggx_lambda(a, wi)); }
/* Density of visible normal wm seen from w. */
static inline float ggx_D_visible(float a, vec3 w, vec3 wm) {
  float c = fabsf(w.z);
  if (!(c > 0)) return 0;
  return ggx_G1(a, w) / c * ggx_D(a, wm) * fabsf(v3_dot(w, wm));
}
/* Samples a visible normal for w (either hemisphere: w is mirrored to +z first). */
static inline vec3 ggx_sample_visible(float a, vec3 w, float u1, float u2) {
  vec3 wh = v3_norm(v3(a * w.x, a * w.y, w.z));
  if (wh.z < 0) wh = v3_neg(wh);
  vec3 t1 = wh.z < 0.99999f ? v3_norm(v3_cross(v3(0, 0, 1), wh)) : v3(1, 0, 0);
  vec3 t2 = v3_cross(wh, t1);
  float r = sqrtf(u1), phi = 2 * PI_F * u2;
  float px = r * cosf(phi), py = r * sinf(phi);
  float h = sqrtf(fmaxf(0.0f, 1 - px * px));
  float s = 0.5f * (1 + wh.z);
  py = (1 - s) * h + s * py;
  float pz = sqrtf(fmaxf(0.0f, 1 - px * px - py * py));
  vec3 nh = v3_add(v3_add(v3_scale(t1, px), v3_scale(t2, py)), v3_scale(wh, pz));
  return v3_norm(v3(a * nh.x, a * nh.y, fmaxf(1e-6f, nh.z)));
}

static inline float beckmann_D(float a, vec3 wm) {
  float c2 = wm.z * wm.z;
  if (!(c2 > 0)) return 0;
  float t2 = fmaxf(0.0f, 1 - c2) / c2;
  return expf(-t2 / (a * a)) / (PI_F * a * a * c2 * c2);
}
static inline float beckmann_lambda(float a, vec3 w) {
  float t2 = ggx_tan2(w);
  if (!isfinite(t2) || !(t2 > 0)) return 0;
  float b = 1 / (a * sqrtf(t2));
  if (b > 6) return 0; /* below 1e-17 */
  return 0.5f * (erff(b) - 1) + expf(-b * b) / (2 * b * sqrtf(PI_F));
}
static inline vec3 beckmann_sample(float a, float u1, float u2) {
  float t2 = -a * a * logf(fmaxf(1 - u1, 1e-30f));
  float c = 1 / sqrtf(1 + t2), s = sqrtf(fmaxf(0.0f, 1 - c * c)), phi = 2 * PI_F * u2;
  return v3(s * cosf(phi), s * sinf(phi), fmaxf(c, 1e-6f));
}

static inline float mf_D(int beck, float a, vec3 wm) { return beck ? beckmann_D(a, wm) : ggx_D(a, wm); }
static inline float mf_G(int beck, float a, vec3 wo, vec3 wi) {
  return beck ? 1 / (1 + beckmann_lambda(a, wo) + beckmann_lambda(a, wi)) : ggx_G(a, wo, wi);
}
/* The density of sampled normal wm (for direction w). */
static inline float mf_pdf_m(int beck, float a, vec3 w, vec3 wm) {
  return beck ? beckmann_D(a, wm) * fabsf(wm.z) : ggx_D_visible(a, w, wm);
}
static inline vec3 mf_sample(int beck, float a, vec3 w, float u1, float u2) {
  return beck ? beckmann_sample(a, u1, u2) : ggx_sample_visible(a, w, u1, u2);
}
#endif
