/* integrator.h — owns the integrator interface and nothing else: the render context
 * (scene, accelerator, light selector, limits), the per-frame context of image-wide
 * integrators, the ops table and its registry (registry.c), and declared parameters.
 * What integrators share lives beside it: shading (material/shading.h), ray queries and
 * next-event estimation (direct.h), path vertices (path_common.h), the camera walk
 * through delta lobes (camera_path.h), ambient occlusion (ao.h). */
#ifndef VALO_INTEGRATOR_H
#define VALO_INTEGRATOR_H
#include "scene/scene.h"
#include "geometry/accel.h"
#include "light/light.h"
#include "material/shading.h"
#include "core/rng.h"
#include "geometry/offset.h"
#include "core/stats.h"
#include "scene/camera.h"

/* Parameters an integrator declares (docs/integrators.md lists the same tables): read
 * from the scene file ("render": {"photon": {"count": 200000}}) and from the command
 * line (--param count=200000, or photon.count=200000), checked against type and range. */
typedef enum iparam_type { IPARAM_INT, IPARAM_FLOAT } iparam_type;
typedef struct integrator_param {
  const char *name;
  iparam_type type;
  double def, lo, hi;
  const char *doc;      /* one line, with the unit and what the default means */
} integrator_param;
#define INTEGRATOR_MAX_PARAMS 16

typedef struct render_ctx {
  const scene *s;
  const accel *acc;
  light_sampler ls;
  int max_depth;           /* -1: unlimited (Russian roulette, capped at PATH_HARD_CAP) */
  int rr_depth;            /* Russian roulette from this bounce on (path_roulette) */
  int hide_emitters;       /* camera rays do not count the emission they meet first */
  const double *param;     /* the integrator's parameter values, in its table's order */
  const void *state;       /* what the integrator's create/prepare made (photon maps, points) */
  uint64_t seed;
  int threads;
  int width, height;       /* the film */
  int sampler_kind;        /* sampler_kind of the render (Sobol or independent) */
  thread_stats *prep;      /* where create/prepare add the counters of their own rays
                              (light paths), from the calling thread; may be NULL */
  const struct cam_lens *lens; /* the still camera (prepare's own camera paths: guided); may be NULL */
  int spp;                 /* the render's samples per pixel (a time budget: its cap) */
  double time_budget;      /* seconds, or 0 */
} render_ctx;
#define PATH_HARD_CAP 1024
#define LI_BATCH_MAX 1024 /* camera rays per li_n call */

/* Integrators (ARCHITECTURE.md, "Growing the integrator interface"). Per-ray ones give
 * li() and get the shared tile loop. Those that work on the whole scene before the camera
 * rays add create (parse nothing: the parameters are already checked; allocate and build
 * what lasts the whole render), prepare (once before every sample index: shoot this
 * pass's photons or VPLs into fresh buffers, deterministic for any thread count) and
 * destroy; li() then reads c->state. The render loop runs one sample per pixel per pass
 * for integrators with prepare, so each pass's camera samples see one independent set. */
/* One frame of an image-wide integrator (render_frame). The render loop calls it once per
 * frame of a sequence (--frames), or once per pass of a still image on the static
 * camera, whose frames are averaged. */
enum { FRAME_GBUF = 10 };
typedef struct frame_ctx {
  int frame;            /* 0 for the first frame the integrator sees (no history yet) */
  cam_view prev;        /* the previous frame's camera (this frame's, lens->view, for frame 0) */
  float *rgb;           /* out: width*height*3 radiance estimates of this frame */
  thread_stats *ts;     /* one per thread */
  const _Atomic int *cancel; /* non-zero: stop between stages and return VALO_ERR_CANCELLED */
  int sequence;         /* 1: frames of a sequence (--frames), shown one by one; 0: the frames of a
                           still, averaged */
  const cam_lens *lens; /* this frame's camera with its lens (camera_ray) */
  float *wt;            /* out when not NULL (a filter with negative lobes): width*height
                           filter weights of this frame's samples (camera_ray) */
  float *gbuf;          /* out when not NULL (the film keeps AOVs): FRAME_GBUF floats per
                           pixel, its camera ray's albedo, shading normal facing the camera,
                           distance to the first hit and the emission seen (the AOVs,
                           render/aov.h) */
} frame_ctx;

/* Per-ray integrators give li() and get the tile loop; image-wide ones give render_frame. */
typedef enum integrator_kind { INTEGRATOR_RAY, INTEGRATOR_IMAGE } integrator_kind;

typedef struct integrator_ops {
  const char *name;
  const char *description;
  integrator_kind kind;
  const integrator_param *params; /* table ended by a NULL name, or NULL */
  /* Radiance arriving along camera ray r. */
  rgb (*li)(const render_ctx *c, ray r, sampler *smp, thread_stats *ts);
  /* Optional: li for n <= LI_BATCH_MAX camera rays at once (out[i] from r[i] and smp[i]),
   * the same numbers as n calls of li, with the rays of each stage queried together. */
  void (*li_n)(const render_ctx *c, const ray *r, sampler *smp, thread_stats *ts, rgb *out, int n);
  valo_status (*create)(const render_ctx *c, void **state, valo_error *err);
  valo_status (*prepare)(void *state, const render_ctx *c, int sample_index, valo_error *err);
  void (*destroy)(void *state);
  /* Image-wide integrators (restir-di, restir-gi) give render_frame instead of li: it runs
   * its stages as parallel_for over pixels (each a barrier), reading the buffers of the
   * previous stage or frame and writing its own (double-buffered), so the result does
   * not depend on the thread count; state persists from frame to frame. */
  valo_status (*render_frame)(void *state, const render_ctx *c, const frame_ctx *f, valo_error *err);
} integrator_ops;

/* The registry (registry.c): every integrator, in the order --help lists them. */
const integrator_ops *integrator_find(const char *name);
/* The i-th registered integrator, or NULL past the last. */
const integrator_ops *integrator_at(int i);
/* Fills values[] (one per entry of ops->params) from the defaults, then from `text`:
 * entries "name=value" or "integrator.name=value" separated by spaces, commas or
 * newlines (later ones win; entries for another integrator are skipped, and with
 * prefixed_only so are entries without an integrator name). An unknown name
 * or a value out of range is an error that names it. */
valo_status integrator_params_parse(const integrator_ops *ops, const char *text, double *values, int prefixed_only, valo_error *err);
/* Index of parameter `name` in ops->params, or -1. */
int integrator_param_index(const integrator_ops *ops, const char *name);

#endif
