/* camera_path.h — owns the one walk through delta lobes (mirrors, smooth glass) to the
 * surfaces a path shades its own way: the camera side of photon, vpl and vsl, restir's
 * G-buffer, and photon mapping's final-gathering rays.
 *
 * The walk traces its ray; emission found there, times the throughput, is added to L in
 * full (no MIS along a delta chain). At a surface with a non-delta lobe it stops and
 * hands the vertex to the caller, which shades it and may go on (delta_walk_continue) if
 * the surface also has delta lobes. At a surface with delta lobes only it samples one and
 * goes on. The lobe at depth d is chosen with the sampler's dimensions from
 * sdim_bounce(d, SDIM_LOBE). One depth limit for every walk: vertices up to depth
 * max_depth (the render's, when >= 0), else up to CAMERA_PATH_MAX_DEPTH, counted from the
 * camera (a gathering ray starts one deeper than the surface it leaves). */
#ifndef VALO_CAMERA_PATH_H
#define VALO_CAMERA_PATH_H
#include "integrator/path_common.h"

#define CAMERA_PATH_MAX_DEPTH 32

typedef struct delta_walk {
  ray r;          /* the next ray to trace */
  rgb beta;       /* throughput from the walk's start to the current vertex */
  rgb L;          /* emission found so far, times beta; callers add their shading here too */
  int depth;      /* the current vertex's depth */
  vec3 first_p;   /* the first surface the walk hit (valid once it hit one) */
  int hit_any;
  /* the current vertex, after delta_walk_next returned 1 */
  isect it;
  bsdf b;
  frame fr;
  vec3 wo;
} delta_walk;

/* A walk from ray r, whose first vertex is at depth `depth`. */
void delta_walk_start(delta_walk *w, ray r, int depth);
/* Walks to the next surface with a non-delta lobe: 1 with the vertex in w, 0 when the
 * walk ended (escaped, depth limit, a failed or non-delta lobe, black throughput). */
int delta_walk_next(delta_walk *w, const render_ctx *c, sampler *smp, thread_stats *ts);
/* At the vertex delta_walk_next returned: samples a lobe; 1 when it was a delta lobe (call
 * delta_walk_next again), 0 when the walk ends there. */
int delta_walk_continue(delta_walk *w, const render_ctx *c, sampler *smp, thread_stats *ts);

/* The camera side of the integrators that shade a surface their own way (photon, vpl,
 * vsl): the walk from camera ray r, adding beta * shade(...) at each surface with a
 * non-delta lobe and going on where a delta lobe is sampled there. */
typedef rgb (*surface_shade_fn)(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, int depth, sampler *smp,
                                thread_stats *ts);
rgb li_shade_through_delta(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, surface_shade_fn shade);
#endif
