/* valo.h — the public C API of valo, a physically based global-illumination renderer.
 *
 * The command-line tool uses nothing but this header. Objects are opaque handles:
 *   valo_scene   an immutable scene loaded from a JSON scene file or a mesh file
 *                (OBJ/MTL, glTF 2.0, PLY … through Assimp);
 *   valo_render  one rendering of a scene with given options; owns its film.
 * Every function that can fail returns a valo_status and, when `err` is not NULL, fills
 * it with a message naming the file (and line:column for parse errors) and the problem.
 * No function calls exit() or abort(). Unless said otherwise, functions are not
 * thread-safe on the same handle; distinct handles may be used from distinct threads.
 */
#ifndef VALO_VALO_H
#define VALO_VALO_H
#include <stddef.h>
#include <stdint.h>

#if defined(VALO_BUILDING)
#define VALO_API __attribute__((visibility("default")))
#else
#define VALO_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

typedef enum valo_status {
  VALO_OK = 0,
  VALO_ERR_IO = 1,          /* a file could not be opened, read or written */
  VALO_ERR_PARSE = 2,       /* malformed file content (JSON syntax, mesh data) */
  VALO_ERR_INVALID = 3,     /* well-formed but wrong: unknown key, wrong type, bad value */
  VALO_ERR_UNSUPPORTED = 4, /* format or feature not supported */
  VALO_ERR_NOMEM = 5,       /* allocation failed */
  VALO_ERR_CANCELLED = 6    /* valo_render_cancel was called */
} valo_status;

typedef struct valo_error {
  valo_status status;
  char message[1024];
} valo_error;

/* Render options. Fields left at VALO_UNSET (or empty strings) take the scene file's
 * value, or the default given beside each field. */
