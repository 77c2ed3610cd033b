/* microfacet.h — owns the microfacet distributions, in the local frame (z = normal),
 * isotropic (below) and anisotropic (the mfa_ functions at the end):
 * - Trowbridge-Reitz (GGX): D(wm) = 1 / (pi a^2 cos^4 (1 + tan^2/a^2)^2), Smith
 *   Lambda(w) = (sqrt(1 + a^2 tan^2) - 1)/2, sampled by visible normals (Heitz 2018,
 *   "Sampling the GGX distribution of visible normals"), whose density is
 *   D_wo(wm) = G1(wo) / |cos wo| * D(wm) * max(0, wo . wm);
 * - Beckmann: D(wm) = exp(-tan^2/a^2) / (pi a^2 cos^4), Smith Lambda(w) = (erf(b) - 1)/2 +
 *   exp(-b^2) / (2 b sqrt(pi)) with b = 1 / (a tan) (Walter et al. 2007), also sampled by
 *   visible normals (the same density with its G1): in the stretched frame where a = 1,
 *   the slope along the incident direction's azimuth has the CDF
 *   (1 + erf(x) + tan(t) exp(-x^2) / sqrt(pi)) / (1 + erf(cot t) + tan(t) exp(-cot^2 t) / sqrt(pi)),
 *   inverted by safeguarded Newton steps in erf(x) from a fitted first guess (Jakob 2014,
 *   "An improved visible normal sampling routine for the Beckmann distribution"), the
 *   other slope is a unit Gaussian (erf(y) uniform).
 * Both use the height-correlated G = 1 / (1 + Lambda(wo) + Lambda(wi)), or on request the
 * separable G1(wo) G1(wi) = 1 / ((1 + Lambda(wo)) (1 + Lambda(wi))) that Mitsuba uses. The
 * mf_ functions choose by `beck` (and mf_G by `sep`). */
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
/* The inverse error function on (-1, 1): Giles' single-precision polynomials (2010),
 * relative error below 4e-7. */
static inline float erfinv_f(float x) {
  x = clampf(x, -0.99999994f, 0.99999994f);
  float w = -logf((1 - x) * (1 + x)), p;
  if (w < 5) {
    w -= 2.5f;
    p = 2.81022636e-08f;
    p = 3.43273939e-07f + p * w; p = -3.5233877e-06f + p * w; p = -4.39150654e-06f + p * w; p = 0.00021858087f + p * w;
    p = -0.00125372503f + p * w; p = -0.00417768164f + p * w; p = 0.246640727f + p * w; p = 1.50140941f + p * w;
  } else {
    w = sqrtf(w) - 3;
    p = -0.000200214257f;
    p = 0.000100950558f + p * w; p = 0.00134934322f + p * w; p = -0.00367342844f + p * w; p = 0.00573950773f + p * w;
    p = -0.0076224613f + p * w; p = 0.00943887047f + p * w; p = 1.00167406f + p * w; p = 2.83297682f + p * w;
  }
  return p * x;
}
/* Slopes (unit roughness) of a normal visible from a direction at angle theta to +z,
 * azimuth along +x. */
static inline void beckmann_visible_slopes(float theta, float u1, float u2, float *sx, float *sy) {
  const float inv_sqrt_pi = 0.564189584f;
  if (theta < 1e-4f) {
    float r = sqrtf(-logf(fmaxf(1 - u1, 1e-30f))), phi = 2 * PI_F * u2;
    *sx = r * cosf(phi); *sy = r * sinf(phi);
    return;
  }
  float tan_t = tanf(theta), cot_t = 1 / tan_t;
  float lo = -1, hi = erff(cot_t); /* the bracket of b = erf(slope) */
  float norm = 1 / (1 + hi + inv_sqrt_pi * tan_t * expf(-cot_t * cot_t));
  float fit = 1 + theta * (-0.876f + theta * (0.4265f - 0.0594f * theta));
  float b = hi - (1 + hi) * powf(1 - u1, fit);
  for (int it = 0; it < 12; it++) {
    if (!(b >= lo && b <= hi)) b = 0.5f * (lo + hi);
    float x = erfinv_f(b);
    float value = norm * (1 + b + inv_sqrt_pi * tan_t * expf(-x * x)) - u1;
    if (fabsf(value) < 1e-6f) break;
    if (value > 0) hi = b; else lo = b;
    b -= value / (norm * (1 - x * tan_t));
  }
  *sx = erfinv_f(b);
  *sy = erfinv_f(2 * fmaxf(u2, 1e-7f) - 1);
}
/* A visible normal for w (either hemisphere: w is mirrored to +z first). */
static inline vec3 beckmann_sample_visible(float a, vec3 w, float u1, float u2) {
  if (w.z < 0) w = v3_neg(w);
  vec3 ws = v3_norm(v3(a * w.x, a * w.y, w.z)); /* stretched to unit roughness */
  float theta = acosf(clampf(ws.z, -1, 1)), r = sqrtf(ws.x * ws.x + ws.y * ws.y);
  float cp = r > 1e-7f ? ws.x / r : 1, sp = r > 1e-7f ? ws.y / r : 0;
  float sx, sy;
  beckmann_visible_slopes(theta, u1, u2, &sx, &sy);
  float rx = cp * sx - sp * sy, ry = sp * sx + cp * sy; /* turned to w's azimuth */
  return v3_norm(v3(-a * rx, -a * ry, 1));
}
static inline float beckmann_D_visible(float a, vec3 w, vec3 wm) {
  float c = fabsf(w.z);
  if (!(c > 0)) return 0;
  return beckmann_D(a, wm) * fabsf(v3_dot(w, wm)) / (c * (1 + beckmann_lambda(a, w)));
}

