/* harness.c — see harness.h. */
#include "harness.h"
#include "geometry/accel.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#ifndef VALO_EXE
#define VALO_EXE "valo"
#endif

#ifndef VALO_SHARED_DIR
#define VALO_SHARED_DIR "../shared"
#endif

int test_full(void) {
  const char *e = getenv("VALO_TEST_FULL");
  return e && *e && strcmp(e, "0");
}

static int g_shared_missing;
static int under_ci(void) { const char *e = getenv("CI"); return e && !strcmp(e, "true"); }

const char *shared_file(const char *rel) {
  static char buf[8][2048];
  static int slot;
  char *b = buf[slot++ & 7];
  const char *root = getenv("VALO_SHARED");
  snprintf(b, 2048, "%s/%s", root && *root ? root : VALO_SHARED_DIR, rel);
  if (access(b, R_OK) != 0) {
    fprintf(stderr, "%s: %s is not there (the shared scenes folder is absent)\n", under_ci() ? "error (CI needs it)" : "skipped", b);
    g_shared_missing = 1;
    return NULL;
  }
  return b;
}

const char *scratch_dir(void) {
  static char dir[1024];
  if (!dir[0]) {
    snprintf(dir, sizeof dir, "valo-test-scratch-%ld", (long)getpid());
    mkdir(dir, 0777);
  }
  return dir;
}

const char *scratch_file(const char *name, const char *text) {
  static char buf[8][1200];
  static int slot;
  char *b = buf[slot++ & 7];
  snprintf(b, 1200, "%s/%s", scratch_dir(), name);
  FILE *f = fopen(b, "wb");
  if (!f) return NULL;
  fputs(text, f);
  fclose(f);
  return b;
}

/* Warnings captured between warnings_capture(1) and warnings_capture(0) (still printed). */
static char g_warnings[8192];
static void capture_warning(void *user, const char *msg) {
  (void)user;
  fprintf(stderr, "valo: warning: %s\n", msg);
  size_t n = strlen(g_warnings);
  snprintf(g_warnings + n, sizeof g_warnings - n, "%s\n", msg);
}
void warnings_capture(int on) {
  g_warnings[0] = 0;
  valo_set_warning_handler(on ? capture_warning : NULL, NULL);
}
const char *warnings_text(void) { return g_warnings; }

/* VALO_TEST_KEEP=1 keeps the scratch folder (to render a test's scene by hand). */
static void cleanup_scratch(void) {
  char cmd[1200];
  const char *d = scratch_dir();
  const char *keep = getenv("VALO_TEST_KEEP");
  if (keep && *keep && strcmp(keep, "0")) { fprintf(stderr, "kept %s\n", d); return; }
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", d);
  if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", d);
}

/* Every render a test makes must lose nothing: no NaN, infinite or negative sample, no
 * non-finite BSDF sample, and at most this fraction of surface samples refused for
 * shading normals (interpolated normals; a case with bump or normal maps raises it). */
#define SHADING_LOSS_DEFAULT 1e-2
static double g_shading_bound = SHADING_LOSS_DEFAULT;
void allow_shading_loss(double fraction) { g_shading_bound = fraction; }

int check_losses(const valo_render *r) {
  valo_stats st;
  valo_render_stats(r, &st);
  int bad = 0;
  for (int k = 0; k < VALO_LOSS_COUNT; k++) {
    if (!st.lost[k]) continue;
    if (k == VALO_LOSS_SHADING_NORMAL) {
      double f = st.surface_samples ? (double)st.lost[k] / (double)st.surface_samples : 1;
      if (f <= g_shading_bound) continue;
      fprintf(stderr, "render lost %.3g%% of its surface samples to shading normals (bound %.3g%%)\n", 100 * f, 100 * g_shading_bound);
    } else {
      fprintf(stderr, "render lost %llu samples: %s\n", (unsigned long long)st.lost[k], valo_loss_name(k));
    }
    bad = 1;
  }
  return bad;
}

static int g_embree_missing;
int test_embree(void) {
  if (embree_available()) return 1;
  g_embree_missing = 1;
  fprintf(stderr, "%s: valo was built without Embree\n", under_ci() ? "error (CI needs it)" : "skipped");
  return 0;
}