#define VALO_UNSET (-1)
#define VALO_DEPTH_UNSET (-2)
typedef struct valo_options {
  int width, height;      /* film size in pixels; default 256x256, at most 16384 each */
  int spp;                /* samples per pixel; default 16, at most 1048576 */
  double time_budget;     /* seconds; > 0 stops after the pass that exceeds it (spp then
                             bounds the total); VALO_UNSET or <= 0: no time limit */
  int threads;            /* worker threads; default: all cores */
  int64_t seed;           /* random seed (>= 0); default 1 */
  int max_depth;          /* path length limit; -1 (default): unlimited, ended by Russian
                             roulette (a safety cap of 1024 bounces applies);
                             VALO_DEPTH_UNSET when not given */
  int rr_depth;           /* the bounce (0: the first surface the camera ray meets) from
                             which Russian roulette may end a path; default 5 (Mitsuba's
                             rr_depth 6: Mitsuba counts the camera ray); VALO_UNSET */
  char integrator[32];    /* "path" (default) */
  char params[1024];      /* integrator parameters (docs/integrators.md): "name=value"
                             entries separated by spaces, commas or newlines; a name may
                             carry its integrator ("photon.count=100000"), entries for
                             another integrator are ignored. The scene file's come first,
                             then these (later entries win). Unknown or out-of-range
                             names make valo_render_create fail, naming them. */
  char accel[16];         /* "embree" (the default where valo was built with Embree 3) or "kdtree" */
  char sampler[16];       /* "sobol" (default: Owen-scrambled Sobol, padded per dimension)
                             or "independent" (a hash per sample and dimension) */
  char light_sampler[16]; /* how next-event estimation picks a light in scenes with more
                             than 64: "grid" (default: a distribution per cell of a grid
                             over the scene, by power over distance squared) or "power"
                             (by power alone) */
  char sphere_lights[16]; /* how next-event estimation samples an emitting sphere seen
                             from outside: "cone" (default: a direction in the cone it
                             subtends, traced to the sphere) or "triangles" (each of its
                             triangles as an area light) */
  int aovs;               /* non-zero: also record the AOVs (albedo, normal, depth) that
                             valo_render_write can then write; with the VALO_AOVS_AO bit
                             also ambient occlusion and the bent normal (one more ray
                             per camera sample); VALO_UNSET = no */
  int adaptive;           /* adaptive sampling (docs/integrators.md): spp is then the average
                             budget per pixel. VALO_ADAPTIVE_ERROR (1, default rule,
                             unbiased) or VALO_ADAPTIVE_DIGEST (2, the digest's priority,
                             biased dark where paths are rare and bright); 0 or
                             VALO_UNSET = no */
  double noise_threshold; /* adaptive: stop when every pixel's relative standard error is
                             below this (e.g. 0.01); VALO_UNSET or <= 0: use the budget */
  int spectral;           /* non-zero: spectral rendering (path integrator only): hero
                             wavelength + 3, dispersion; VALO_UNSET = RGB */
  double aperture_radius; /* thin-lens radius in scene units, over the scene camera's;
                             0 = pinhole; VALO_UNSET = the scene's */
  double focus_distance;  /* distance to the plane of focus along the view axis, > 0;
                             VALO_UNSET = the scene's (file cameras: autofocus on the
                             surface at the image centre) */
  int crop_x, crop_y, crop_width, crop_height; /* render only this window of the width x
                             height frame (pixels from its top-left corner; the image is
                             the window); VALO_UNSET: none (x, y: 0; width, height: to the
                             frame's edge when the other fields are given) */
  char filter[16];        /* pixel reconstruction filter: "box" (default), "tent",
                             "gaussian" or "blackman-harris" (docs/scene-format.md, "film") */
  double filter_radius;   /* its radius in pixels; VALO_UNSET = the filter's default (box
                             0.5, tent 1, gaussian 2, blackman-harris 1.5) */
  int splat;              /* 1: each sample is splatted into every pixel the filter reaches
                             and each pixel divided by its weights' sum (Mitsuba's film),
                             else the filter is sampled, a sample counting for its pixel
                             alone (docs/scene-format.md, "film"); VALO_UNSET = 0 */
  int frames;             /* > 0: render a sequence of this many frames (the scene's
                             camera animation, or a static camera), each at spp samples
                             per pixel, calling the frame callback after each
                             (valo_render_on_frame); VALO_UNSET = one still image */
  int hide_emitters;      /* non-zero: lights seen directly by camera rays (area lights,
                             the environment) are not drawn; seen through a mirror or
                             glass, and the light they cast, they are (Mitsuba's
                             hide_emitters); VALO_UNSET = no */
  int batch;              /* camera samples a thread traces together, stage by stage, with
                             an integrator that can (path): 1 to 1024, 1 = one path at a
                             time; the image is the same bit for bit on the kd-tree, the
                             same in distribution with Embree; VALO_UNSET = 256 */
} valo_options;

#define VALO_AOVS_AO 2
#define VALO_AOVS_VARIANCE 4 /* also each pixel's sample variance (the "denoised:" output) */

#define VALO_ADAPTIVE_ERROR 1
#define VALO_ADAPTIVE_DIGEST 2

/* Sets every field of `o` to "unset". */
VALO_API void valo_options_init(valo_options *o);

typedef struct valo_scene valo_scene;
typedef struct valo_render valo_render;

/* Loads a scene. `path` names a .json scene file, or any mesh file Assimp reads
 * (camera taken from the file when it has one, otherwise framed automatically).
 * On success *out owns the scene; free with valo_scene_destroy. */
VALO_API valo_status valo_scene_load(const char *path, valo_scene **out, valo_error *err);

/* How a scene is loaded (valo_scene_load_with). Unset fields take the defaults given. */
typedef struct valo_load_options {
  char env_file[1024];    /* an environment map (.exr/.hdr/.pfm, equirectangular) that
                             replaces the scene's environment; "" = none (default) */
  double env_scale;       /* its radiance scale (default 1) */
  double env_rotation;    /* its rotation about the up axis in degrees (default 0) */
  char up[4];             /* mesh files framed automatically: the model's up axis, "y"
                             (default) or "z" (scanned and CAD models) */
  char defines[1024];     /* a Mitsuba scene's <default> values: "NAME=VALUE NAME=VALUE",
                             replacing the file's (Mitsuba's -D); "" = none (default) */
  void (*on_warning)(void *user, const char *message); /* where this scene's warnings go,
                             while loading and in every render of it (a valo_log_fn);
                             NULL (default): the process-wide handler */
  void *on_warning_user;
} valo_load_options;
VALO_API void valo_load_options_init(valo_load_options *o);
/* valo_scene_load with options (NULL = defaults). A mesh file given directly (not through
 * a JSON scene) that has no light of its own (no emissive material, no light in the
 * file) is lit as model viewers do: by env_file if given, else a uniform white
 * environment of radiance 1, and a note says so. Any scene that ends up with no light
 * at all gets a warning that the image will be black. */
