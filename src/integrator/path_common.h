/* path_common.h — owns the vertices of the path integrators (path, path_spectral, the
 * recursive whitted and distribution, light paths): the path state for MIS and Russian
 * roulette, tracing a vertex with its emission weight, continuing by BSDF sampling. */
#ifndef VALO_PATH_COMMON_H
#define VALO_PATH_COMMON_H
#include "integrator/direct.h"
#include "core/spectrum.h"

/* The common start of a vertex of the recursive integrators (whitted, distribution):
 * traces r, puts the emission it finds in *L (if count_emission), and, when it hit a
 * surface and depth < max_depth, fills the hit, its BSDF, the shading frame and wo, adds
 * the direct light without MIS to *L and returns 1; otherwise returns 0. */
int recursive_vertex(const render_ctx *c, const ray *r, sampler *smp, thread_stats *ts, int depth, int max_depth, int count_emission,
                     rgb *L, isect *it, bsdf *b, frame *fr, vec3 *wo);

/* The state a path tracer carries from one vertex to the next, apart from its
 * throughput (RGB in path.c, four wavelengths in path_spectral.c): what the previous
 * bounce was, for MIS-weighting emission found by it, and the relative index it
 * crossed, for Russian roulette. */
typedef struct path_state {
  int specular;      /* the last bounce was a delta lobe (or the camera): no MIS */
  float prev_pdf;    /* its solid-angle pdf */
  vec3 prev_p;       /* where it left from */
  float eta_acc;     /* product of 1/eta_scale over refractions */
} path_state;
static inline path_state path_state_start(vec3 origin) { path_state st = {1, 0, origin, 1}; return st; }
/* Traces the path's next ray r: returns 1 at a surface (filling *it), 0 when it escapes.
 * Either way *Le is the radiance emitted back along r there (the area light hit, or the
 * environment; black if none) and *w its MIS weight (power heuristic) against the
 * next-event estimation that could have found the same light. */
int path_trace_vertex(const render_ctx *c, const ray *r, const path_state *st, thread_stats *ts, isect *it, rgb *Le, float *w);
/* path_trace_vertex for a ray the caller traced: h its hit, NULL when it escaped. */
int path_hit_vertex(const render_ctx *c, const ray *r, const path_state *st, const hit *h, isect *it, rgb *Le, float *w);
/* The emission part of path_trace_vertex for a ray traced by the caller: h is its hit
 * (it filled from it) or NULL when it escaped. */
void path_vertex_emission(const render_ctx *c, const ray *r, const path_state *st, const hit *h, const isect *it, rgb *Le, float *w);
/* Samples the BSDF at it to continue the path: on success returns 1 with the weight
 * f |cos| / pdf in *weight, the state updated and *r the next ray. 0 ends the path
 * (no direction, or one on which shading and geometric normals disagree). */
int path_continue(const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp, thread_stats *ts, path_state *st, rgb *weight,
                  ray *r);
/* Samples the BSDF at it for viewer direction wo (the sampler's next 1D and 2D values):
 * returns 1 with *bs and the world direction *wi, or 0 when no direction came out or it
 * disagrees with the geometric normal about reflection vs transmission. */
int sample_bsdf_world(const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp, thread_stats *ts, bsdf_sample *bs, vec3 *wi);
/* The same from given numbers (lobe choice ul, direction u1 u2), without counting a
 * surface sample. */
int sample_bsdf_world_u(const isect *it, const bsdf *b, const frame *fr, vec3 wo, float ul, float u1, float u2, thread_stats *ts, bsdf_sample *bs,
                        vec3 *wi);
/* Whether direction wi (local wi_l) and the viewer wo (local wo_l) agree between the
 * shading frame and the geometric normal about reflection vs transmission (else shading
 * normals would leak light); counts the loss when not. */
int sides_agree(const isect *it, vec3 wo_l, vec3 wi_l, vec3 wo, vec3 wi, thread_stats *ts);
/* Russian roulette (pbrt-v4's rule) from bounce rr_depth on (render.rr_depth): survive
 * with probability min(1, max throughput x eta^2); returns the factor to scale the
 * throughput by on survival, 0 to end the path. */
float path_roulette(const path_state *st, float max_beta, int depth, int rr_depth, sampler *smp);
/* The end of a bounce of an RGB path: 0 when the throughput *beta is black or not
 * finite or Russian roulette (its dimension of this depth) ends the path; otherwise 1
 * with *beta divided by the survival probability. */
static inline int path_survive(const path_state *st, rgb *beta, int depth, int rr_depth, sampler *smp) {
  if (c3_black(*beta) || !c3_finite(*beta)) return 0;
  sampler_set_dim(smp, sdim_bounce(depth, SDIM_ROULETTE));
  float survive = path_roulette(st, c3_max(*beta), depth, rr_depth, smp);
  if (survive == 0) return 0;
  *beta = c3_scale(*beta, survive);
  return 1;
}

/* The path tracer's estimate (path.c) of the radiance arriving along r; without
 * count_first_emission, the emission of the surface r hits first is left out (what that
 * surface reflects: bias compensation in vpl.c). */
rgb path_radiance(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, int count_first_emission);
/* path_radiance through participating media and null surfaces (path_media.c): what
 * `path` renders when the scene has any (scene.has_media). */
rgb path_radiance_media(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, int count_first_emission);
/* The same walk on a path's channels: RGB (wl NULL; lanes 0-2 of the result) or, for
 * --spectral, the four wavelengths wl (which a dispersive dielectric may cut to one). */
spec4 path_media_walk(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, int count_first_emission, wavelengths *wl);
/* --spectral's BSDF at a surface (path_spectral.c): a dispersive dielectric takes its
 * index at the hero wavelength (the others dropped from wl); a conductor given per
 * wavelength gets F = 1 in b and is returned (NULL: none), its Fresnel term then being
 * nk_fresnel's, per wavelength, for the pair of directions (world space, both away from
 * the surface). */
const nk_curve *spectral_bsdf(const scene *s, const isect *it, bsdf *b, wavelengths *wl);
spec4 nk_fresnel(const nk_curve *nk, vec3 wo, vec3 wi, const wavelengths *wl);

#endif
