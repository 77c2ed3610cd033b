/* camera_path.h — owns the camera side of the integrators that shade a surface their own
 * way (photon, vpl, vsl, restir's G-buffer): the walk through delta lobes. */
#ifndef VALO_CAMERA_PATH_H
#define VALO_CAMERA_PATH_H
#include "integrator/path_common.h"

/* The camera side of the integrators that shade a surface their own way (photon, vpl,
 * vsl): follows delta lobes from r, counting the emission found, and adds beta *
 * shade(...) at each surface with a non-delta lobe; a sampled non-delta lobe ends the
 * path there (shade's estimate stands for it). */
typedef rgb (*surface_shade_fn)(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, int depth, sampler *smp,
                                thread_stats *ts);
rgb li_shade_through_delta(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, surface_shade_fn shade);
/* The two steps of such a camera path (li_shade_through_delta, restir's G-buffer). One
 * vertex: traces r and adds beta x the emission found to *L (fully: no MIS along a delta
 * chain); at a surface with depth < max_depth fills it, its BSDF, the shading frame and
 * wo and returns 1. Continuing: samples a lobe (the sampler's current dimension); returns
 * 1 with *r and *beta updated when a delta lobe was taken and beta is still finite and
 * non-black, 0 to end the chain. */
int delta_chain_vertex(const render_ctx *c, const ray *r, rgb beta, int depth, int max_depth, thread_stats *ts, rgb *L, isect *it, bsdf *b,
                       frame *fr, vec3 *wo);
int delta_chain_continue(const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp, thread_stats *ts, rgb *beta, ray *r);
#endif
