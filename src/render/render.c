/* render.c — owns the public API objects (valo_scene, valo_render), the film (double
 * accumulation per pixel, box filter: each jittered sample counts for its own pixel) and
 * the render loop: passes of samples over 16x16 tiles on the thread pool, with sample
 * and time budgets, cancellation and progress. Every sample draws its random numbers
 * from (seed, pixel, sample index, dimension), and each pixel's samples are summed in
 * sample order, so images are bit-identical for any thread count. */
#include "valo/valo.h"
#include "scene/scene.h"
#include "geometry/accel.h"
#include "integrator/integrator.h"
#include "image/image_io.h"
#include "image/tonemap.h"
#include "core/threadpool.h"
#include "core/error.h"
#include "core/sampling.h"
#include "light/envmap.h"
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <stdio.h>

#define TILE 16
#define AOV_FLOATS 11
#define MAX_RES 16384
#define MAX_SPP 1048576
#define MAX_PIXEL_SAMPLES 4.0e12

struct valo_scene { scene *s; };
extern const integrator_ops integrator_path_spectral, integrator_ao;

struct valo_render {
  const scene *s;
  valo_options opt;
  render_ctx ctx;
  const integrator_ops *integ;
  sampler_kind sampler_kind;
  accel *acc;
  accel_filter alpha_filter;
  double *sum;            /* 3 doubles per pixel */
  float *aov;             /* AOV_FLOATS per pixel (albedo rgb, normal xyz, depth, ao, bent
                             normal xyz) summed, or NULL */
  double param[INTEGRATOR_MAX_PARAMS];
  void *istate;           /* the integrator's create() result */
  float ao_dist;          /* ray length of the ao AOV */
  uint32_t *count;        /* samples per pixel */
  double *sq;             /* adaptive: per pixel sums of squares: r, g, b and luminance */
  int spp_done;
  double build_seconds, render_seconds;
  thread_stats total;      /* rays, losses and surface samples of every run so far */
  thread_stats prep;       /* create's and prepare's, added to total at run_finish */
  atomic_int cancel;
  camera cam_still;       /* the scene camera fitted to the film (frame 0 of an animation) */
  cam_view view, view_prev;/* this frame's pinhole basis and the previous frame's */
  float aperture, focus;   /* thin lens: radius (0 = pinhole) and focus distance */
  int frames_done;         /* a sequence: frames finished */
  int image_frames;        /* render_frame calls made (the integrator's frame index) */
  float *frame_rgb;        /* render_frame output, width*height*3 */
  valo_frame_fn on_frame;
  void *on_frame_user;
};

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int alpha_filter_pass(const void *user, uint32_t tri, float b1, float b2) { return scene_alpha_pass(user, tri, b1, b2); }

VALO_API const char *valo_version(void) { return VALO_VERSION_STRING; }

VALO_API void valo_options_init(valo_options *o) {
  memset(o, 0, sizeof *o);
  o->width = o->height = o->spp = o->threads = o->max_depth = VALO_UNSET;
  o->time_budget = VALO_UNSET;
  o->seed = VALO_UNSET;
  o->aovs = VALO_UNSET;
  o->adaptive = VALO_UNSET;
  o->noise_threshold = VALO_UNSET;
  o->spectral = VALO_UNSET;
  o->aperture_radius = o->focus_distance = VALO_UNSET;
  o->max_depth = VALO_DEPTH_UNSET; /* -1 is a meaningful value */
  o->frames = VALO_UNSET;
}

VALO_API void valo_output_options_init(valo_output_options *o) {
  memset(o, 0, sizeof *o);
  snprintf(o->tonemap, sizeof o->tonemap, "clamp");
  o->bloom_threshold = 1;
}

static int ends_with(const char *s, const char *suf) {
  size_t n = strlen(s), m = strlen(suf);
  return n >= m && !strcasecmp(s + n - m, suf);
}

VALO_API void valo_load_options_init(valo_load_options *o) {
  memset(o, 0, sizeof *o);
  o->env_scale = 1;
  snprintf(o->up, sizeof o->up, "y");
}

/* Lights a scene could have before commit: emissive triangles, lights, an environment. */
static int scene_has_any_light(const scene *s) {
  if (s->nlights > 0) return 1;
  if (s->has_env && (s->env_map || !c3_black(s->env_radiance))) return 1;
  for (uint32_t t = 0; t < s->ntris; t++)
    if (!c3_black(s->mats[s->tri_mat[t]].emission)) return 1;
  return 0;
}

