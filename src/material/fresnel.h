/* fresnel.h — owns the Fresnel equations (digest 000): unpolarised dielectric
 * Fr = (r_par^2 + r_perp^2)/2 with total internal reflection, and the conductor form for a
 * complex index n + ik (pbrt-v3 §8.2.1), per RGB channel. */
#ifndef VALO_FRESNEL_H
#define VALO_FRESNEL_H
#include "core/vec.h"

/* cos_i > 0 on the side of index eta_i; eta = eta_t / eta_i. */
/* Schlick's (1 - cos)^5, the weight of 1 - F0 in his Fresnel approximation. */
static inline float schlick_weight(float cos_i) {
  float m = 1 - cos_i;
  return m * m * m * m * m;
}
static inline float fresnel_dielectric(float cos_i, float eta) {
  cos_i = clampf(cos_i, -1, 1);
  if (cos_i < 0) { eta = 1 / eta; cos_i = -cos_i; }
  float sin2_t = (1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return 1;
  float cos_t = safe_sqrt(1 - sin2_t);
  float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5f * (r_par * r_par + r_perp * r_perp);
}
/* A thin pane of index eta (its two faces and the light bouncing between them, pbrt-v4's
 * ThinDielectricBxDF): R' = R + T^2 R / (1 - R^2) of one face's R, T = 1 - R, at |cos_i|;
 * the rest passes straight through. */
static inline float fresnel_thin_dielectric(float cos_i, float eta) {
  float R = fresnel_dielectric(fabsf(cos_i), eta);
  return R < 1 ? R + (1 - R) * (1 - R) * R / (1 - R * R) : R;
}

static inline float fresnel_conductor1(float cos_i, float eta, float k) {
  cos_i = clampf(cos_i, 0, 1);
  float c2 = cos_i * cos_i, s2 = 1 - c2;
  float e2 = eta * eta, k2 = k * k;
  float t0 = e2 - k2 - s2;
  float a2b2 = safe_sqrt(t0 * t0 + 4 * e2 * k2);
  float t1 = a2b2 + c2;
  float a = safe_sqrt(0.5f * (a2b2 + t0));
  float t2 = 2 * cos_i * a;
  float rs = (t1 - t2) / (t1 + t2);
  float t3 = c2 * a2b2 + s2 * s2;
  float t4 = t2 * s2;
  float rp = rs * (t3 - t4) / (t3 + t4);
  return 0.5f * (rp + rs);
}
static inline rgb fresnel_conductor(float cos_i, rgb eta, rgb k) {
  return c3(fresnel_conductor1(cos_i, eta.r, k.r), fresnel_conductor1(cos_i, eta.g, k.g), fresnel_conductor1(cos_i, eta.b, k.b));
}
/* Refracts wi (pointing away) about n (same side as wi) with eta = eta_t/eta_i. */
static inline int refract_dir(vec3 wi, vec3 n, float eta, vec3 *wt) {
  float cos_i = v3_dot(n, wi);
  float sin2_t = fmaxf(0.0f, 1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return 0;
  float cos_t = safe_sqrt(1 - sin2_t);
  *wt = v3_add(v3_scale(v3_neg(wi), 1 / eta), v3_scale(n, cos_i / eta - cos_t));
  return 1;
}
#endif
