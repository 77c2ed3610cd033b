/* harness.h — owns the tiny test harness: each test executable holds a {name, fn} table;
 * `exe NAME` runs one case (how ctest registers them), `exe` runs all. A case returns 0
 * (pass), 1 (fail) or TEST_SKIP (77: skipped, e.g. ../shared is missing). */
#ifndef VALO_TEST_HARNESS_H
#define VALO_TEST_HARNESS_H
#include <stdio.h>
#include <stddef.h>

#define TEST_SKIP 77
typedef struct test_case { const char *name; int (*fn)(void); } test_case;

#define CHECK(cond, ...)                                                         \
  do {                                                                           \
    if (!(cond)) {                                                               \
      fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__, __LINE__, #cond);   \
      fprintf(stderr, __VA_ARGS__);                                              \
      fputc('\n', stderr);                                                       \
      return 1;                                                                  \
    }                                                                            \
  } while (0)

int test_main(int argc, char **argv, const test_case *cases);
/* Path of a file under ../shared (VALO_SHARED_DIR), or NULL (with a message) if absent. */
const char *shared_file(const char *rel);
/* 1 when the full (heavy) statistical form is asked for: VALO_TEST_FULL=1. */
int test_full(void);
/* 1 when valo was built with Embree; else 0, and under CI=true the running case fails
 * (Embree comparisons must run in CI, not skip). */
int test_embree(void);
/* Writes text to a file in the test's scratch folder; returns its path (static buffer
 * per call slot 0..7). */
const char *scratch_file(const char *name, const char *text);
const char *scratch_dir(void);
/* scratch_dir()/name (one of 8 rotating static buffers). */
const char *scratch_path(const char *name);
/* 1 when both files can be read and hold the same bytes. */
int same_bytes(const char *a, const char *b);
/* A file's whole text, NUL-ended (malloc'd: free it), or NULL. */
char *read_text_file(const char *path);
/* Renders a JSON scene given as text (through the public API) with optional option
 * overrides; returns malloc'd RGB pixels and the size, or NULL (message printed). */
#include "valo/valo.h"
float *render_json_text(const char *json, const valo_options *opt, int *w, int *h);
/* The mean of the green channel of render_json_text's image; -1 when it failed. */
double render_json_mean_green(const char *json);
/* Loads the scene file at `path`, creates a render with `opt` (may be NULL) and runs it;
 * returns the finished render and its scene in *scene (destroy both), or NULL with the
 * message printed. */
valo_render *render_file(const char *path, const valo_options *opt, valo_scene **scene);
/* The same with load options (NULL: defaults). */
valo_render *render_file_with(const char *path, const valo_load_options *lo, const valo_options *opt, valo_scene **scene);
/* 1 (with a message) when render r lost samples: any NaN, infinite or negative sample
 * or non-finite BSDF sample, or more shading-normal refusals than the case allows
 * (1 % of surface samples, what interpolated normals on coarse spheres refuse, unless
 * allow_shading_loss raised it). render_file checks
 * every render it makes. */
int check_losses(const valo_render *r);
void allow_shading_loss(double fraction);
/* warnings_capture(1) starts collecting library warnings (they are still printed; the
 * text is cleared), warnings_capture(0) stops; warnings_text() is what was collected. */
void warnings_capture(int on);
const char *warnings_text(void);
/* Writes AOV `name` ("albedo", "normal", "depth") of a render made with aovs set to a PFM
 * in the scratch folder and reads it back into *out (image_free it); 0 on success. */
#include "image/image_io.h"
int read_aov(const valo_render *r, const char *name, image *out);
/* An image against a reference: per-channel mean error and the worst relative error over
 * lit blocks (block x block pixels whose reference luminance is above 5 % of the image's
 * mean). */
/* Mean error per channel; blocks compared per channel, where the reference's channel mean
 * in the block is at least 5 % of the image's mean luminance (lit_blocks counts those
 * block-channels); the worst relative block-channel error and where it is. */
typedef struct cmp_result { double mean_err[3]; double worst_block; int worst_bx, worst_by, worst_c, lit_blocks; } cmp_result;
void compare_images(const float *img, const float *ref, int w, int h, int block, cmp_result *r);
/* Seconds on a monotonic clock; sleeping for ms milliseconds. */
double wall_now(void);
void nap_ms(int ms);
/* Runs the valo binary with args (NULL-terminated): sends SIGINT (as Ctrl-C does) after
 * sigint_ms milliseconds when > 0, kills it after timeout_s seconds (a hang: returns 999).
 * Returns the exit code (128+signal if killed); the combined stdout+stderr go to out
 * (and to stderr); run_cli_seconds gets the wall time. */
int run_cli(const char *const *args, int sigint_ms, int timeout_s, char *out, size_t cap);
extern double run_cli_seconds;
/* Starts valo with args (NULL-ended, at most 38) in a child process of its own session
 * (whose id is its pid), its standard output and error to the file log (created or
 * truncated); returns the child's pid. */
#include <sys/types.h>
pid_t spawn_cli(const char *const *args, const char *log);
/* The same for another program (found on PATH when exe has no slash: mpirun). */
pid_t spawn_exe(const char *exe, const char *const *args, const char *log);
int run_exe(const char *exe, const char *const *args, int sigint_ms, int timeout_s, char *out, size_t cap);
#endif
