/* integrator.h — owns the integrator interface and the helpers every integrator shares:
 * the render context (scene, accelerator, light selector, limits), surface interactions
 * built from hits, ray spawning with robust offsets, counted ray queries, and next-event
 * estimation with MIS. Integrators are an ops table in a registry (integrator.c); each
 * one is a file that writes its li(). */
#ifndef VALO_INTEGRATOR_H
#define VALO_INTEGRATOR_H
#include "scene/scene.h"
#include "geometry/accel.h"
#include "light/light.h"
#include "material/bsdf.h"
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
  const double *param;     /* the integrator's parameter values, in its table's order */
  const void *state;       /* what the integrator's create/prepare made (photon maps, points) */
  uint64_t seed;
  int threads;
  int width, height;       /* the film */
  int sampler_kind;        /* sampler_kind of the render (Sobol or independent) */
  thread_stats *prep;      /* where create/prepare add the counters of their own rays
                              (light paths), from the calling thread; may be NULL */
} render_ctx;
#define PATH_HARD_CAP 1024

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
typedef struct frame_ctx {
  int frame;            /* 0 for the first frame the integrator sees (no history yet) */
  cam_view cam, prev;   /* this frame's camera and the previous frame's (equal for frame 0) */
  float *rgb;           /* out: width*height*3 radiance estimates of this frame */
  thread_stats *ts;     /* one per thread */
  const _Atomic int *cancel; /* non-zero: stop between stages and return VALO_ERR_CANCELLED */
  int sequence;         /* 1: frames of a sequence (--frames), shown one by one; 0: the frames of a
                           still, averaged */
  const cam_lens *lens; /* this frame's camera with its lens (camera_ray): cam is lens->view */
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

typedef struct isect {
  vec3 p, perr;       /* point and its floating-point error bound */
  vec3 ng;            /* unit geometric normal (counter-clockwise winding side) */
  vec3 ns;            /* unit shading normal (interpolated, or ng) */
  float u, v;
  uint32_t tri;
  const material *m;
} isect;

void isect_from_hit(const scene *s, const ray *r, const hit *h, isect *it);
/* The BSDF at it, with the material's texture maps applied at its UV. */
bsdf bsdf_at(const scene *s, const isect *it);
static inline vec3 offset_origin_isect(const isect *it, vec3 d) { return offset_origin(it->p, it->perr, it->ng, d); }
static inline int ctx_intersect(const render_ctx *c, const ray *r, hit *h, thread_stats *ts) {
  ts->rays++;
  return accel_intersect(c->acc, r, h);
}
/* Is the segment from it (leaving towards p_to) blocked? p_to is offset too when n_to is
 * non-zero (a point on a surface). */
int ctx_segment_blocked(const render_ctx *c, const isect *it, vec3 p_to, vec3 n_to, thread_stats *ts);
static inline ray spawn_ray(const isect *it, vec3 d) {
  ray r;
  r.o = offset_origin_isect(it, d);
  r.d = d;
  r.tmax = INFINITY;
  return r;
}

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
/* Shading frame at it for viewer direction wo, faced for opaque BSDFs (geometric normal
 * too); returns the frame and updates it->ng. */
frame shading_frame(isect *it, const bsdf *b, vec3 wo);
/* Probability that estimate_direct picks light index li at shading point p. */
static inline float ctx_light_pmf(const render_ctx *c, uint32_t li, vec3 p) { return light_select_pmf(&c->ls, c->s, li, p); }

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
/* Samples the BSDF at it to continue the path: on success returns 1 with the weight
 * f |cos| / pdf in *weight, the state updated and *r the next ray. 0 ends the path
 * (no direction, or one on which shading and geometric normals disagree). */
int path_continue(const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp, thread_stats *ts, path_state *st, rgb *weight,
                  ray *r);
/* Samples the BSDF at it for viewer direction wo (the sampler's next 1D and 2D values):
 * returns 1 with *bs and the world direction *wi, or 0 when no direction came out or it
 * disagrees with the geometric normal about reflection vs transmission. */
int sample_bsdf_world(const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp, thread_stats *ts, bsdf_sample *bs, vec3 *wi);
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
/* Russian roulette (pbrt-v4) after depth 2: survive with probability
 * min(1, max throughput x eta^2); returns the factor to scale the throughput by on
 * survival, 0 to end the path. */
float path_roulette(const path_state *st, float max_beta, int depth, sampler *smp);

/* The path tracer's estimate (path.c) of the radiance arriving along r; without
 * count_first_emission, the emission of the surface r hits first is left out (what that
 * surface reflects: bias compensation in vpl.c). */
rgb path_radiance(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, int count_first_emission);

/* Ambient occlusion (digest 003, ao.c): one cosine-weighted ray about the normal n
 * (faced to the viewer) from it, up to length dist. Returns 1 when it escapes (the
 * direction is then *dir), 0 when something is within dist. */
int ao_sample(const render_ctx *c, const isect *it, vec3 n, float dist, sampler *smp, thread_stats *ts, vec3 *dir);
/* The ao ray length for parameter value d: d itself when > 0, else (automatic) a tenth
 * of the radius of the scene's bounding sphere (contact shadows and corners; the whole
 * radius would leave an interior black). */
float ao_ray_length(const scene *s, double d);
#endif