VALO_API valo_status valo_scene_load_with(const char *path, const valo_load_options *lo, valo_scene **out, valo_error *err) {
  *out = NULL;
  if (err) { err->status = VALO_OK; err->message[0] = 0; }
  valo_load_options def;
  valo_load_options_init(&def);
  if (!lo) lo = &def;
  if (!path || !*path) return err_set(err, VALO_ERR_INVALID, "no scene file given");
  if (strcmp(lo->up, "y") && strcmp(lo->up, "z") && lo->up[0]) return err_set(err, VALO_ERR_INVALID, "up axis \"%s\" (y or z)", lo->up);
  scene *s = scene_new(path);
  valo_scene *vs = calloc(1, sizeof *vs);
  if (!s || !vs) { scene_free(s); free(vs); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  int json = ends_with(path, ".json");
  s->up_z = !strcmp(lo->up, "z");
  valo_status st = json ? load_json(s, path, err) : load_mesh(s, path, NULL, UINT32_MAX, 1, err);
  if (st == VALO_OK && lo->env_file[0]) {
    /* --env replaces whatever environment the scene had. */
    if (s->env_map) { envmap_free(s->env_map); free(s->env_map); s->env_map = NULL; }
    s->env_map = calloc(1, sizeof *s->env_map);
    if (!s->env_map) st = err_set(err, VALO_ERR_NOMEM, "out of memory");
    else st = envmap_load(s->env_map, lo->env_file, (float)lo->env_scale, (float)lo->env_rotation, err);
    s->has_env = st == VALO_OK;
  }
  if (st == VALO_OK && !scene_has_any_light(s)) {
    if (!json) {
      s->has_env = 1;
      s->env_radiance = c3(1, 1, 1);
      log_note("%s has no light of its own (no emissive material, no light): it is lit by a uniform white environment "
               "(radiance 1), as model viewers do; --env FILE lights it by an environment map instead", path);
    } else {
      log_warning("%s has no light (no emissive material, no light, no environment): the image will be black", path);
    }
  }
  if (st == VALO_OK) st = scene_commit(s, err);
  if (st) { scene_free(s); free(vs); return st; }
  vs->s = s;
  *out = vs;
  return VALO_OK;
}

VALO_API valo_status valo_scene_load(const char *path, valo_scene **out, valo_error *err) {
  return valo_scene_load_with(path, NULL, out, err);
}

VALO_API int valo_scene_has_light(const valo_scene *vs) { return vs->s->nlights > 0; }

VALO_API void valo_scene_destroy(valo_scene *vs) {
  if (!vs) return;
  scene_free(vs->s);
  free(vs);
}
VALO_API void valo_scene_file_options(const valo_scene *vs, valo_options *out) { *out = vs->s->file_opts; }
VALO_API uint64_t valo_scene_triangle_count(const valo_scene *vs) { return vs->s->ntris; }

static void merge_options(valo_options *dst, const valo_options *file, const valo_options *cli) {
  valo_options_init(dst);
  const valo_options *src[2] = {file, cli};
  for (int i = 0; i < 2; i++) {
    const valo_options *o = src[i];
    if (!o) continue;
    if (o->width != VALO_UNSET) dst->width = o->width;
    if (o->height != VALO_UNSET) dst->height = o->height;
    if (o->spp != VALO_UNSET) dst->spp = o->spp;
    if (o->time_budget != VALO_UNSET) dst->time_budget = o->time_budget;
    if (o->threads != VALO_UNSET) dst->threads = o->threads;
    if (o->seed != VALO_UNSET) dst->seed = o->seed;
    if (o->max_depth != VALO_DEPTH_UNSET) dst->max_depth = o->max_depth;
    if (o->integrator[0]) memcpy(dst->integrator, o->integrator, sizeof dst->integrator);
    if (o->params[0]) {
      /* file first, then the caller's: later entries win */
      size_t used = strlen(dst->params);
      snprintf(dst->params + used, sizeof dst->params - used, "%s%s", used ? " " : "", o->params);
    }
    if (o->accel[0]) memcpy(dst->accel, o->accel, sizeof dst->accel);
    if (o->sampler[0]) memcpy(dst->sampler, o->sampler, sizeof dst->sampler);
    if (o->light_sampler[0]) memcpy(dst->light_sampler, o->light_sampler, sizeof dst->light_sampler);
    if (o->aovs != VALO_UNSET) dst->aovs = o->aovs;
    if (o->adaptive != VALO_UNSET) dst->adaptive = o->adaptive;
    if (o->noise_threshold != VALO_UNSET) dst->noise_threshold = o->noise_threshold;
    if (o->spectral != VALO_UNSET) dst->spectral = o->spectral;
    if (o->aperture_radius != VALO_UNSET) dst->aperture_radius = o->aperture_radius;
    if (o->focus_distance != VALO_UNSET) dst->focus_distance = o->focus_distance;
    if (o->frames != VALO_UNSET) dst->frames = o->frames;
  }
  if (dst->width == VALO_UNSET) dst->width = 256;
  if (dst->height == VALO_UNSET) dst->height = 256;
  if (dst->spp == VALO_UNSET) dst->spp = 16;
  if (dst->threads == VALO_UNSET || dst->threads == 0) dst->threads = threads_available();
  if (dst->seed == VALO_UNSET) dst->seed = 1;
  if (dst->aovs == VALO_UNSET) dst->aovs = 0;
  if (dst->adaptive == VALO_UNSET) dst->adaptive = 0;
  if (dst->noise_threshold == VALO_UNSET) dst->noise_threshold = 0;
  if (dst->spectral == VALO_UNSET) dst->spectral = 0;
  if (dst->max_depth == VALO_DEPTH_UNSET) dst->max_depth = -1;
  if (dst->frames == VALO_UNSET) dst->frames = 0;
  if (!dst->integrator[0]) snprintf(dst->integrator, sizeof dst->integrator, "path");
  if (!dst->accel[0]) snprintf(dst->accel, sizeof dst->accel, "kdtree");
  if (!dst->sampler[0]) snprintf(dst->sampler, sizeof dst->sampler, "sobol");
  if (!dst->light_sampler[0]) snprintf(dst->light_sampler, sizeof dst->light_sampler, "grid");
}

/* The pinhole basis of frame f of a sequence (the scene's camera animation, if any), or
 * of the still camera (a still ignores the animation: it is the camera's own fields);
 * -1 when up is parallel to the view direction. */
static int set_view(valo_render *r, int f) {
  camera c = r->opt.frames > 0 ? scene_camera_at(r->s, &r->cam_still, (float)f) : r->cam_still;
  cam_view *v = &r->view;
  v->o = c.pos;
  v->fwd = v3_norm(v3_sub(c.look_at, c.pos));
  v->right = v3_norm(v3_cross(v->fwd, c.up));
  v->up = v3_cross(v->right, v->fwd);
  v->tan_half = tanf(0.5f * c.fov_deg * PI_F / 180.0f);
  v->width = r->opt.width;
  v->height = r->opt.height;
  v->aspect = (float)r->opt.width / (float)r->opt.height;
  return (!v3_finite(v->right) || !(v3_len2(v->right) > 0.5f)) ? -1 : 0;
}

VALO_API valo_status valo_render_create(const valo_scene *vs, const valo_options *opts, valo_render **out, valo_error *err) {
  *out = NULL;
  if (err) { err->status = VALO_OK; err->message[0] = 0; }
  const scene *s = vs->s;
  valo_options o;
  merge_options(&o, &s->file_opts, opts);
  if (o.width < 1 || o.height < 1 || o.width > MAX_RES || o.height > MAX_RES)
    return err_set(err, VALO_ERR_INVALID, "resolution %dx%d is out of range (1..%d per side)", o.width, o.height, MAX_RES);
  if (o.spp < 1 || o.spp > MAX_SPP) return err_set(err, VALO_ERR_INVALID, "sample count %d is out of range (1..%d)", o.spp, MAX_SPP);
  if ((double)o.width * o.height * o.spp > MAX_PIXEL_SAMPLES)
    return err_set(err, VALO_ERR_INVALID, "%dx%d at %d spp is more than %.0e samples", o.width, o.height, o.spp, MAX_PIXEL_SAMPLES);
  if (o.threads < 1 || o.threads > 1024) return err_set(err, VALO_ERR_INVALID, "thread count %d is out of range (1..1024)", o.threads);
  if (o.seed < 0) return err_set(err, VALO_ERR_INVALID, "seed must not be negative");
  if (o.aperture_radius != VALO_UNSET && !(o.aperture_radius >= 0 && o.aperture_radius < 1e6))
    return err_set(err, VALO_ERR_INVALID, "aperture radius must be >= 0");
  if (o.focus_distance != VALO_UNSET && !(o.focus_distance > 0 && o.focus_distance < 1e9))
    return err_set(err, VALO_ERR_INVALID, "focus distance must be > 0");
  if (o.frames < 0 || o.frames > 1000000) return err_set(err, VALO_ERR_INVALID, "frame count %d is out of range (1..1000000)", o.frames);
  if (o.max_depth < -1) return err_set(err, VALO_ERR_INVALID, "max_depth must be -1 (unlimited) or >= 0");
  if (strcmp(o.sampler, "sobol") && strcmp(o.sampler, "independent"))
    return err_set(err, VALO_ERR_INVALID, "unknown sampler \"%s\" (sobol or independent)", o.sampler);
  if (strcmp(o.light_sampler, "grid") && strcmp(o.light_sampler, "power"))
    return err_set(err, VALO_ERR_INVALID, "unknown light sampler \"%s\" (grid or power)", o.light_sampler);
  const integrator_ops *integ = integrator_find(o.integrator);
  if (!integ) {
    char list[256] = "";
    for (const char *const *n = valo_integrator_names(); *n; n++) { strncat(list, " ", sizeof list - strlen(list) - 1); strncat(list, *n, sizeof list - strlen(list) - 1); }
    return err_set(err, VALO_ERR_INVALID, "unknown integrator \"%s\" (available:%s)", o.integrator, list);
  }
  if (o.spectral) {
    if (strcmp(o.integrator, "path")) return err_set(err, VALO_ERR_UNSUPPORTED, "spectral mode works with the path integrator only");
    integ = &integrator_path_spectral;
  }
  double param[INTEGRATOR_MAX_PARAMS] = {0}, ao_param[INTEGRATOR_MAX_PARAMS] = {0};
  valo_status pst = integrator_params_parse(integ, o.params, param, 0, err);
  if (pst) return pst;
  /* The ao AOV takes the ao integrator's ray length ("ao.distance=..."). */
  pst = integrator_params_parse(&integrator_ao, o.params, ao_param, !strcmp(integ->name, "ao") ? 0 : 1, err);
  if (pst) return pst;
  if (o.adaptive && integ->prepare)
    return err_set(err, VALO_ERR_UNSUPPORTED, "adaptive sampling does not work with the %s integrator (each pass shares one light-path set)", integ->name);
  if (o.adaptive && o.frames > 0) return err_set(err, VALO_ERR_UNSUPPORTED, "adaptive sampling does not work with --frames");
  if (integ->render_frame) {
    if (o.adaptive) return err_set(err, VALO_ERR_UNSUPPORTED, "adaptive sampling does not work with the %s integrator (it renders whole frames)", integ->name);
    if (o.aovs) return err_set(err, VALO_ERR_UNSUPPORTED, "the %s integrator records no AOVs (albedo:, normal:, depth:, ao:, bent: outputs)", integ->name);
    if (o.aperture_radius > 0) return err_set(err, VALO_ERR_UNSUPPORTED, "the %s integrator has a pinhole camera (no aperture)", integ->name);
  }
  valo_render *r = calloc(1, sizeof *r);
  if (!r) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  r->s = s;
  r->opt = o;
  r->integ = integ;
  memcpy(r->param, param, sizeof param);
  r->sampler_kind = strcmp(o.sampler, "independent") ? SAMPLER_SOBOL : SAMPLER_INDEPENDENT;
  atomic_init(&r->cancel, 0);
  r->sum = calloc((size_t)o.width * o.height * 3, sizeof(double));
  if (o.aovs) r->aov = calloc((size_t)o.width * o.height * AOV_FLOATS, sizeof(float));
  if (integ->render_frame && !(r->frame_rgb = calloc((size_t)o.width * o.height * 3, sizeof(float)))) {
    free(r->sum); free(r->aov); free(r);
    return err_set(err, VALO_ERR_NOMEM, "out of memory for a %dx%d film", o.width, o.height);
  }
  r->count = calloc((size_t)o.width * o.height, sizeof(uint32_t));
  if (o.adaptive) r->sq = calloc((size_t)o.width * o.height * 4, sizeof(double));
  if (!r->sum || (o.aovs && !r->aov) || !r->count || (o.adaptive && !r->sq)) {
    free(r->sum); free(r->aov); free(r->count); free(r->sq); free(r->frame_rgb); free(r);
    return err_set(err, VALO_ERR_NOMEM, "out of memory for a %dx%d film", o.width, o.height);
  }
  double t0 = now_seconds();
  int any_alpha = 0;
  for (uint32_t t = 0; t < s->ntris && !any_alpha; t++) any_alpha = (s->tri_flags[t] & TRI_ALPHA) != 0;
  r->alpha_filter.pass = alpha_filter_pass;
  r->alpha_filter.user = s;
  r->alpha_filter.tri_flags = s->tri_flags;
  r->alpha_filter.flag_bit = TRI_ALPHA;
  valo_status st = accel_create(o.accel, s->pos, s->idx, s->ntris, o.threads, any_alpha ? &r->alpha_filter : NULL, &r->acc, err);
  if (st) { free(r->sum); free(r->aov); free(r->count); free(r->sq); free(r->frame_rgb); free(r); return st; }
  r->build_seconds = now_seconds() - t0;
  if (light_sampler_init(&r->ctx.ls, s, strcmp(r->opt.light_sampler, "power") ? LIGHT_SELECT_GRID : LIGHT_SELECT_POWER)) { valo_render_destroy(r); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  r->ctx.s = s;
  r->ctx.acc = r->acc;
  r->ctx.max_depth = o.max_depth;
  r->ctx.param = r->param;
  r->ctx.seed = (uint64_t)o.seed;
  r->ctx.threads = o.threads;
  r->ctx.width = o.width;
  r->ctx.height = o.height;
  r->ctx.sampler_kind = r->sampler_kind;
  r->ctx.prep = &r->prep;
  r->ao_dist = ao_ray_length(s, ao_param[0]);
  /* Camera basis; an automatic camera is fitted to this film's aspect first. */
  r->cam_still = scene_camera_fit(s, (float)o.width / (float)o.height);
  const camera *c = &r->cam_still;
  if (set_view(r, 0)) {
    valo_render_destroy(r);
    return err_set(err, VALO_ERR_INVALID, "%s: camera up vector is parallel to the view direction", s->path);
  }
  r->view_prev = r->view;
  r->aperture = o.aperture_radius != VALO_UNSET ? (float)o.aperture_radius : c->aperture_radius;
  r->focus = o.focus_distance != VALO_UNSET ? (float)o.focus_distance : c->focus_distance;
  if (!(r->focus > 0)) {
    /* Autofocus (file cameras carry no focus distance): the surface at the image
     * centre, or the distance to the look-at point if the centre ray escapes. */
    ray cr = {r->view.o, r->view.fwd, INFINITY};
    hit h;
    int hit_centre = accel_intersect(r->acc, &cr, &h);
    r->focus = hit_centre ? h.t : v3_len(v3_sub(c->look_at, c->pos));
    if (!(r->focus > 0)) r->focus = 1;
    if (r->aperture > 0 && !hit_centre)
      log_warning("%s: autofocus: the ray through the image centre hits nothing, so the lens focuses at %g (%s); set --focus", s->path,
                  (double)r->focus, r->focus == 1 && !(v3_len(v3_sub(c->look_at, c->pos)) > 0) ? "a fallback" : "the look-at distance");
  }
  if (integ->create) {
    valo_status cst = integ->create(&r->ctx, &r->istate, err);
    if (cst) { valo_render_destroy(r); return cst; }
    r->ctx.state = r->istate;
  }
  *out = r;
  return VALO_OK;
}

static ray camera_ray(const valo_render *r, int px, int py, sampler *smp) {
  float jx, jy;
  sampler_set_dim(smp, SDIM_FILM);
  sampler_2d(smp, &jx, &jy);
  vec3 d = cam_view_dir(&r->view, (float)px + jx, (float)py + jy);
  ray ry;
  ry.o = r->view.o;
  ry.tmax = INFINITY;
  float lu, lv;
  sampler_set_dim(smp, SDIM_LENS);
  sampler_2d(smp, &lu, &lv);
  sampler_set_dim(smp, SDIM_WAVELENGTH);
  if (r->aperture > 0) {
    /* Thin lens: every ray through the lens meets at the plane of focus. */
    float ft = r->focus / v3_dot(d, r->view.fwd);
    vec3 pf = v3_add(r->view.o, v3_scale(d, ft));
    float dx, dy;
    sample_concentric_disk(lu, lv, &dx, &dy);
    ry.o = v3_add(r->view.o, v3_add(v3_scale(r->view.right, dx * r->aperture), v3_scale(r->view.up, dy * r->aperture)));
    d = v3_norm(v3_sub(pf, ry.o));
  }
  ry.d = d;
  return ry;
}

/* AOVs of one camera ray: albedo, shading normal facing the ray, hit distance, and one
 * ambient-occlusion ray (unoccluded fraction and the unoccluded direction, whose mean is
 * the bent normal). */
static void record_aovs(const valo_render *r, ray ry, float *acc, sampler *smp, thread_stats *ts) {
  hit h;
  if (!ctx_intersect(&r->ctx, &ry, &h, ts)) return;
  isect it;
  isect_from_hit(r->s, &ry, &h, &it);
  bsdf b = bsdf_at(r->s, &it);
  material tm = *it.m;
  tm.kd = b.kd;
  tm.ks = b.ks;
  rgb a = material_albedo(&tm, v3_dot(it.ns, v3_neg(ry.d)));
  vec3 n = v3_faceforward(it.ns, v3_neg(ry.d));
  acc[0] += a.r; acc[1] += a.g; acc[2] += a.b;
  acc[3] += n.x; acc[4] += n.y; acc[5] += n.z;
  acc[6] += h.t * v3_len(ry.d);
  if (!(r->opt.aovs & VALO_AOVS_AO)) return;
  vec3 dir;
  sampler_set_dim(smp, SDIM_AOV);
  if (ao_sample(&r->ctx, &it, n, r->ao_dist, smp, ts, &dir)) {
    acc[7] += 1;
    acc[8] += dir.x; acc[9] += dir.y; acc[10] += dir.z;
  }
}

typedef struct pass_job {
  valo_render *r;
  int s0, s1;          /* sample indices [s0, s1) */
  const uint32_t *target; /* or, when not NULL: each pixel from its count up to target[pix] */
  int tiles_x;
  thread_stats *ts;    /* one per thread */
} pass_job;

/* Adds one sample's radiance to pixel pix of the film: NaN, infinite and negative ones
 * count as taken but are dropped (counted by cause in ts). */
static void film_add(valo_render *r, size_t pix, rgb L, thread_stats *ts) {
  r->count[pix]++;
  if (!sample_usable(ts, L)) return;
  double *acc = &r->sum[3 * pix];
  acc[0] += L.r; acc[1] += L.g; acc[2] += L.b;
  if (r->sq) {
    double *q = &r->sq[4 * pix], l = c3_lum(L);
    q[0] += (double)L.r * L.r; q[1] += (double)L.g * L.g; q[2] += (double)L.b * L.b; q[3] += l * l;
  }
}

/* Takes samples [s0, s1) of pixel (x, y) in order. */
static void sample_pixel(valo_render *r, int x, int y, int s0, int s1, thread_stats *ts) {
  uint64_t pix = (uint64_t)y * (uint64_t)r->opt.width + (uint64_t)x;
  for (int si = s0; si < s1; si++) {
    sampler smp = sampler_make_kind((uint64_t)r->opt.seed, pix, (uint64_t)si, r->sampler_kind);
    ray ry = camera_ray(r, x, y, &smp);
    ts->rays++;
    if (r->aov) record_aovs(r, ry, &r->aov[AOV_FLOATS * pix], &smp, ts);
    film_add(r, pix, r->integ->li(&r->ctx, ry, &smp, ts), ts);
  }
}

static void render_tile(void *user, int64_t item, int thread) {
  pass_job *j = user;
  valo_render *r = j->r;
  if (atomic_load_explicit(&r->cancel, memory_order_relaxed)) return;
  thread_stats *ts = &j->ts[thread];
  int tx = (int)(item % j->tiles_x), ty = (int)(item / j->tiles_x);
  int x0 = tx * TILE, y0 = ty * TILE;
  int x1 = x0 + TILE < r->opt.width ? x0 + TILE : r->opt.width;
  int y1 = y0 + TILE < r->opt.height ? y0 + TILE : r->opt.height;
  for (int y = y0; y < y1; y++)
    for (int x = x0; x < x1; x++) {
      if (!j->target) { sample_pixel(r, x, y, j->s0, j->s1, ts); continue; }
      size_t pix = (size_t)y * (size_t)r->opt.width + (size_t)x;
      int c = (int)r->count[pix], t = (int)j->target[pix];
      if (t > c) sample_pixel(r, x, y, c, t, ts);
    }
}

/* ---- adaptive sampling (docs/integrators.md). A uniform first pass takes half of the
 * budget (of the samples, or of the time with --time). "error" (the default, unbiased)
 * then fixes each pixel's count from its neighbours' relative variance (adapt_error:
 * water-filling, in a few stages over tiles); "digest" gives rounds of ADAPT_BATCH more
 * samples to the 1/ADAPT_FRACTION of pixels with the highest priority on their own
 * samples (adapt_digest). The first pass's share and the 17x17 neighbourhood are the best
 * of those bench_adaptive measures against the bound of any allocation
 * (docs/performance.md); counts are fixed from deterministic sums between stages, so the
 * image is identical for any thread count. */
#define ADAPT_BATCH 8
#define ADAPT_FRACTION 8
#define ADAPT_UNIFORM 0.5 /* the first pass's share (docs/performance.md, "Ninth session": the bound) */
#define ADAPT_EPS 0.01
#define ADAPT_RADIUS 8 /* the 17x17 neighbourhood whose variance sets a pixel's priority */

/* The "error" rule's v of pixel i: the relative variance of one sample, var / (mean^2 +
 * eps) per channel (as relMSE weighs them), averaged over r, g, b; 0 with fewer than two
 * samples. (Per channel, not on luminance: the bound bench_adaptive measures is 1.12x
 * against 1.08x on CornellBox-Original, whose walls are red and green.) */
static double pixel_relvar(const valo_render *r, size_t i) {
  double n = r->count[i], acc = 0;
  if (n < 2) return 0;
  for (int c = 0; c < 3; c++) {
    double s = r->sum[3 * i + c], mean = s / n, var = (r->sq[4 * i + c] - s * mean) / (n - 1);
    if (var > 0) acc += var / (mean * mean + ADAPT_EPS);
  }
  return acc / 3;
}
/* The "digest" rule's priority of pixel i, on its own samples' luminance:
 * (N sum s^2 / (sum s)^2 - 1) / N. */
static double pixel_digest(const valo_render *r, size_t i) {
  const double *m = &r->sum[3 * i];
  double n = r->count[i], s = 0.2126 * m[0] + 0.7152 * m[1] + 0.0722 * m[2], s2 = r->sq[4 * i + 3];
  if (n < 2 || !(s > 0)) return 0;
  double rel = (n * s2 / (s * s) - 1) / n;
  return rel > 0 ? rel : 0;
}

typedef struct prio { double p; uint32_t i; } prio;
static int prio_cmp(const void *a, const void *b) {
  const prio *x = a, *y = b;
  if (x->p != y->p) return x->p < y->p ? 1 : -1;
  return x->i < y->i ? -1 : (x->i > y->i);
}

/* Partially orders a so that its first k entries are the k first by prio_cmp (a total
 * order: ties go by pixel index), in O(n) expected time: quickselect with Lomuto
 * partitions around a median-of-three pivot; deterministic. */
static void prio_select(prio *a, size_t n, size_t k) {
  size_t lo = 0, hi = n;
  while (hi - lo > 1) {
    size_t m = lo + (hi - lo) / 2, l = hi - 1, piv;
    /* index of the median of a[lo], a[m], a[l] */
    if (prio_cmp(&a[lo], &a[m]) < 0) piv = prio_cmp(&a[m], &a[l]) < 0 ? m : (prio_cmp(&a[lo], &a[l]) < 0 ? l : lo);
    else piv = prio_cmp(&a[lo], &a[l]) < 0 ? lo : (prio_cmp(&a[m], &a[l]) < 0 ? l : m);
    prio t = a[piv]; a[piv] = a[l]; a[l] = t;
    size_t store = lo;
    for (size_t i = lo; i < l; i++)
      if (prio_cmp(&a[i], &a[l]) < 0) { t = a[i]; a[i] = a[store]; a[store] = t; store++; }
    t = a[store]; a[store] = a[l]; a[l] = t;
    if (store == k) return;
    if (store > k) hi = store;
    else lo = store + 1;
  }
}

typedef struct adapt_job { valo_render *r; const prio *sel; int64_t n; thread_stats *ts; } adapt_job;
static void adapt_chunk(void *user, int64_t item, int thread) {
  adapt_job *j = user;
  if (atomic_load_explicit(&j->r->cancel, memory_order_relaxed)) return;
  int64_t lo = item * 64, hi = lo + 64 < j->n ? lo + 64 : j->n;
  for (int64_t k = lo; k < hi; k++) {
    uint32_t pix = j->sel[k].i;
    int x = (int)(pix % (uint32_t)j->r->opt.width), y = (int)(pix / (uint32_t)j->r->opt.width);
    int c = (int)j->r->count[pix];
    sample_pixel(j->r, x, y, c, c + ADAPT_BATCH, &j->ts[thread]);
  }
}

/* Calls the progress callback (if any) with the larger of frac and the share of the time
 * budget spent; non-zero when it asks to cancel. */
static int report_progress(valo_progress_fn progress, void *user, double frac, int spp, double el, double budget) {
  if (budget > 0 && el / budget > frac) frac = el / budget < 1 ? el / budget : 1;
  return progress && progress(user, frac, spp, el);
}

/* The "digest" rule after the first pass: rounds that give ADAPT_BATCH more samples to
 * the 1/ADAPT_FRACTION of pixels with the highest priority (N sum s^2 / (sum s)^2 - 1) / N,
 * on each pixel's own samples so far (biased: docs/integrators.md), until the budget or
 * every pixel is below the noise threshold. */
static valo_status adapt_digest(valo_render *r, int uniform_spp, double total, double budget, double t0, valo_progress_fn progress, void *user,
                                thread_stats *ts, valo_error *err) {
  size_t np = (size_t)r->opt.width * r->opt.height;
  double taken = (double)uniform_spp * (double)np;
  prio *pr = malloc(np * sizeof *pr);
  if (!pr) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  size_t k = np / ADAPT_FRACTION > 0 ? np / ADAPT_FRACTION : 1;
  double thr2 = r->opt.noise_threshold > 0 ? r->opt.noise_threshold * r->opt.noise_threshold : 0;
  valo_status st = VALO_OK;
  while (taken < total) {
    for (size_t i = 0; i < np; i++) {
      double pd = pixel_digest(r, i);
      pr[i].i = (uint32_t)i;
      pr[i].p = pd > thr2 ? pd : 0;
    }
    size_t sel = k;
    if (taken + (double)sel * ADAPT_BATCH > total) sel = (size_t)((total - taken) / ADAPT_BATCH);
    if (sel == 0) break;
    prio_select(pr, np, sel);
    qsort(pr, sel, sizeof *pr, prio_cmp);
    if (!(pr[0].p > 0)) break; /* every pixel below the noise threshold */
    while (sel > 0 && !(pr[sel - 1].p > 0)) sel--;
    adapt_job aj = {r, pr, (int64_t)sel, ts};
    parallel_for(r->opt.threads, ((int64_t)sel + 63) / 64, adapt_chunk, &aj);
    if (atomic_load(&r->cancel)) { st = err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d spp", (int)(taken / (double)np)); break; }
    taken += (double)sel * ADAPT_BATCH;
    double el = now_seconds() - t0;
    if (report_progress(progress, user, taken / total, (int)(taken / (double)np), el, budget)) {
      st = err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d spp", (int)(taken / (double)np));
      break;
    }
    if (budget > 0 && el >= budget) break;
  }
  r->spp_done = (int)(taken / (double)np);
  free(pr);
  return st;
}

/* out = sums of in over the (2 ADAPT_RADIUS + 1)^2 window around each pixel (clipped to
 * the image), separably: rows into tmp, then columns. */
static void box_sums(const double *in, double *tmp, double *out, int W, int H) {
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      double acc = 0;
      for (int xx = x - ADAPT_RADIUS; xx <= x + ADAPT_RADIUS; xx++)
        if (xx >= 0 && xx < W) acc += in[(size_t)y * W + xx];
      tmp[(size_t)y * W + x] = acc;
    }
  for (int y = 0; y < H; y++) {
    double *row = &out[(size_t)y * W];
    memset(row, 0, (size_t)W * sizeof *row);
    for (int yy = y - ADAPT_RADIUS; yy <= y + ADAPT_RADIUS; yy++)
      if (yy >= 0 && yy < H)
        for (int x = 0; x < W; x++) row[x] += tmp[(size_t)yy * W + x];
  }
}

/* Sample counts for `total` samples over the image (water-filling): target_i =
 * min(cap_i, max(count_i, floor(lam a_i))), lam the largest whose targets sum to at most
 * total; the samples left over go one each to the pixels next in line, by index. So
 * counts grow as a_i = sqrt(v_i) where the budget reaches, and never fall below what a
 * pixel has. Deterministic (no thread or timing enters). Returns the targets' sum. */
static double waterfill_at(const valo_render *r, const double *a, const uint32_t *cap, size_t np, double lam, uint32_t *target) {
  double sum = 0;
  for (size_t i = 0; i < np; i++) {
    double want = floor(lam * a[i]);
    uint32_t t = r->count[i];
    if (want > (double)t) t = want >= (double)cap[i] ? cap[i] : (uint32_t)want;
    target[i] = t;
    sum += t;
  }
  return sum;
}
static double waterfill(const valo_render *r, const double *a, const uint32_t *cap, size_t np, double total, uint32_t *target, uint32_t *hi_t) {
  double all = waterfill_at(r, a, cap, np, 1e300, target);
  if (all <= total) return all; /* every pixel that can grow is at its cap */
  double lo = 0, hi = 1;
  while (waterfill_at(r, a, cap, np, hi, hi_t) <= total) {
    lo = hi;
    hi *= 2;
  }
  for (int it = 0; it < 52; it++) { /* a double's precision; the remainder goes out below */
    double mid = 0.5 * (lo + hi);
    if (waterfill_at(r, a, cap, np, mid, hi_t) <= total) lo = mid;
    else hi = mid;
  }
  double sum = waterfill_at(r, a, cap, np, lo, target);
  waterfill_at(r, a, cap, np, hi, hi_t);
  for (size_t i = 0; i < np && sum < total; i++)
    if (hi_t[i] > target[i]) { target[i]++; sum++; }
  return sum;
}

/* The "error" rule after the first pass (docs/integrators.md): each pixel's relative
 * variance per sample, var(L) / (mean^2 + eps), from the first pass and then frozen; a
 * pixel's share comes from its neighbours' (17x17 without itself). A pixel's own samples
 * never decide how many samples it gets, so its mean stays unbiased (a pixel that
 * happened to miss a rare bright path is not left with too few samples to find it:
 * test_analytic adaptive_unbiased); the neighbours share the rare paths a caustic
 * spreads. Counts grow as the square root of that variance (the allocation that
 * minimises the summed relMSE), up to v / X^2 with a noise threshold X. The samples go
 * out in stages over tiles: equal steps towards the final counts for a sample budget
 * (the same image for any thread count), and with a time budget stages of 60 % of the
 * samples the remaining time holds at the last stage's rate. */
static valo_status adapt_error(valo_render *r, double total, double budget, double t0, valo_progress_fn progress, void *user, thread_stats *ts,
                               valo_error *err) {
  size_t np = (size_t)r->opt.width * r->opt.height;
  int W = r->opt.width, H = r->opt.height;
  double *rv = calloc(np, sizeof *rv), *a = malloc(np * sizeof *a), *box = malloc(np * sizeof *box);
  uint32_t *cap = malloc(np * sizeof *cap), *target = malloc(np * sizeof *target), *tmp = malloc(np * sizeof *tmp);
  uint32_t *fin = malloc(np * sizeof *fin), *first = malloc(np * sizeof *first);
  valo_status st = VALO_OK;
  if (!rv || !a || !box || !cap || !target || !tmp || !fin || !first) { st = err_set(err, VALO_ERR_NOMEM, "out of memory"); goto done; }
  double thr2 = r->opt.noise_threshold > 0 ? r->opt.noise_threshold * r->opt.noise_threshold : 0;
  double taken = 0;
  for (size_t i = 0; i < np; i++) { rv[i] = pixel_relvar(r, i); taken += r->count[i]; }
  box_sums(rv, a, box, W, H);
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      size_t i = (size_t)y * W + x;
      int wx = (x + ADAPT_RADIUS < W ? x + ADAPT_RADIUS : W - 1) - (x - ADAPT_RADIUS > 0 ? x - ADAPT_RADIUS : 0) + 1;
      int wy = (y + ADAPT_RADIUS < H ? y + ADAPT_RADIUS : H - 1) - (y - ADAPT_RADIUS > 0 ? y - ADAPT_RADIUS : 0) + 1;
      int cnt = wx * wy - 1; /* without the pixel itself */
      double v = cnt > 0 ? (box[i] - rv[i]) / cnt : 0;
      if (!(v > 0)) v = 0;
      a[i] = sqrt(v);
      double c = thr2 > 0 ? ceil(v / thr2) : 2e9; /* sample indices are int */
      cap[i] = c < (double)r->count[i] ? r->count[i] : c > 2e9 ? 2000000000u : (uint32_t)c;
    }
  int tiles_x = (W + TILE - 1) / TILE, tiles_y = (H + TILE - 1) / TILE;
  double rate = 0, t_prev = now_seconds();
  if (budget > 0) rate = taken / (t_prev - t0 > 1e-6 ? t_prev - t0 : 1e-6);
  /* A sample budget: the final counts at once, taken in equal stages of about 2 samples
   * per pixel (8 to 64 of them) so that progress moves; they depend on the budget alone,
   * so the image does not depend on timing. */
  int stages = 0;
  if (!(budget > 0)) {
    if (waterfill(r, a, cap, np, total, fin, tmp) <= taken) goto finish; /* all at their noise threshold */
    for (size_t i = 0; i < np; i++) first[i] = r->count[i];
    double per_pixel = (total - taken) / (double)np;
    stages = per_pixel / 2 < 8 ? 8 : per_pixel / 2 > 64 ? 64 : (int)(per_pixel / 2);
  }
  for (int stage = 1;; stage++) {
    double sum = 0;
    if (budget > 0) {
      double rem = budget - (now_seconds() - t0);
      if (rem <= 0.02 * budget) break;
      double goal = taken + (rem > 0.1 * budget ? 0.6 : 0.95) * rate * rem;
      if (goal > total) goal = total;
      if (goal < taken + 1) break;
      sum = waterfill(r, a, cap, np, goal, target, tmp);
      if (sum <= taken) break; /* nothing left to take: every pixel at its noise threshold */
    } else {
      if (stage > stages) break;
      for (size_t i = 0; i < np; i++) {
        target[i] = first[i] + (uint32_t)((uint64_t)(fin[i] - first[i]) * (uint64_t)stage / (uint64_t)stages);
        sum += target[i];
      }
    }
    pass_job job = {r, 0, 0, target, tiles_x, ts}; /* tiles keep rays coherent */
    double s0 = now_seconds();
    parallel_for(r->opt.threads, (int64_t)tiles_x * tiles_y, render_tile, &job);
    if (atomic_load(&r->cancel)) {
      st = err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d spp", (int)(taken / (double)np));
      break;
    }
    double el = now_seconds() - t0, dt = now_seconds() - s0;
    if (dt > 1e-6) rate = (sum - taken) / dt;
    taken = sum;
    if (report_progress(progress, user, taken / total, (int)(taken / (double)np), el, budget)) {
      st = err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d spp", (int)(taken / (double)np));
      break;
    }
    if (taken >= total || (budget > 0 && el >= budget)) break;
  }
finish:
  r->spp_done = (int)(taken / (double)np);
done:
  free(rv); free(a); free(box); free(cap); free(target); free(tmp); free(fin); free(first);
  return st;
}

/* One frame of an image-wide integrator, added to the film as one sample per pixel (in
 * pixel order: the film does not depend on the thread count). */
static valo_status image_frame(valo_render *r, thread_stats *ts, valo_error *err) {
  frame_ctx f = {r->image_frames, r->view, r->image_frames ? r->view_prev : r->view, r->frame_rgb, ts, &r->cancel, r->opt.frames > 0};
  valo_status st = r->integ->render_frame(r->istate, &r->ctx, &f, err);
  if (st) return st;
  r->image_frames++;
  r->view_prev = r->view;
  size_t np = (size_t)r->opt.width * r->opt.height;
  for (size_t i = 0; i < np; i++) film_add(r, i, c3(r->frame_rgb[3 * i], r->frame_rgb[3 * i + 1], r->frame_rgb[3 * i + 2]), &ts[0]);
  return VALO_OK;
}

/* Samples [s0, s1) of every pixel through the tile loop (per-ray integrators); those
 * with prepare take one sample index at a time, each after its prepare. */
static valo_status tile_samples(valo_render *r, int s0, int s1, thread_stats *ts, valo_error *err) {
  int tiles_x = (r->opt.width + TILE - 1) / TILE, tiles_y = (r->opt.height + TILE - 1) / TILE;
  for (int a = s0; a < s1;) {
    int b = s1;
    if (r->integ->prepare) {
      b = a + 1;
      valo_status pst = r->integ->prepare(r->istate, &r->ctx, a, err);
      if (pst) return pst;
    }
    pass_job job = {r, a, b, NULL, tiles_x, ts};
    parallel_for(r->opt.threads, (int64_t)tiles_x * tiles_y, render_tile, &job);
    if (atomic_load(&r->cancel)) return err_set(err, VALO_ERR_CANCELLED, "render cancelled");
    a = b;
  }
  return VALO_OK;
}

/* A sequence (opt.frames): each frame on its own camera (the animation's), with a fresh
 * film of spp samples per pixel, handed to the frame callback. Sample indices go on
 * from frame to frame (frame f takes [f spp, (f+1) spp)), so no two frames share noise. */
static valo_status run_sequence(valo_render *r, valo_progress_fn progress, void *user, thread_stats *ts, valo_error *err) {
  double t0 = now_seconds();
  double budget = r->opt.time_budget > 0 ? r->opt.time_budget : 0;
  size_t np = (size_t)r->opt.width * r->opt.height;
  for (int f = r->frames_done; f < r->opt.frames; f++) {
    if (set_view(r, f)) return err_set(err, VALO_ERR_INVALID, "%s: the camera at frame %d has its up vector along the view direction", r->s->path, f);
    memset(r->sum, 0, np * 3 * sizeof *r->sum);
    memset(r->count, 0, np * sizeof *r->count);
    r->spp_done = 0;
    if (r->integ->render_frame) {
      for (int k = 0; k < r->opt.spp; k++) {
        valo_status st = image_frame(r, ts, err);
        if (st) return st;
        r->spp_done++;
      }
    } else {
      int64_t s0 = (int64_t)f * r->opt.spp;
      if (s0 + r->opt.spp > UINT32_MAX) return err_set(err, VALO_ERR_INVALID, "frames x spp is more than 2^32 sample indices");
      valo_status st = tile_samples(r, (int)s0, (int)(s0 + r->opt.spp), ts, err);
      if (st) return st;
      r->spp_done = r->opt.spp;
    }
    r->frames_done++;
    if (r->on_frame) {
      valo_status st = r->on_frame(r->on_frame_user, r, f, err);
      if (st) return st;
    }
    double el = now_seconds() - t0;
    double frac = (double)(f + 1) / r->opt.frames;
    if (progress && progress(user, frac, r->spp_done, el)) return err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d frames", r->frames_done);
    if (budget > 0 && el >= budget) break;
  }
  return VALO_OK;
}

VALO_API void valo_render_on_frame(valo_render *r, valo_frame_fn fn, void *user) { r->on_frame = fn; r->on_frame_user = user; }

VALO_API const char *valo_loss_name(int cause) {
  static const char *names[VALO_LOSS_COUNT] = {"NaN", "infinite", "negative", "BSDF non-finite", "shading normal"};
  return cause >= 0 && cause < VALO_LOSS_COUNT ? names[cause] : "unknown";
}

/* The end of valo_render_run: time and per-thread counters into the render's totals, and
 * a warning naming each cause of dropped camera samples or BSDF failures (shading-normal
 * refusals are expected with interpolated normals: valo_stats reports them). Frees ts. */
static valo_status run_finish(valo_render *r, thread_stats *ts, double t0, valo_status st) {
  r->render_seconds += now_seconds() - t0;
  thread_stats sum = r->prep;
  memset(&r->prep, 0, sizeof r->prep);
  for (int t = 0; t < r->opt.threads; t++) thread_stats_add(&sum, &ts[t]);
  free(ts);
  thread_stats_add(&r->total, &sum);
  const uint64_t *run = sum.lost;
  for (int k = 0; k < VALO_LOSS_COUNT; k++) {
    if (run[k] && k <= VALO_LOSS_NEGATIVE)
      log_warning("%llu samples were %s and were dropped (their pixels are darker)", (unsigned long long)run[k], valo_loss_name(k));
    else if (run[k] && k == VALO_LOSS_BSDF_NONFINITE)
      log_warning("%llu BSDF samples had a non-finite weight or pdf and ended their paths", (unsigned long long)run[k]);
  }
  return st;
}

VALO_API valo_status valo_render_run(valo_render *r, valo_progress_fn progress, void *user, valo_error *err) {
  if (err) { err->status = VALO_OK; err->message[0] = 0; }
  int threads = r->opt.threads;
  thread_stats *ts = calloc((size_t)threads, sizeof *ts);
  if (!ts) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  double t0 = now_seconds();
  if (r->opt.frames > 0) return run_finish(r, ts, t0, run_sequence(r, progress, user, ts, err));
  double budget = r->opt.time_budget > 0 ? r->opt.time_budget : 0;
  int pass_spp = 1;
  valo_status st = VALO_OK;
  int uniform_spp = r->opt.spp;
  if (r->opt.adaptive) {
    uniform_spp = (int)(r->opt.spp * ADAPT_UNIFORM);
    if (uniform_spp < 4) uniform_spp = r->opt.spp < 4 ? r->opt.spp : 4;
  }
  /* Passes grow until one takes about a second, so progress stays lively. */
  while (r->spp_done < uniform_spp) {
    int n = pass_spp;
    if (r->spp_done + n > uniform_spp) n = uniform_spp - r->spp_done;
    /* One sample index per pass for integrators with prepare (its light paths are shot
     * first) and for image-wide ones (a still is frames on the static camera, averaged). */
    if (r->integ->prepare || r->integ->render_frame) n = 1;
    double p0 = now_seconds();
    valo_status pst = r->integ->render_frame ? image_frame(r, ts, err) : tile_samples(r, r->spp_done, r->spp_done + n, ts, err);
    if (pst && pst != VALO_ERR_CANCELLED) { st = pst; break; }
    double pt = now_seconds() - p0;
    if (atomic_load(&r->cancel)) {
      /* A cancelled pass stops between tiles: every tile holds whole samples (a tile
       * that started finished its samples), so the film stays a valid image. Pixels of
       * the tiles this pass finished hold n more samples; spp_done counts whole passes. */
      st = err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d spp", r->spp_done);
      break;
    }
    r->spp_done += n;
    double el = now_seconds() - t0;
    double frac = (double)r->spp_done / r->opt.spp;
    if (report_progress(progress, user, frac, r->spp_done, el, budget)) {
      st = err_set(err, VALO_ERR_CANCELLED, "render cancelled after %d spp", r->spp_done);
      break;
    }
    if (budget > 0 && el >= budget) break;
    /* Adaptive with a time budget: the uniform first pass gets ADAPT_UNIFORM of the time
     * (at least 4 spp), as it gets that share of a sample budget; before, with --time it
     * took the whole budget and adaptive sampling never ran. */
    if (r->opt.adaptive && budget > 0 && el >= budget * ADAPT_UNIFORM && r->spp_done >= 4) break;
    if (pt < 0.5 && pass_spp < 64) pass_spp *= 2;
    if (r->opt.adaptive && budget > 0 && pass_spp * (pt / n) > budget * ADAPT_UNIFORM / 2) pass_spp = pass_spp > 1 ? pass_spp / 2 : 1;
  }
  if (r->opt.adaptive) uniform_spp = r->spp_done;
  if (r->opt.adaptive && st == VALO_OK && !(budget > 0 && now_seconds() - t0 >= budget)) {
    size_t np = (size_t)r->opt.width * r->opt.height;
    double total = (double)r->opt.spp * (double)np;
    if (r->opt.adaptive == VALO_ADAPTIVE_DIGEST) st = adapt_digest(r, uniform_spp, total, budget, t0, progress, user, ts, err);
    else st = adapt_error(r, total, budget, t0, progress, user, ts, err);
  }
  return run_finish(r, ts, t0, st);
}

VALO_API void valo_render_cancel(valo_render *r) { atomic_store(&r->cancel, 1); }

VALO_API void valo_render_stats(const valo_render *r, valo_stats *o) {
  memset(o, 0, sizeof *o);
  o->triangles = r->s->ntris;
  o->build_seconds = r->build_seconds;
  o->render_seconds = r->render_seconds;
  o->rays = r->total.rays;
  memcpy(o->lost, r->total.lost, sizeof o->lost);
  o->surface_samples = r->total.surface_samples;
  o->spp_done = r->spp_done;
  o->frames_done = r->frames_done;
  size_t np = (size_t)r->opt.width * r->opt.height;
  for (size_t i = 0; i < np; i++) o->samples += r->count[i];
  o->width = r->opt.width;
  o->height = r->opt.height;
  o->threads = r->opt.threads;
  snprintf(o->integrator, sizeof o->integrator, "%s", r->opt.integrator);
  snprintf(o->accel, sizeof o->accel, "%s", r->opt.accel);
  snprintf(o->sampler, sizeof o->sampler, "%s", r->opt.sampler);
  snprintf(o->light_sampler, sizeof o->light_sampler, "%s", r->opt.light_sampler);
}

VALO_API void valo_render_pixels(const valo_render *r, float *rgb_out) {
  size_t n = (size_t)r->opt.width * r->opt.height;
  for (size_t i = 0; i < n; i++) {
    double inv = r->count[i] > 0 ? 1.0 / r->count[i] : 0;
    for (int c = 0; c < 3; c++) rgb_out[3 * i + c] = (float)(r->sum[3 * i + c] * inv);
  }
}

/* Data AOVs written as PNG (docs/integrators.md): mapped into [0, 1] so that they are
 * visible, then stored linearly in the 8 bits (each value pre-decoded from sRGB, so the
 * PNG writer's sRGB encoding gives back byte = round(255 v)). kind 0: normals, n/2 + 1/2;
 * 1: depth, divided by the largest in the image (black where nothing was hit); 2: sample
 * counts, divided by the largest. */
static void png_data_map(float *px, size_t np, int kind) {
  float mx = 0;
  for (size_t i = 0; i < 3 * np; i++) mx = px[i] > mx ? px[i] : mx;
  for (size_t i = 0; i < 3 * np; i++) {
    float v = kind == 0 ? px[i] * 0.5f + 0.5f : (mx > 0 ? px[i] / mx : 0);
    v = clampf(v, 0, 1);
    px[i] = v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
  }
}

VALO_API valo_status valo_render_write(const valo_render *r, const char *path, const valo_output_options *o, valo_error *err) {
  if (err) { err->status = VALO_OK; err->message[0] = 0; }
  valo_output_options def;
  valo_output_options_init(&def);
  if (!o) o = &def;
  if (!strncmp(path, "spp:", 4)) {
    size_t np = (size_t)r->opt.width * r->opt.height;
    float *px = malloc(np * 3 * sizeof(float));
    if (!px) return err_set(err, VALO_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < np; i++) px[3 * i] = px[3 * i + 1] = px[3 * i + 2] = (float)r->count[i];
    if (ends_with(path, ".png")) png_data_map(px, np, 2);
    valo_output_options raw;
    valo_output_options_init(&raw);
    valo_status st = image_write(path + 4, r->opt.width, r->opt.height, px, ends_with(path, ".png") ? &raw : o, err);
    free(px);
    return st;
  }
  static const char *const aov_names[5] = {"albedo:", "normal:", "depth:", "ao:", "bent:"};
  for (int k = 0; k < 5; k++) {
    size_t n = strlen(aov_names[k]);
    if (strncmp(path, aov_names[k], n)) continue;
    if (!r->aov) return err_set(err, VALO_ERR_INVALID, "%s: the render was made without AOVs", path);
    if (k >= 3 && !(r->opt.aovs & VALO_AOVS_AO))
      return err_set(err, VALO_ERR_INVALID, "%s: the render was made without the ao AOV (aovs needs VALO_AOVS_AO)", path);
    size_t np = (size_t)r->opt.width * r->opt.height;
    float *px = malloc(np * 3 * sizeof(float));
    if (!px) return err_set(err, VALO_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < np; i++) {
      const float *a = &r->aov[AOV_FLOATS * i];
      float inv = r->count[i] > 0 ? 1.0f / (float)r->count[i] : 0;
      if (k == 4) {
        /* bent normal: the mean unoccluded direction, normalised (0 where all occluded) */
        vec3 b = v3(a[8], a[9], a[10]);
        float l = v3_len(b);
        b = l > 0 ? v3_scale(b, 1 / l) : v3(0, 0, 0);
        px[3 * i] = b.x; px[3 * i + 1] = b.y; px[3 * i + 2] = b.z;
        continue;
      }
      for (int c = 0; c < 3; c++) px[3 * i + c] = (k == 2 ? a[6] : k == 3 ? a[7] : a[3 * k + c]) * inv;
    }
    int png = ends_with(path, ".png"), data = k == 1 || k == 2 || k == 4;
    if (png && data) png_data_map(px, np, k == 2 ? 1 : 0);
    valo_output_options raw;
    valo_output_options_init(&raw);
    valo_status st = image_write(path + n, r->opt.width, r->opt.height, px, png && data ? &raw : o, err);
    free(px);
    return st;
  }
  tonemap_kind tk;
  if (tonemap_parse(o->tonemap, &tk)) return err_set(err, VALO_ERR_INVALID, "unknown tone mapper \"%s\" (clamp, log, reinhard, aces)", o->tonemap);
  float *px = malloc((size_t)r->opt.width * r->opt.height * 3 * sizeof(float));
  if (!px) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  valo_render_pixels(r, px);
  valo_status st = image_write(path, r->opt.width, r->opt.height, px, o, err);
  free(px);
  return st;
}

VALO_API void valo_render_destroy(valo_render *r) {
  if (!r) return;
  accel_destroy(r->acc);
  light_sampler_free(&r->ctx.ls);
  if (r->integ && r->integ->destroy && r->istate) r->integ->destroy(r->istate);
  free(r->sum);
  free(r->aov);
  free(r->count);
  free(r->sq);
  free(r->frame_rgb);
  free(r);
}
