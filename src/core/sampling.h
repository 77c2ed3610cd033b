/* sampling.h — owns the sampling warps (square → disk/hemisphere/sphere/triangle/
 * Phong lobe, spherical triangle) with their densities, and the MIS power heuristic. Digest 000
 * "Sampling recipes"; pbrt-v4 util/sampling.h for the concentric disk. */
#ifndef VALO_SAMPLING_H
#define VALO_SAMPLING_H
#include "core/vec.h"

static inline void sample_concentric_disk(float u1, float u2, float *dx, float *dy) {
  float ox = 2.0f * u1 - 1.0f, oy = 2.0f * u2 - 1.0f;
  if (ox == 0 && oy == 0) { *dx = *dy = 0; return; }
  float r, th;
  if (fabsf(ox) > fabsf(oy)) { r = ox; th = (PI_F / 4) * (oy / ox); }
  else { r = oy; th = PI_F / 2 - (PI_F / 4) * (ox / oy); }
  *dx = r * cosf(th); *dy = r * sinf(th);
}
/* Cosine-weighted hemisphere around +z; pdf = cos(theta)/pi. */
static inline vec3 sample_cosine_hemisphere(float u1, float u2) {
  float x, y;
  sample_concentric_disk(u1, u2, &x, &y);
  return v3(x, y, safe_sqrt(1.0f - x * x - y * y));
}
static inline float cosine_hemisphere_pdf(float cos_theta) { return cos_theta > 0 ? cos_theta * INV_PI_F : 0; }
static inline vec3 sample_uniform_sphere(float u1, float u2) {
  float z = 1.0f - 2.0f * u1, r = safe_sqrt(1.0f - z * z), phi = 2.0f * PI_F * u2;
  return v3(r * cosf(phi), r * sinf(phi), z);
}
static inline float uniform_sphere_pdf(void) { return 1.0f / (4.0f * PI_F); }
/* Uniform point on a triangle as barycentrics (b0, b1); b2 = 1-b0-b1 (pbrt-v4's warp). */
static inline void sample_uniform_triangle(float u1, float u2, float *b0, float *b1) {
  if (u1 < u2) { *b0 = u1 / 2; *b1 = u2 - *b0; }
  else { *b1 = u2 / 2; *b0 = u1 - *b1; }
}
/* Phong lobe around +z: pdf = (n+1)/(2pi) cos^n(theta), theta = acos(u^(1/(n+1))). */
static inline vec3 sample_phong_lobe(float u1, float u2, float n) {
  float c = powf(u1, 1.0f / (n + 1.0f)), s = safe_sqrt(1.0f - c * c), phi = 2.0f * PI_F * u2;
  return v3(s * cosf(phi), s * sinf(phi), c);
}
static inline float phong_lobe_pdf(float cos_alpha, float n) {
  return cos_alpha > 0 ? (n + 1.0f) * (0.5f * INV_PI_F) * powf(cos_alpha, n) : 0;
}
/* Uniform cone around +z with cos of half-angle cos_max; pdf = 1/(2pi(1-cos_max)). */
static inline vec3 sample_uniform_cone(float u1, float u2, float cos_max) {
  float c = (1.0f - u1) + u1 * cos_max, s = safe_sqrt(1.0f - c * c), phi = 2.0f * PI_F * u2;
  return v3(s * cosf(phi), s * sinf(phi), c);
}
/* Spherical triangles (Arvo, "Stratified sampling of spherical triangles", SIGGRAPH 1995,
 * in pbrt-v4's formulation). Directions a, b, c are unit vectors from the reference point
 * to the vertices. Solid angle (Van Oosterom & Strackee 1983):
 *   |2 atan2(a . (b x c), 1 + a.b + a.c + b.c)|. */
static inline float spherical_triangle_area(vec3 a, vec3 b, vec3 c) {
  return fabsf(2.0f * atan2f(v3_dot(a, v3_cross(b, c)), 1.0f + v3_dot(a, b) + v3_dot(a, c) + v3_dot(b, c)));
}
/* Angle between unit vectors, accurate near 0 and pi. */
static inline float angle_between(vec3 v1, vec3 v2) {
  if (v3_dot(v1, v2) < 0) return PI_F - 2.0f * asinf(clampf(v3_len(v3_add(v1, v2)) / 2, -1, 1));
  return 2.0f * asinf(clampf(v3_len(v3_sub(v2, v1)) / 2, -1, 1));
}
static inline vec3 gram_schmidt(vec3 v, vec3 w) { return v3_sub(v, v3_scale(w, v3_dot(v, w))); }
/* A direction uniform in the solid angle of the spherical triangle (a, b, c); returns 0 if
 * the triangle is degenerate. Its density is 1 / spherical_triangle_area(a, b, c). u1 picks
 * the sub-triangle's area, u2 the position along the arc (Arvo's two steps). */
static inline int sample_spherical_triangle(vec3 a, vec3 b, vec3 c, float u1, float u2, vec3 *w) {
  vec3 n_ab = v3_cross(a, b), n_bc = v3_cross(b, c), n_ca = v3_cross(c, a);
  if (!(v3_len2(n_ab) > 0) || !(v3_len2(n_bc) > 0) || !(v3_len2(n_ca) > 0)) return 0;
  n_ab = v3_norm(n_ab); n_bc = v3_norm(n_bc); n_ca = v3_norm(n_ca);
  float alpha = angle_between(n_ab, v3_neg(n_ca)), beta = angle_between(n_bc, v3_neg(n_ab)), gamma = angle_between(n_ca, v3_neg(n_bc));
  float A_pi = alpha + beta + gamma, Ap_pi = PI_F + u1 * (A_pi - PI_F);
  if (!(A_pi - PI_F > 0)) return 0;
  float cos_a = cosf(alpha), sin_a = sinf(alpha);
  float sin_phi = sinf(Ap_pi) * cos_a - cosf(Ap_pi) * sin_a, cos_phi = cosf(Ap_pi) * cos_a + sinf(Ap_pi) * sin_a;
  float k1 = cos_phi + cos_a, k2 = sin_phi - sin_a * v3_dot(a, b);
  float den = (k2 * sin_phi + k1 * cos_phi) * sin_a;
  float cos_bp = den != 0 ? (k2 + (k2 * cos_phi - k1 * sin_phi) * cos_a) / den : 1.0f;
  cos_bp = clampf(cos_bp, -1, 1);
  float sin_bp = safe_sqrt(1 - cos_bp * cos_bp);
  vec3 cp = v3_add(v3_scale(a, cos_bp), v3_scale(v3_norm(gram_schmidt(c, a)), sin_bp));
  float cos_t = 1 - u2 * (1 - v3_dot(cp, b)), sin_t = safe_sqrt(1 - cos_t * cos_t);
  *w = v3_norm(v3_add(v3_scale(b, cos_t), v3_scale(v3_norm(gram_schmidt(cp, b)), sin_t)));
  return v3_finite(*w);
}

static inline float power_heuristic(float fpdf, float gpdf) {
  float f = fpdf * fpdf, g = gpdf * gpdf;
  if (isinf(f)) return 1.0f;
  return f + g > 0 ? f / (f + g) : 0.0f;
}
#endif
