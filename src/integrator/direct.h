/* direct.h — owns the ray queries integrators make through the render context (counted
 * in thread_stats) and next-event estimation with multiple importance sampling. */
#ifndef VALO_DIRECT_H
#define VALO_DIRECT_H
#include "integrator/integrator.h"

static inline int ctx_intersect(const render_ctx *c, const ray *r, hit *h, thread_stats *ts) {
  ts->rays++;
  return accel_intersect(c->acc, r, h);
}
/* Is r blocked? (a shadow ray, counted) */
static inline int ctx_occluded(const render_ctx *c, const ray *r, thread_stats *ts) {
  ts->rays++;
  return accel_occluded(c->acc, r);
}
/* The shadow ray from `from` (leaving at o, its offset origin) to p_to, which is offset
 * towards `from` too when n_to is non-zero (a point on a surface): direction p_to - o,
 * tmax just short of 1. */
ray segment_ray(vec3 o, vec3 from, vec3 p_to, vec3 n_to);
/* The first hit along r on a surface that is not null: null surfaces (the boundaries of
 * media) are passed, r going on from just past each. Returns 1 with *h (its t measured
 * from the last origin) and *it, and in *before the distance from r's origin to that
 * last origin; 0 when nothing solid lies within r.tmax. */
int ctx_intersect_solid(const render_ctx *c, ray r, hit *h, isect *it, float *before, thread_stats *ts);
/* segment_ray from it's offset origin (leaving towards p_to) to p_to. */
ray segment_ray_from(const isect *it, vec3 p_to, vec3 n_to);
/* Is the segment from it (leaving towards p_to) blocked? (segment_ray_from) */
int ctx_segment_blocked(const render_ctx *c, const isect *it, vec3 p_to, vec3 n_to, thread_stats *ts);
/* Picks a light for point p (the sampler's next 1D value) and samples it (the next 2D):
 * returns its index with *pmf and *ls, or UINT32_MAX when nothing came out. it: the
 * surface p lies on (NULL in a medium). A light of an emitting sphere seen from outside
 * is sampled through the sphere's cone (light.h, light_sphere_at): a ray is traced, and
 * *pmf is the sphere's; ls->visible says the light was found unblocked. */
uint32_t direct_light_sample(const render_ctx *c, vec3 p, const isect *it, sampler *smp, thread_stats *ts, float *pmf, light_li *ls);
/* The density (per steradian at p) with which direct_light_sample picks the point p_light
 * (normal n_light) of area light li: the MIS weight of a BSDF-sampled hit there. */
float ctx_light_pdf_area(const render_ctx *c, uint32_t li, vec3 p, vec3 p_light, vec3 n_light);
/* Probability that next-event estimation picks light index li at shading point p. */
static inline float ctx_light_pmf(const render_ctx *c, uint32_t li, vec3 p) { return light_select_pmf(&c->ls, c->s, li, p); }

/* The parts of one next-event sample, for integrators that multiply them their own way
 * (per wavelength): the estimate is f_cos * Li * scale, scale = MIS weight / pdf.
 * Returns 0 when the sample contributes nothing. */
typedef struct direct_sample { rgb f_cos, Li; float scale, light_pdf; vec3 wi, p_light, n_light; int far, visible, delta; } direct_sample;
int sample_direct(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                  thread_stats *ts, int mis, direct_sample *out);
/* sample_direct without the shadow ray: the caller tests the segment to out->p_light
 * (out->n_light; out->far: the light is at infinity) itself (through media:
 * path_media.c); out->visible: nothing solid lies on it. */
int sample_direct_unshadowed(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                             thread_stats *ts, int mis, direct_sample *out);
/* Next-event estimation at it (sample_direct, its shadow ray traced) as one RGB value,
 * f * Li * |cos| / pdf with weight 1 (light sampling alone): for integrators that never
 * count emission found by BSDF-sampled rays at non-specular vertices. fr: frame of the
 * shading normal (already faced for opaque BSDFs). */
rgb estimate_direct_nomis(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                          thread_stats *ts);
/* Emission arriving along r when it hits (or escapes to) a light: the area light's
 * radiance for hit h (if found), else the environment's. */
rgb emitted_along(const render_ctx *c, const ray *r, const hit *h, int found, const isect *it);
#endif
