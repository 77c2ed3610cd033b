/* offset.h — owns robust spawning of secondary rays (pbrt-v3 §3.9.5): the hit point is
 * recomputed from barycentrics with a conservative floating-point error bound, and the
 * origin is pushed along the geometric normal past that bound, then rounded away, so a
 * ray neither re-hits its own surface nor starts behind it (no acne, no leaks). */
#ifndef VALO_OFFSET_H
#define VALO_OFFSET_H
#include "core/vec.h"

/* Point from barycentrics and its absolute error bound. */
static inline vec3 tri_point(vec3 p0, vec3 p1, vec3 p2, float b1, float b2, vec3 *err) {
  float b0 = 1 - b1 - b2;
  vec3 p = v3_add(v3_add(v3_scale(p0, b0), v3_scale(p1, b1)), v3_scale(p2, b2));
  vec3 s = v3_add(v3_add(v3_abs(v3_scale(p0, b0)), v3_abs(v3_scale(p1, b1))), v3_abs(v3_scale(p2, b2)));
  *err = v3_scale(s, fp_gamma(7));
  return p;
}

/* Origin for a ray leaving p (error perr, unit geometric normal ng) in direction w. */
static inline vec3 offset_origin(vec3 p, vec3 perr, vec3 ng, vec3 w) {
  float d = v3_dot(v3_abs(ng), perr) * 2.0f + 1e-7f * fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z)));
  vec3 off = v3_scale(ng, d);
  if (v3_dot(w, ng) < 0) off = v3_neg(off);
  vec3 po = v3_add(p, off);
  if (off.x > 0) po.x = next_float_up(po.x); else if (off.x < 0) po.x = next_float_down(po.x);
  if (off.y > 0) po.y = next_float_up(po.y); else if (off.y < 0) po.y = next_float_down(po.y);
  if (off.z > 0) po.z = next_float_up(po.z); else if (off.z < 0) po.z = next_float_down(po.z);
  return po;
}
#endif
