/* restir_internal.h — owns what restir-di (restir_di.c) and restir-gi (restir_gi.c) share
 * with the frame they run in (restir_common.c): the parameter indices, the random
 * dimensions, the G-buffer pixel, the state, the stage jobs and the pairwise-MIS merge. */
#ifndef VALO_RESTIR_INTERNAL_H
#define VALO_RESTIR_INTERNAL_H
#include "integrator/restir.h"
#include "core/streams.h"

/* Parameter indices: restir-gi's table extends restir-di's first nine; restir-di's tenth
 * is P_RESERVOIRS. */
enum { P_CANDIDATES, P_TEMPORAL, P_HISTORY, P_SPATIAL, P_RADIUS, P_ITER, P_UNBIASED, P_NORMAL, P_DEPTH, P_DIRECT, P_JACOBIAN, P_DIRECT_SPATIAL,
       P_DIRECT_ITER };
enum { P_RESERVOIRS = P_DIRECT };
/* Reservoir k's share of a pixel's M candidates among K (the first M % K take one more). */
static inline int restir_share(int M, int K, int k) { return M / K + (k < M % K); }
extern const integrator_param restir_di_params[];

/* ---- per-pixel random streams: (seed, pixel, frame); stages use fixed dimensions */
/* Random dimensions: core/streams.h (SDIM_RESTIR_*, RDIM_*). */

typedef struct gpix {
  isect it;
  frame fr;
  bsdf b;
  vec3 wo;
  rgb beta;      /* throughput of the delta chain from the camera to it */
  rgb Le;        /* emission seen along that chain (weighted) */
  float depth;   /* how far the camera is from the first hit (cam_view_depth) */
  int valid;     /* a surface with a non-delta lobe */
  int chain;     /* reached through a delta bounce: not reprojected */
  float fw;      /* the camera sample's filter weight (camera_ray) */
} gpix;

typedef struct restir_state {
  int gi;
  int width, height;
  size_t np;
  restir_cfg dcfg, gcfg;        /* DI settings; GI settings (gi only) */
  int direct_restir;          /* gi: direct light by restir-di */
  gpix *g, *g_prev;
  di_res *di[2], *di_prev;    /* ping-pong buffers of this frame; last frame's final:
                                 `reservoirs` per pixel, pixel p's k-th at p K + k */
  int reservoirs;             /* K: dcfg's, at most one per candidate */
  gi_res *gr[2], *gr_prev;
  int di_final, gi_final;     /* which ping-pong buffer holds the final reservoirs */
  int have_prev;
} restir_state;

typedef struct stage_job {
  restir_state *s;
  const render_ctx *c;
  const frame_ctx *f;
  int src, dst;     /* ping-pong buffer indices */
} stage_job;

/* What merging asks of a kind of reservoir: target(u, at, j), the target of input j's
 * sample at pixel `at` in the measure common to all pixels; visible(u, at, j), whether
 * `at` sees that sample (called right after target of the same pair); own(u, j), if not
 * NULL, input j's target at its own pixel as kept with the input (else target is asked);
 * W(u, j), input j's contribution weight in that measure (0: none). */
typedef struct merge_ops {
  float (*target)(void *u, const gpix *at, int j);
  float (*own)(void *u, int j);
  int (*visible)(void *u, const gpix *at, int j, thread_stats *ts);
  float (*W)(void *u, int j);
} merge_ops;

static inline float rnd(sampler *s) { return rng_to_float(sampler_u32(s)); }
/* Pixel pix's stream of this frame for the stages' own choices, at dimension dim. */
sampler restir_pixel_stream(const render_ctx *c, const frame_ctx *f, size_t pix, uint32_t dim);
/* Merges inputs 0..n-1 (restir_common.c: pairwise MIS, or 1/M when biased). */
int restir_merge(const merge_ops *ops, void *u, int unbiased, int can, const float *M, const gpix *const *gs, int n, float cap_M,
                 sampler *rng, thread_stats *ts, float *M_out, float *W_out);
/* DI (restir_di.c): the initial candidates stage, merging, shading a pixel. */
void restir_stage_di_initial(void *user, int64_t row, int thread);
void restir_di_merge(const render_ctx *c, int unbiased, const gpix *const *gs, const di_res *const *in, int n, float cap_M, sampler *rng,
                     thread_stats *ts, di_res *out);
rgb restir_di_shade(const di_res *r);
/* GI (restir_gi.c): the initial samples stage, merging, the target. */
void restir_stage_gi_initial(void *user, int64_t row, int thread);
void restir_gi_merge(const render_ctx *c, int unbiased, int use_jacobian, const gpix *const *gs, const gi_res *const *in, int n,
                     float cap_M, sampler *rng, thread_stats *ts, gi_res *out);
float restir_gi_target(const gpix *g, const gi_res *r, rgb *contrib, vec3 *wi_out);
/* The frame and the state (restir_common.c): the integrators' render_frame, destroy and
 * (gi: restir-gi) create. */
valo_status restir_frame(void *state, const render_ctx *c, const frame_ctx *f, valo_error *err);
void restir_destroy(void *state);
valo_status restir_create(const render_ctx *c, void **state, int gi, valo_error *err);
#endif
