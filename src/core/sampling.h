/* sampling.h — owns the sampling warps (square → disk/hemisphere/sphere/triangle/
 * Phong lobe) with their densities, and the MIS power heuristic. Digest 000
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
static inline float power_heuristic(float fpdf, float gpdf) {
  float f = fpdf * fpdf, g = gpdf * gpdf;
  if (isinf(f)) return 1.0f;
  return f + g > 0 ? f / (f + g) : 0.0f;
}
#endif
