/* direct.h — owns the ray queries integrators make through the render context (counted
 * in thread_stats) and next-event estimation with multiple importance sampling. */
#ifndef VALO_DIRECT_H
#define VALO_DIRECT_H
#include "integrator/integrator.h"

static inline int ctx_intersect(const render_ctx *c, const ray *r, hit *h, thread_stats *ts) {
  ts->rays++;
  return accel_intersect(c->acc, r, h);
}
/* Is the segment from it (leaving towards p_to) blocked? p_to is offset too when n_to is
 * non-zero (a point on a surface). */
int ctx_segment_blocked(const render_ctx *c, const isect *it, vec3 p_to, vec3 n_to, thread_stats *ts);
/* Probability that estimate_direct picks light index li at shading point p. */
static inline float ctx_light_pmf(const render_ctx *c, uint32_t li, vec3 p) { return light_select_pmf(&c->ls, c->s, li, p); }

/* Next-event estimation at it: picks a light in proportion to power, samples it, traces
 * a shadow ray, and returns f * Li * |cos| / pdf with the power-heuristic MIS weight
 * against BSDF sampling (weight 1 for delta lights). fr: frame of the shading normal
 * (already faced for opaque BSDFs). */
rgb estimate_direct(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                    thread_stats *ts);
/* The parts of one next-event sample, for integrators that multiply them their own way
 * (per wavelength): the estimate is f_cos * Li * scale, scale = MIS weight / pdf.
 * Returns 0 when the sample contributes nothing. */
typedef struct direct_sample { rgb f_cos, Li; float scale; vec3 wi; } direct_sample;
int sample_direct(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                  thread_stats *ts, int mis, direct_sample *out);
/* The same estimate with weight 1 (light sampling alone): for integrators that never
 * count emission found by BSDF-sampled rays at non-specular vertices. */
rgb estimate_direct_nomis(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                          thread_stats *ts);
/* Emission arriving along r when it hits (or escapes to) a light: the area light's
 * radiance for hit h (if found), else the environment's. */
rgb emitted_along(const render_ctx *c, const ray *r, const hit *h, int found, const isect *it);
#endif
