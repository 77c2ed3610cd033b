/* vec.h — owns the small vector/frame math used everywhere: vec3 (float), colour
 * triplets (rgb), orthonormal frames and the gamma() error bound of pbrt-v3 §3.9. */
#ifndef VALO_VEC_H
#define VALO_VEC_H
#include <math.h>
#include <float.h>
#include <stdint.h>
#include <string.h>

#define PI_F 3.14159265358979323846f
#define INV_PI_F 0.31830988618379067154f

typedef struct vec3 { float x, y, z; } vec3;
typedef struct rgb { float r, g, b; } rgb;

static inline vec3 v3(float x, float y, float z) { vec3 v = {x, y, z}; return v; }
static inline vec3 v3_add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 v3_sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 v3_mul(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline vec3 v3_scale(vec3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline vec3 v3_neg(vec3 a) { return v3(-a.x, -a.y, -a.z); }
static inline float v3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 v3_cross(vec3 a, vec3 b) {
  return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float v3_len2(vec3 a) { return v3_dot(a, a); }
static inline float v3_len(vec3 a) { return sqrtf(v3_dot(a, a)); }
static inline vec3 v3_norm(vec3 a) { float l = v3_len(a); return l > 0 ? v3_scale(a, 1.0f / l) : a; }
static inline vec3 v3_abs(vec3 a) { return v3(fabsf(a.x), fabsf(a.y), fabsf(a.z)); }
/* Plain compares rather than fminf/fmaxf, which gcc leaves as libm calls. */
static inline float minf_fast(float a, float b) { return a < b ? a : b; }
static inline float maxf_fast(float a, float b) { return a > b ? a : b; }
static inline vec3 v3_min(vec3 a, vec3 b) { return v3(minf_fast(a.x, b.x), minf_fast(a.y, b.y), minf_fast(a.z, b.z)); }
static inline vec3 v3_max(vec3 a, vec3 b) { return v3(maxf_fast(a.x, b.x), maxf_fast(a.y, b.y), maxf_fast(a.z, b.z)); }
static inline float v3_get(vec3 a, int i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }
static inline void v3_set(vec3 *a, int i, float f) { if (i == 0) a->x = f; else if (i == 1) a->y = f; else a->z = f; }
static inline int v3_finite(vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
/* Reflect w about n (both pointing away from the surface). */
static inline vec3 v3_reflect(vec3 w, vec3 n) { return v3_sub(v3_scale(n, 2.0f * v3_dot(w, n)), w); }
static inline vec3 v3_faceforward(vec3 n, vec3 v) { return v3_dot(n, v) < 0 ? v3_neg(n) : n; }

static inline rgb c3(float r, float g, float b) { rgb c = {r, g, b}; return c; }
static inline rgb c3_add(rgb a, rgb b) { return c3(a.r + b.r, a.g + b.g, a.b + b.b); }
static inline rgb c3_mul(rgb a, rgb b) { return c3(a.r * b.r, a.g * b.g, a.b * b.b); }
static inline rgb c3_scale(rgb a, float s) { return c3(a.r * s, a.g * s, a.b * s); }
static inline rgb c3_sub(rgb a, rgb b) { return c3(a.r - b.r, a.g - b.g, a.b - b.b); }
static inline float c3_max(rgb a) { return fmaxf(a.r, fmaxf(a.g, a.b)); }
static inline float c3_lum(rgb a) { return 0.2126f * a.r + 0.7152f * a.g + 0.0722f * a.b; }
/* The same to Mitsuba's six digits (its luminance of a linear sRGB colour). */
static inline float c3_lum_mitsuba(rgb a) { return 0.212671f * a.r + 0.715160f * a.g + 0.072169f * a.b; }
static inline float c3_avg(rgb a) { return (a.r + a.g + a.b) * (1.0f / 3.0f); }
static inline int c3_black(rgb a) { return a.r == 0 && a.g == 0 && a.b == 0; }
static inline int c3_finite(rgb a) { return isfinite(a.r) && isfinite(a.g) && isfinite(a.b); }

/* Orthonormal frame around n (Duff et al. 2017, branchless). */
typedef struct frame { vec3 s, t, n; } frame;
static inline frame frame_from_n(vec3 n) {
  float sign = copysignf(1.0f, n.z);
  float a = -1.0f / (sign + n.z), b = n.x * n.y * a;
  frame f;
  f.s = v3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  f.t = v3(b, sign + n.y * n.y * a, -n.y);
  f.n = n;
  return f;
}
static inline vec3 frame_to_local(const frame *f, vec3 v) { return v3(v3_dot(v, f->s), v3_dot(v, f->t), v3_dot(v, f->n)); }
static inline vec3 frame_to_world(const frame *f, vec3 v) {
  return v3_add(v3_add(v3_scale(f->s, v.x), v3_scale(f->t, v.y)), v3_scale(f->n, v.z));
}

/* Floating-point error bound gamma(n) = n*eps/(1-n*eps) (pbrt-v3 eq. 3.10). */
static inline float fp_gamma(int n) { const float e = FLT_EPSILON * 0.5f; return (n * e) / (1 - n * e); }
static inline float next_float_up(float v) {
  if (isinf(v) && v > 0) return v;
  if (v == -0.0f) v = 0.0f;
  uint32_t u; memcpy(&u, &v, 4);
  if (v >= 0) ++u; else --u;
  memcpy(&v, &u, 4);
  return v;
}
static inline float next_float_down(float v) {
  if (isinf(v) && v < 0) return v;
  if (v == 0.0f) v = -0.0f;
  uint32_t u; memcpy(&u, &v, 4);
  if (v > 0) --u; else ++u;
  memcpy(&v, &u, 4);
  return v;
}
static inline float clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
static inline float sqr(float v) { return v * v; }
static inline float safe_sqrt(float v) { return sqrtf(fmaxf(v, 0.0f)); }

typedef struct bbox { vec3 lo, hi; } bbox;
static inline bbox bbox_empty(void) { bbox b = {v3(FLT_MAX, FLT_MAX, FLT_MAX), v3(-FLT_MAX, -FLT_MAX, -FLT_MAX)}; return b; }
static inline bbox bbox_add(bbox b, vec3 p) { b.lo = v3_min(b.lo, p); b.hi = v3_max(b.hi, p); return b; }
static inline bbox bbox_union(bbox a, bbox b) { a.lo = v3_min(a.lo, b.lo); a.hi = v3_max(a.hi, b.hi); return a; }
static inline float bbox_area(bbox b) {
  vec3 d = v3_sub(b.hi, b.lo);
  if (d.x < 0 || d.y < 0 || d.z < 0) return 0;
  return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
}
#endif