VALO_API valo_status valo_scene_load_with(const char *path, const valo_load_options *lo, valo_scene **out, valo_error *err);
/* Non-zero when the loaded scene has at least one light (emissive triangle, point, spot or
 * directional light, a non-black environment, or a medium that glows). */
VALO_API int valo_scene_has_light(const valo_scene *scene);
/* How many area lights overlap another in their plane (where they overlap, the first in
 * the scene's order is the one seen: docs/scene-format.md, "lights"). */
VALO_API unsigned valo_scene_overlapping_lights(const valo_scene *scene);
/* Writes the JSON scene (docs/scene-format.md) that the Mitsuba scene file at path means
 * to out, atomically, with its file names made absolute; lo (may be NULL) gives its
 * --define values. The same translation valo_scene_load makes of a .xml file. */
VALO_API valo_status valo_scene_convert(const char *path, const valo_load_options *lo, const char *out, valo_error *err);
VALO_API void valo_scene_destroy(valo_scene *scene);
/* The options the scene file itself asks for (unset fields stay VALO_UNSET). */
VALO_API void valo_scene_file_options(const valo_scene *scene, valo_options *out);
VALO_API uint64_t valo_scene_triangle_count(const valo_scene *scene);

/* Progress callback: called from the rendering thread after every pass, with the
 * fraction done in [0,1], samples per pixel finished so far and seconds elapsed. Return
 * non-zero to cancel. May be NULL. */
typedef int (*valo_progress_fn)(void *user, double fraction, int spp_done, double seconds);

/* Creates a render of `scene` (which must outlive it) with `opts` applied over the
 * scene file's options; builds the acceleration structure. */
VALO_API valo_status valo_render_create(const valo_scene *scene, const valo_options *opts,
                                        valo_render **out, valo_error *err);
/* Renders until the sample or time budget is met. When cancelled (valo_render_cancel, or
 * the progress callback returning non-zero) it returns VALO_ERR_CANCELLED and the film
 * keeps every finished sample: all pixels hold the whole passes counted in
 * valo_stats.spp_done, and tiles of the interrupted pass that had finished hold that
 * pass too (each pixel is averaged over its own count). valo_render_write then writes it. */
VALO_API valo_status valo_render_run(valo_render *r, valo_progress_fn progress, void *user,
                                     valo_error *err);
/* Called by valo_render_run after each frame of a sequence (valo_options.frames), from
 * the calling thread, with the film holding that frame alone (valo_render_write writes
 * it). Returning non-zero stops the sequence with that status (err filled). */
typedef valo_status (*valo_frame_fn)(void *user, const valo_render *r, int frame, valo_error *err);
VALO_API void valo_render_on_frame(valo_render *r, valo_frame_fn fn, void *user);
/* Checkpoints: valo_render_run writes the render's state to path at pass boundaries, at
 * most every `every_seconds` (0: at every boundary), atomically (a temporary file, fsync,
 * rename). A still image only (not --frames), from per-ray integrators (not restir-di or
 * restir-gi); with adaptive sampling and a time budget only the uniform passes are
 * checkpointed. VALO_ERR_INVALID when the render cannot be checkpointed. */
VALO_API valo_status valo_render_checkpoint_to(valo_render *r, const char *path, double every_seconds, valo_error *err);
/* Goes on from the checkpoint at path: call after valo_render_create, before
 * valo_render_run. The render ends as an uninterrupted one with the same scene, seed and
 * options would, byte for byte. A checkpoint that is truncated or corrupted, made by
 * another valo version, for another scene or with other options (all but the thread
 * count and the time budget) is refused, the message saying which. A time budget is that
 * of the resumed run; valo_stats counts the samples, rays and seconds of every run. */