int test_main(int argc, char **argv, const test_case *cases) {
  int failed = 0, ran = 0;
  int rc_single = -1;
  for (const test_case *c = cases; c->name; c++) {
    if (argc > 1 && strcmp(argv[1], c->name)) continue;
    ran++;
    fprintf(stderr, "== %s\n", c->name);
    g_shared_missing = 0;
    g_shading_bound = SHADING_LOSS_DEFAULT;
    g_embree_missing = 0;
    int rc = c->fn();
    /* Under CI a case that needs ../shared fails instead of skipping, and so does one
     * that wanted Embree in a build without it. */
    if (rc == TEST_SKIP && g_shared_missing && under_ci()) rc = 1;
    if (g_embree_missing && under_ci()) rc = 1;
    if (rc == TEST_SKIP) fprintf(stderr, "-- %s: skipped\n", c->name);
    else if (rc) { fprintf(stderr, "-- %s: FAILED\n", c->name); failed++; }
    else fprintf(stderr, "-- %s: ok\n", c->name);
    if (argc > 1) rc_single = rc;
  }
  cleanup_scratch();
  if (ran == 0) { fprintf(stderr, "no test case named %s\n", argc > 1 ? argv[1] : "(none)"); return 2; }
  if (rc_single >= 0) return rc_single == TEST_SKIP ? TEST_SKIP : (rc_single ? 1 : 0);
  return failed ? 1 : 0;
}

valo_render *render_file(const char *path, const valo_options *opt, valo_scene **scene) { return render_file_with(path, NULL, opt, scene); }

valo_render *render_file_with(const char *path, const valo_load_options *lo, const valo_options *opt, valo_scene **scene) {
  valo_error err;
  valo_scene *sc = NULL;
  valo_render *r = NULL;
  *scene = NULL;
  if (!path) { fprintf(stderr, "no scene file\n"); return NULL; }
  if (valo_scene_load_with(path, lo, &sc, &err)) { fprintf(stderr, "load: %s\n", err.message); return NULL; }
  if (valo_render_create(sc, opt, &r, &err)) { fprintf(stderr, "create: %s\n", err.message); valo_scene_destroy(sc); return NULL; }
  if (valo_render_run(r, NULL, NULL, &err) || check_losses(r)) {
    if (err.status) fprintf(stderr, "run: %s\n", err.message);
    valo_render_destroy(r);
    valo_scene_destroy(sc);
    return NULL;
  }
  *scene = sc;
  return r;
}

int read_aov(const valo_render *r, const char *name, image *out) {
  char file[1200], spec[1300];
  valo_error err;
  snprintf(file, sizeof file, "%s/aov_%s.pfm", scratch_dir(), name);
  snprintf(spec, sizeof spec, "%s:%s", name, file);
  if (valo_render_write(r, spec, NULL, &err) || image_read(file, out, &err)) { fprintf(stderr, "AOV %s: %s\n", name, err.message); return -1; }
  return 0;
}

float *render_json_text(const char *json, const valo_options *opt, int *w, int *h) {
  static int counter;
  char name[64];
  snprintf(name, sizeof name, "scene%d.json", counter++);
  const char *path = scratch_file(name, json);
  valo_scene *sc = NULL;
  float *px = NULL;
  if (!path) { fprintf(stderr, "cannot write %s\n", name); return NULL; }
  valo_render *r = render_file(path, opt, &sc);
  if (!r) return NULL;
  valo_stats st;
  valo_render_stats(r, &st);
  *w = st.width; *h = st.height;
  px = malloc((size_t)st.width * st.height * 3 * sizeof(float));
  if (px) valo_render_pixels(r, px);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  return px;
}

double render_json_mean_green(const char *json) {
  int w, h;
  float *px = render_json_text(json, NULL, &w, &h);
  if (!px) return -1;
  double m = 0;
  for (int i = 0; i < w * h; i++) m += px[3 * i + 1];
  free(px);
  return m / ((double)w * h);
}

/* Compares img to ref: per-channel mean error and worst relative error over lit blocks
 * (block luminance above 5 % of the image's mean luminance). */