static inline float mf_D(int beck, float a, vec3 wm) { return beck ? beckmann_D(a, wm) : ggx_D(a, wm); }
static inline float mf_G(int beck, int sep, float a, vec3 wo, vec3 wi) {
  if (sep) {
    float lo = beck ? beckmann_lambda(a, wo) : ggx_lambda(a, wo), li = beck ? beckmann_lambda(a, wi) : ggx_lambda(a, wi);
    return 1 / ((1 + lo) * (1 + li));
  }
  return beck ? 1 / (1 + beckmann_lambda(a, wo) + beckmann_lambda(a, wi)) : ggx_G(a, wo, wi);
}
/* The density of sampled normal wm (for direction w). */
static inline float mf_pdf_m(int beck, float a, vec3 w, vec3 wm) {
  return beck ? beckmann_D_visible(a, w, wm) : ggx_D_visible(a, w, wm);
}
static inline vec3 mf_sample(int beck, float a, vec3 w, float u1, float u2) {
  return beck ? beckmann_sample_visible(a, w, u1, u2) : ggx_sample_visible(a, w, u1, u2);
}

/* Anisotropic roughness (ax along the frame's s axis, ay along t; Heitz 2014,
 * "Understanding the masking-shadowing function", section 5): both distributions are
 * the isotropic one of unit roughness stretched by (ax, ay), so
 *   GGX D(wm) = 1 / (pi ax ay cos^4 (1 + (x^2/ax^2 + y^2/ay^2)/z^2)^2),
 *   Beckmann D(wm) = exp(-(x^2/ax^2 + y^2/ay^2)/z^2) / (pi ax ay cos^4),
 * Lambda(w) is the isotropic Lambda of the direction's own roughness
 *   a(w) = sqrt((x^2 ax^2 + y^2 ay^2) / (x^2 + y^2)),
 * and visible normals are sampled in the stretched frame and unstretched. The mfa_
 * functions fall back to the isotropic ones, bit for bit, when ax == ay. */
static inline float mf_alpha_dir(float ax, float ay, vec3 w) {
  float s2 = w.x * w.x + w.y * w.y;
  if (!(s2 > 0)) return ax;
  return sqrtf((w.x * w.x * ax * ax + w.y * w.y * ay * ay) / s2);
}
static inline float mfa_D(int beck, float ax, float ay, vec3 wm) {
  if (ax == ay) return mf_D(beck, ax, wm);
  float c2 = wm.z * wm.z;
  if (!(c2 > 0)) return 0;
  float e = (wm.x * wm.x / (ax * ax) + wm.y * wm.y / (ay * ay)) / c2;
  if (beck) return expf(-e) / (PI_F * ax * ay * c2 * c2);
  return 1 / (PI_F * ax * ay * c2 * c2 * (1 + e) * (1 + e));
}
static inline float mfa_lambda(int beck, float ax, float ay, vec3 w) {
  float a = mf_alpha_dir(ax, ay, w);
  return beck ? beckmann_lambda(a, w) : ggx_lambda(a, w);
}
static inline float mfa_G(int beck, int sep, float ax, float ay, vec3 wo, vec3 wi) {
  if (ax == ay) return mf_G(beck, sep, ax, wo, wi);
  float lo = mfa_lambda(beck, ax, ay, wo), li = mfa_lambda(beck, ax, ay, wi);
  return sep ? 1 / ((1 + lo) * (1 + li)) : 1 / (1 + lo + li);
}
static inline float mfa_pdf_m(int beck, float ax, float ay, vec3 w, vec3 wm) {
  if (ax == ay) return mf_pdf_m(beck, ax, w, wm);
  float c = fabsf(w.z);
  if (!(c > 0)) return 0;
  return mfa_D(beck, ax, ay, wm) * fabsf(v3_dot(w, wm)) / (c * (1 + mfa_lambda(beck, ax, ay, w)));
}
static inline vec3 mfa_sample(int beck, float ax, float ay, vec3 w, float u1, float u2) {
  if (ax == ay) return mf_sample(beck, ax, w, u1, u2);
  if (w.z < 0) w = v3_neg(w);
  vec3 ws = v3_norm(v3(ax * w.x, ay * w.y, w.z)); /* the unit-roughness frame */
  vec3 m = mf_sample(beck, 1, ws, u1, u2);
  return v3_norm(v3(ax * m.x, ay * m.y, fmaxf(1e-6f, m.z)));
}
#endif