VALO_API valo_status valo_render_resume(valo_render *r, const char *path, valo_error *err);
/* Asks a running render to stop: tiles already started finish, no new tile starts.
 * Thread-safe and async-signal-safe (one atomic store). */
VALO_API void valo_render_cancel(valo_render *r);

/* Why samples or path vertices were lost (valo_stats.lost). The first three are camera
 * samples whose radiance was not a finite non-negative number: they count as taken and
 * add nothing (darkening their pixel). BSDF_NONFINITE: a BSDF sample whose weight or pdf
 * was not finite, ending its path. SHADING_NORMAL: a BSDF or light sample refused because
 * the shading normal and the geometric normal disagree about reflection vs transmission
 * (it would leak light through the surface); nonzero only where shading normals differ
 * from the geometry (interpolated or mapped normals). */
typedef enum valo_loss {
  VALO_LOSS_NAN,
  VALO_LOSS_INF,
  VALO_LOSS_NEGATIVE,
  VALO_LOSS_BSDF_NONFINITE,
  VALO_LOSS_SHADING_NORMAL,
  VALO_LOSS_COUNT
} valo_loss;
/* A short name for a loss cause ("NaN", "infinite", ...). */
VALO_API const char *valo_loss_name(int cause);

typedef struct valo_stats {
  uint64_t triangles;
  double build_seconds;   /* acceleration structure */
  double render_seconds;
  uint64_t rays;          /* all rays traced: camera, bounce and shadow */
  int spp_done;           /* whole passes: samples every pixel has (adaptive: the average;
                             a sequence: the current frame's) */
  int frames_done;        /* a sequence: frames finished (and given to the callback) */
  uint64_t samples;       /* camera samples taken over the whole film */
  uint64_t lost[VALO_LOSS_COUNT]; /* by cause (valo_loss), over every run of this render */
  uint64_t surface_samples; /* BSDF and light samples drawn at surfaces: the base of the
                             SHADING_NORMAL and BSDF_NONFINITE fractions */
  int width, height;
  int threads;
  char integrator[32];
  char accel[16];
  char sampler[16];
  char light_sampler[16];
} valo_stats;
VALO_API void valo_render_stats(const valo_render *r, valo_stats *out);

/* Rendering across processes (MPI; docs/performance.md). valo_mpi_init joins the MPI job
 * when an MPI launcher (mpirun, srun) started the process, before anything else, and
 * returns how many processes the launcher started (1 outside one). valo_mpi_size is how
 * many ranks share the work: 1 without MPI, or when valo was built without it (then a
 * launcher's K > 1 is the caller's error to report). Under K ranks every rank loads the
 * same scene and creates the same render; rank 0 runs it (budgets, progress, adaptive
 * plans, checkpoints) and alone should write outputs, handing out tiles to the others,
 * whose valo_render_run returns when rank 0's does. The image is byte-identical to one
 * process's. valo_render_resume and valo_render_checkpoint_to do nothing on other ranks.
 * Image-wide integrators (restir-di, restir-gi) need one rank. Not thread-safe: call from
 * the main thread. */
VALO_API int valo_mpi_init(int *argc, char ***argv);
VALO_API int valo_mpi_rank(void);
VALO_API int valo_mpi_size(void);
/* Collective over the ranks: each passes a code (0: all well; a valo_status or an exit
 * code) and, when it is not 0, its message in err; returns the code of the lowest rank
 * whose code is not 0 (0 when none), whose message err then holds on every rank
 * ("rank K (host): ..." on the others). One rank alone: returns code. */
VALO_API int valo_mpi_agree(int code, valo_error *err);
VALO_API void valo_mpi_finalize(void);
/* Rank k's share of the last run under MPI (k < valo_mpi_size(), on rank 0): its host,
 * threads, tiles and samples rendered, rays traced, peak memory, and seconds spent rendering. -1 when
 * there is none (one process, another rank, or no run yet). */
typedef struct valo_rank_stats {
  char host[64];
  int threads;
  uint64_t tiles, samples, rays, peak_memory_bytes;
  double busy_seconds;
} valo_rank_stats;
VALO_API int valo_render_rank_stats(const valo_render *r, int k, valo_rank_stats *out);