void compare_images(const float *img, const float *ref, int w, int h, int block, cmp_result *r) {
  double s_img[3] = {0}, s_ref[3] = {0};
  for (int i = 0; i < w * h; i++)
    for (int c = 0; c < 3; c++) { s_img[c] += img[3 * i + c]; s_ref[c] += ref[3 * i + c]; }
  double mean_lum = (s_ref[0] + s_ref[1] + s_ref[2]) / (3.0 * w * h);
  for (int c = 0; c < 3; c++) r->mean_err[c] = fabs(s_img[c] - s_ref[c]) / s_ref[c];
  r->worst_block = 0; r->lit_blocks = 0; r->worst_bx = r->worst_by = r->worst_c = -1;
  for (int by = 0; by < h / block; by++)
    for (int bx = 0; bx < w / block; bx++) {
      double a[3] = {0}, b[3] = {0};
      for (int y = by * block; y < (by + 1) * block; y++)
        for (int x = bx * block; x < (bx + 1) * block; x++)
          for (int c = 0; c < 3; c++) { a[c] += img[3 * (y * w + x) + c]; b[c] += ref[3 * (y * w + x) + c]; }
      double n = (double)block * block;
      for (int c = 0; c < 3; c++) {
        if (b[c] / n < 0.05 * mean_lum) continue; /* this channel is dark here */
        r->lit_blocks++;
        double e = fabs(a[c] - b[c]) / b[c];
        if (e > r->worst_block) { r->worst_block = e; r->worst_bx = bx; r->worst_by = by; r->worst_c = c; }
      }
    }
}

double run_cli_seconds;
double wall_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

void nap_ms(int ms) {
  struct timespec d = {ms / 1000, (long)(ms % 1000) * 1000000L};
  nanosleep(&d, NULL);
}

pid_t spawn_exe(const char *exe, const char *const *args, const char *log) {
  pid_t pid = fork();
  if (pid == 0) {
    setsid(); /* its own session: a test can signal everything it started (pkill -s) */
    int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1); dup2(fd, 2);
    close(fd);
    const char *argv[40];
    int n = 0;
    argv[n++] = exe;
    for (int i = 0; args[i] && n < 39; i++) argv[n++] = args[i];
    argv[n] = NULL;
    execvp(exe, (char *const *)argv);
    _exit(127);
  }
  return pid;
}

pid_t spawn_cli(const char *const *args, const char *log) { return spawn_exe(VALO_EXE, args, log); }

int run_cli(const char *const *args, int sigint_ms, int timeout_s, char *out, size_t cap) {
  return run_exe(VALO_EXE, args, sigint_ms, timeout_s, out, cap);
}

int run_exe(const char *exe, const char *const *args, int sigint_ms, int timeout_s, char *out, size_t cap) {
  char log[1200];
  snprintf(log, sizeof log, "%s/out.txt", scratch_dir());
  double t0 = wall_now();
  pid_t pid = spawn_exe(exe, args, log);
  int status = 0;
  if (sigint_ms > 0) {
    struct timespec d = {sigint_ms / 1000, (long)(sigint_ms % 1000) * 1000000L};
    nanosleep(&d, NULL);
    kill(pid, SIGINT);
  }
  for (;;) {
    pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (wall_now() - t0 > timeout_s) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      fprintf(stderr, "%s hung: killed after %d s\n", exe, timeout_s);
      run_cli_seconds = wall_now() - t0;
      return 999;
    }
    struct timespec ts = {0, 5000000};
    nanosleep(&ts, NULL);
  }
  run_cli_seconds = wall_now() - t0;
  FILE *f = fopen(log, "rb");
  size_t len = f ? fread(out, 1, cap - 1, f) : 0;
  if (f) fclose(f);
  out[len] = 0;
  fprintf(stderr, "valo said (%.2f s): %s", run_cli_seconds, out);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return WEXITSTATUS(status);
}

const char *scratch_path(const char *name) {
  static char b[8][1200];
  static int k;
  char *p = b[k++ & 7];
  snprintf(p, sizeof b[0], "%s/%s", scratch_dir(), name);
  return p;
}

int same_bytes(const char *a, const char *b) {
  FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
  int same = fa && fb;
  while (same) {
    int ca = fgetc(fa), cb = fgetc(fb);
    if (ca != cb) same = 0;
    if (ca == EOF || cb == EOF) break;
  }
  if (fa) fclose(fa);
  if (fb) fclose(fb);
  return same;
}

char *read_text_file(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  char *b = NULL;
  long n = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
  if (n >= 0 && fseek(f, 0, SEEK_SET) == 0 && (b = malloc((size_t)n + 1))) {
    if (fread(b, 1, (size_t)n, f) != (size_t)n) { free(b); b = NULL; }
    else b[n] = 0;
  }
  fclose(f);
  return b;
}
