/* vpl_common.h — owns what vpl (vpl.c) and vsl (vsl.c) share (digest 002): the virtual
 * lights of a pass, shot from light paths (lightpath.c) before every sample index, what a
 * light reflects towards a point, the sum over every light with one shadow ray each, and
 * the direct light both add at the camera path's surface. */
#ifndef VALO_VPL_COMMON_H
#define VALO_VPL_COMMON_H
#include "integrator/camera_path.h"

typedef struct vpl {
  vec3 p, n;        /* position and the shading normal faced to where the light came from */
  vec3 wi;          /* unit direction towards where the light came from */
  rgb power;        /* flux, divided by the paths emitted */
  bsdf b;
  frame fr;
  vec3 ng;          /* geometric normal (faced like n) */
  float radius;     /* vsl: the sphere's radius */
} vpl;

/* The lights of the current pass: vlight_shoot replaces them. */
typedef struct vlight_set {
  vpl *v;
  uint32_t n;
  uint64_t paths;   /* light paths per pass, measured once on a pilot set */
} vlight_set;

/* Shoots pass `sample_index`'s lights: enough light paths for about `count` lights (the
 * number measured once on a pilot set of its own, so it does not depend on the paths used
 * and the estimate stays unbiased); powers divided by the paths emitted. */
valo_status vlight_shoot(vlight_set *s, const render_ctx *c, int sample_index, double count, valo_error *err);
void vlight_free(vlight_set *s);
/* f_v: what light l reflects towards direction w (unit, leaving l); 0 when w is on the
 * side the light did not arrive on (opaque BSDFs). */
rgb vpl_reflect(const vpl *l, vec3 w);
/* Unshadowed contribution of light i at it (0 when it cannot reach it). */
typedef rgb (*vlight_contrib_fn)(const render_ctx *c, const vlight_set *s, uint32_t i, const isect *it, const bsdf *b, const frame *fr,
                                 vec3 wo_l, sampler *smp);
/* The sum over every light of its contribution, with a shadow ray each. */
rgb vlight_gather_all(const render_ctx *c, const vlight_set *s, vlight_contrib_fn contrib, const isect *it, const bsdf *b, const frame *fr,
                      vec3 wo, sampler *smp, thread_stats *ts);
/* Systematic sampling of S lights from the running sums cdf[0..n) of their weights (total
 * the last): draw m of S (offset u0 in [0,1)) is the first i at or after `from` whose sum
 * passes (m + u0) / S of the total. Draws come in increasing order, so each starts from
 * the previous one's index. */
static inline uint32_t vlight_systematic(const float *cdf, uint32_t n, uint32_t from, int m, int S, float u0, double total) {
  float target = (float)(((float)m + u0) / (float)S * total);
  while (from + 1 < n && cdf[from] <= target) from++;
  return from;
}
/* Direct light at it: the mean of nd next-event samples, stratified together across the
 * pixel's samples. */
rgb vlight_direct(const render_ctx *c, int nd, const isect *it, const bsdf *b, const frame *fr, vec3 wo, int depth, sampler *smp,
                  thread_stats *ts);
#endif