/* Interactive rendering (valo view): the camera moves between steps and the film is
 * shown as it fills. A camera: position, the point looked at, the up direction and the
 * vertical field of view in degrees, or an orthographic camera's height in scene units
 * (ortho_height > 0; 0: perspective); spherical: it sees every direction (equirectangular;
 * field of view and height unused). */
typedef struct valo_camera {
  double pos[3], look_at[3], up[3];
  double fov_deg;
  double ortho_height;
  int spherical;
} valo_camera;
VALO_API void valo_render_camera(const valo_render *r, valo_camera *out);
/* Moves the camera (lens and focus unchanged); the next step should restart the film.
 * VALO_ERR_INVALID when up is parallel to the view direction, the field of view is not in
 * (0, 180) (a perspective camera), the height is not positive and finite (an orthographic
 * one) or the render is a sequence (valo_options.frames). */
VALO_API valo_status valo_render_set_camera(valo_render *r, const valo_camera *c, valo_error *err);
/* Renders one step on the current camera and returns: per-ray integrators add `spp`
 * samples per pixel to the film (sample indices going on from the film's count, so a
 * still camera converges to valo_render_run's image); image-wide integrators (restir-di,
 * restir-gi) render `spp` frames as frames of a sequence, with temporal reuse from the
 * previous step's frame reprojected to this camera. restart 1: empty the film first
 * (per-ray integrators start again at sample index 0); VALO_STEP_FRESH: empty it and go on
 * with sample indices no earlier film of this render used, so the new film's noise is
 * independent of the last (what the live denoiser's temporal filter needs). Not for
 * sequences, adaptive sampling or more than one MPI rank (VALO_ERR_INVALID). Budgets
 * are the caller's. */
#define VALO_STEP_FRESH 2
VALO_API valo_status valo_render_step(valo_render *r, int spp, int restart, valo_error *err);
/* Copies one layer of the film as linear RGB (width*height*3 floats): "" the image (as
 * valo_render_pixels), or an AOV by its output prefix without the colon ("albedo",
 * "normal", "depth", "ao", "bent", "spp") — the render must record it (VALO_ERR_INVALID
 * otherwise, saying why). */
VALO_API valo_status valo_render_layer(const valo_render *r, const char *layer, float *rgb_out, valo_error *err);
/* The real-time denoiser (what `valo view` shows): the film as it stands, filtered by
 * spatiotemporal variance-guided filtering (Schied et al. 2017) into rgb_out
 * (width*height*3). Each call is a frame of the filter: its history, kept in the render,
 * goes on accumulating while the film does, and is reprojected to the current camera
 * through the first hits' depth when the film has restarted since the last call (a step
 * with restart, so every image-wide frame), kept only where depth and normal agree. The
 * render must record AOVs (valo_options.aovs; with VALO_AOVS_VARIANCE the variance comes
 * from the film's squares, else from the history or the neighbourhood): VALO_ERR_INVALID
 * otherwise. Same bytes for any thread count. */
VALO_API valo_status valo_render_denoise_live(valo_render *r, float *rgb_out, valo_error *err);
/* Forgets the live denoiser's history: the next frame is filtered alone. */
VALO_API void valo_render_denoise_reset(valo_render *r);

/* Output settings for display-referred formats (PNG). EXR/PFM are always linear. */
typedef struct valo_output_options {
  float exposure;         /* stops; 0 by default */
  char tonemap[16];       /* "clamp" (default), "log" (natural logarithm, as the thesis),
                             "reinhard" or "aces" (filmic) */
  float bloom;            /* bloom strength; 0 (default) = off */
  float bloom_radius;     /* Gaussian std. dev. in pixels (default 1/100 of the width) */
  float bloom_threshold;  /* radiance above which pixels bloom (default 1, after exposure) */
} valo_output_options;
VALO_API void valo_output_options_init(valo_output_options *o);

/* Writes the film; the format follows the extension: .exr (linear float, OpenEXRCore),
 * .pfm (linear float), .png (8-bit sRGB). Written to a temporary file in the same folder
 * and renamed, so a reader never sees a partial file. A prefix "albedo:", "normal:" or
 * "depth:" writes that AOV instead (the render must have been created with aovs set):
 * the first camera hit's albedo, its shading normal (world space, facing the camera)
 * and its distance from the camera (0 where the ray escaped), averaged over samples;
 * "ao:" and "bent:" (aovs with the VALO_AOVS_AO bit) its unoccluded fraction and the
 * normalised mean unoccluded direction.
 * "spp:" writes the number of samples each pixel received (in all three channels). */
VALO_API valo_status valo_render_write(const valo_render *r, const char *path,
                                       const valo_output_options *o, valo_error *err);
/* Copies the linear RGB film (width*height*3 floats, row-major, top row first). */
VALO_API void valo_render_pixels(const valo_render *r, float *rgb_out);
VALO_API void valo_render_destroy(valo_render *r);

/* Reads an EXR, PFM or Radiance HDR into linear RGB (w*h*3 floats, top row first; free
 * with valo_image_free); writes one (.exr, .pfm, or .png through o, NULL: the defaults)
 * atomically as valo_render_write does. */
VALO_API valo_status valo_image_read(const char *path, int *w, int *h, float **rgb, valo_error *err);
VALO_API valo_status valo_image_write(const char *path, int w, int h, const float *rgb, const valo_output_options *o, valo_error *err);
VALO_API void valo_image_free(float *rgb);
/* Writes n bytes to path as valo writes its images: atomically through a temporary file
 * renamed over the file (a symbolic link is followed and kept), or in place into a FIFO,
 * a device or /dev/stdout. VALO_ERR_IO with the reason. For tools built on valo (the
 * CLI's --stats-json and report files). */
VALO_API valo_status valo_file_write(const char *path, const void *data, size_t n, valo_error *err);

/* The declared options (one table: the command line's flags, the JSON scene file's
 * keys, defaults, ranges and help all come from it). valo_option_at(i) is entry i (NULL
 * past the last): its flag ("--spp", or NULL for a scene-file key only), the value it
 * takes ("N"; NULL for a flag without a value), its JSON key ("render.spp", or NULL) and
 * its help (lines separated by '\n'). Thread-safe. */
typedef struct valo_option_info {
  const char *flag;
  const char *metavar;
  const char *json;
  const char *help;
} valo_option_info;
VALO_API const valo_option_info *valo_option_at(int i);
/* Sets the option with this flag from its text value (NULL for a flag without one) in the
 * struct it belongs to. VALO_ERR_INVALID for an unknown flag or a bad value, with a
 * message saying what a valid value is. */
VALO_API valo_status valo_option_set(const char *flag, const char *value, valo_options *render, valo_load_options *load,
                                     valo_output_options *output, valo_error *err);

/* Where warnings and notes go. Each handle routes its own: a scene's come from
 * valo_load_options.on_warning (inherited by its renders), a render's can be set with
 * valo_render_set_warning_handler; calls on that handle send them there, from the
 * calling thread. Without one they go to the process-wide handler set by
 * valo_set_warning_handler (not thread-safe: set it before rendering), and without that
 * to standard error, prefixed "valo: warning: " (notes: "valo: note: "); a handler gets
 * notes prefixed "note: ". */
typedef void (*valo_log_fn)(void *user, const char *message);
VALO_API void valo_set_warning_handler(valo_log_fn fn, void *user);
VALO_API void valo_render_set_warning_handler(valo_render *r, valo_log_fn fn, void *user);

VALO_API const char *valo_version(void);
VALO_API const char *valo_status_string(valo_status s);
/* The names of the registered integrators, NULL-terminated. */
VALO_API const char *const *valo_integrator_names(void);
/* Writes integrator `name`'s one-line description and its parameters (name, default,
 * range, meaning), one per line, into buf (NUL-terminated, cut at n). Returns 0, or -1
 * for an unknown name. */
VALO_API int valo_integrator_describe(const char *name, char *buf, size_t n);
/* Checks parameter text (valo_options.params syntax) against integrator `name`'s table:
 * VALO_OK, or VALO_ERR_INVALID with a message naming the entry (unknown integrator,
 * unknown parameter, value not a number or out of range). Thread-safe. */
VALO_API valo_status valo_integrator_check_params(const char *name, const char *params, valo_error *err);

#ifdef __cplusplus
}
#endif
#endif
