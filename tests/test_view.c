/* test_view.c — `valo view` as a user runs it, and the library calls under it:
 *  - steps add up to valo_render_run's image; cameras, layers and steps are checked;
 *  - --benchmark without a display (SDL's dummy driver): prints "fps X" last, and -o writes
 *    the last frame itself — path's one-sample frame equals `valo render --spp 1`, and
 *    restir-di's sixth frame equals frame 5 of `valo render --frames 6 --spp 1` (temporal
 *    reuse from frame to frame, no averaging), the EXR files byte for byte;
 *  - in a window under Xvfb, driven by xdotool: the camera is printed (C), a drag orbits
 *    it, the save key (P) writes the EXR and PNG of the moved view, which differ from the
 *    first camera's render, and Esc quits with exit 0;
 *  - wrong use is refused with exit 2; no display without --benchmark is an error (exit 1).
 * Without SDL2 in the build, or without Xvfb and xdotool, the cases skip, and fail under
 * CI=true. Under the sanitizers, leaks are checked in the windowless cases (see
 * xvfb_drag_and_save for why not in the window). */
#include "harness.h"
#include "image/image_io.h"
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static char g_out[65536];
static const char *scene(void) { return VALO_SOURCE_DIR "/scenes/default.json"; }
static int ci(void) { return getenv("CI") && !strcmp(getenv("CI"), "true"); }

/* Every viewer this test starts: no display, unless a case gives one. */
static void view_env(const char *display) {
  if (display) setenv("DISPLAY", display, 1);
  else unsetenv("DISPLAY");
  unsetenv("WAYLAND_DISPLAY");
  unsetenv("SDL_VIDEODRIVER");
}

/* 1 when valo has a viewer; else 0 (TEST_SKIP, or failing under CI, is the caller's). */
static int have_viewer(void) {
  view_env(NULL);
  const char *a[] = {"view", scene(), "--res", "8x8", "--benchmark", "1", NULL};
  int rc = run_cli(a, 0, 120, g_out, sizeof g_out);
  if (rc != 0 && strstr(g_out, "without SDL2")) {
    fprintf(stderr, "valo was built without SDL2: %s\n", ci() ? "failing under CI=true" : "skipped");
    return 0;
  }
  return 1;
}
#define NEED_VIEWER() do { if (!have_viewer()) return ci() ? 1 : TEST_SKIP; } while (0)

/* The last line of the output. */
static const char *last_line(const char *s) {
  const char *end = s + strlen(s);
  while (end > s && end[-1] == '\n') end--;
  const char *p = end;
  while (p > s && p[-1] != '\n') p--;
  return p;
}

static int benchmark_frames(void) {
  NEED_VIEWER();
  /* path: a frame is one sample per pixel, the film started again */
  const char *a[] = {"view", scene(), "--res", "64x48", "--benchmark", "3", "--no-denoise", "-o", scratch_path("path-frame.exr"), NULL};
  int rc = run_cli(a, 0, 300, g_out, sizeof g_out);
  CHECK(rc == 0, "valo view --benchmark exited %d", rc);
  double fps = 0;
  CHECK(sscanf(last_line(g_out), "fps %lf", &fps) == 1 && fps > 0, "the last line is not \"fps X\": %s", last_line(g_out));
  const char *r[] = {"render", scene(), "--res", "64x48", "--spp", "1", "-q", "-o", scratch_path("path-1spp.exr"), NULL};
  CHECK(run_cli(r, 0, 300, g_out, sizeof g_out) == 0, "valo render failed");
  CHECK(same_bytes(scratch_path("path-frame.exr"), scratch_path("path-1spp.exr")), "path's benchmark frame is not the 1-spp render");
  /* restir-di: frame 6 carries the history of frames 1-5, as a sequence's frame 5 does
   * (on a still camera: the default scene has no camera animation) */
  const char *ml = scene();
  const char *p = "candidates=4 iterations=1 spatial=2 unbiased=0 reservoirs=2"; /* over the viewer's reservoirs=1 */
  const char *b[] = {"view", ml, "--integrator", "restir-di", "--param", p, "--res", "48x36", "--benchmark", "6", "--no-denoise", "-o", scratch_path("restir-frame.exr"), NULL};
  rc = run_cli(b, 0, 300, g_out, sizeof g_out);
  CHECK(rc == 0 && sscanf(last_line(g_out), "fps %lf", &fps) == 1 && fps > 0, "restir-di benchmark: exit %d, last line %s", rc, last_line(g_out));
  const char *s[] = {"render", ml, "--integrator", "restir-di", "--param", p, "--res", "48x36", "--spp", "1", "--frames", "6", "-q",
                     "-o", scratch_path("seq-%d.exr"), NULL};
  CHECK(run_cli(s, 0, 300, g_out, sizeof g_out) == 0, "the restir-di sequence failed");
  CHECK(same_bytes(scratch_path("restir-frame.exr"), scratch_path("seq-5.exr")), "restir-di's sixth benchmark frame is not frame 5 of the sequence");
  CHECK(!same_bytes(scratch_path("restir-frame.exr"), scratch_path("seq-4.exr")), "frames 4 and 5 are equal: the test cannot tell them apart");
  /* by default the frame is shown, and written, through the real-time denoiser: the
   * third of three one-sample frames (each with new sample indices), as
   * valo_render_denoise_live gives it */
  const char *d[] = {"view", scene(), "--res", "64x48", "--benchmark", "3", "-o", scratch_path("path-denoised.exr"), NULL};
  CHECK(run_cli(d, 0, 300, g_out, sizeof g_out) == 0, "the denoised benchmark failed: %s", g_out);
  valo_error err;
  valo_scene *sc;
  CHECK(valo_scene_load(scene(), &sc, &err) == VALO_OK, "%s", err.message);
  valo_options o;
  valo_options_init(&o);
  o.width = 64; o.height = 48; o.aovs = 1 | VALO_AOVS_VARIANCE;
  valo_render *vr;
  float *px = malloc(64 * 48 * 3 * sizeof *px);
  CHECK(px && valo_render_create(sc, &o, &vr, &err) == VALO_OK, "%s", err.message);
  for (int f = 0; f < 3; f++)
    CHECK(valo_render_step(vr, 1, VALO_STEP_FRESH, &err) == VALO_OK && valo_render_denoise_live(vr, px, &err) == VALO_OK, "%s", err.message);
  CHECK(valo_image_write(scratch_path("api-denoised.exr"), 64, 48, px, NULL, &err) == VALO_OK, "%s", err.message);
  valo_render_destroy(vr);
  valo_scene_destroy(sc);
  free(px);
  CHECK(same_bytes(scratch_path("path-denoised.exr"), scratch_path("api-denoised.exr")), "view's denoised frame is not valo_render_denoise_live's");
  CHECK(!same_bytes(scratch_path("path-denoised.exr"), scratch_path("path-frame.exr")), "the denoised frame is the raw one");
  fprintf(stderr, "path and restir-di benchmark frames are the frames themselves, raw and denoised (fps %.1f)\n", fps);
  return 0;
}

static int refusals(void) {
  NEED_VIEWER();
  const char *bad[][8] = {{"view", scene(), "--frames", "3", "--benchmark", "1", NULL},
                          {"view", scene(), "--benchmark", "0", NULL},
                          {"view", scene(), "--adaptive", "--benchmark", "1", NULL},
                          {"view", "--benchmark", NULL}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    int rc = run_cli(bad[i], 0, 60, g_out, sizeof g_out);
    CHECK(rc == 2, "case %zu: exit %d, expected 2", i, rc);
  }
  const char *missing[] = {"view", "no-such-scene.json", "--benchmark", "1", NULL};
  int rc = run_cli(missing, 0, 60, g_out, sizeof g_out);
  CHECK(rc == 1 && strstr(g_out, "no-such-scene.json"), "a missing scene: exit %d, %s", rc, g_out);
  /* no display and no --benchmark: an error, not a window nobody sees */
  const char *nodisp[] = {"view", scene(), "--res", "16x16", NULL};
  rc = run_cli(nodisp, 0, 60, g_out, sizeof g_out);
  CHECK(rc == 1 && strstr(g_out, "cannot open a window"), "no display: exit %d, %s", rc, g_out);
  return 0;
}

/* Runs an xdotool command line on the display (through the shell); its exit code. */
static int xdo(const char *display, const char *args) {
  char cmd[1200];
  snprintf(cmd, sizeof cmd, "DISPLAY=%s timeout 20 xdotool %s > /dev/null 2>&1", display, args);
  return system(cmd);
}
/* Waits up to s seconds for text to appear in the file at path. */
static int wait_for(const char *path, const char *text, double s) {
  for (double t0 = wall_now(); wall_now() - t0 < s; nap_ms(100)) {
    char *f = read_text_file(path);
    int found = f && strstr(f, text);
    free(f);
    if (found) return 1;
  }
  return 0;
}

/* Two "camera" lines of the log: the position after "position": [ of the first and of the
 * last. */
static int camera_positions(const char *log, double first[3], double last[3]) {
  int n = 0;
  for (const char *p = log; (p = strstr(p, "\"position\": [")); p++) {
    double v[3];
    if (sscanf(p + 13, "%lf, %lf, %lf", &v[0], &v[1], &v[2]) != 3) return 0;
    memcpy(n ? last : first, v, sizeof v);
    n++;
  }
  return n >= 2;
}

/* The viewer on display, logging to log: C, a drag, P, Esc (the window is 320x240: 80x60
 * shown 4x). Sets *v to 0 once it has exited. */
static int drive(const char *display, const char *log, pid_t *v) {
  CHECK(xdo(display, "search --sync --onlyvisible --name \"valo view\"") == 0, "no viewer window appeared");
  nap_ms(500);
  xdo(display, "search --name \"valo view\" windowfocus --sync");
  CHECK(xdo(display, "key c") == 0 && wait_for(log, "\"camera\"", 20), "C printed no camera");
  CHECK(xdo(display, "search --name \"valo view\" mousemove --window %1 60 120 mousedown 1 sleep 0.1 mousemove --window %1 120 130 sleep 0.1 "
                     "mousemove --window %1 200 140 sleep 0.1 mouseup 1") == 0,
        "xdotool could not drag");
  nap_ms(1500); /* the moved camera refines */
  CHECK(xdo(display, "key p") == 0 && wait_for(log, "saved", 30), "P saved nothing");
  CHECK(xdo(display, "key Escape") == 0, "xdotool could not press Esc");
  int status = 0;
  pid_t got = 0;
  for (double t0 = wall_now(); wall_now() - t0 < 30 && (got = waitpid(*v, &status, WNOHANG)) == 0;) nap_ms(100);
  CHECK(got == *v && WIFEXITED(status) && WEXITSTATUS(status) == 0, "the viewer did not quit with exit 0 after Esc (status %d)", status);
  *v = 0;
  char *text = read_text_file(log);
  double a[3], b[3];
  int two = text && camera_positions(text, a, b);
  free(text);
  CHECK(two, "the log lacks the camera before and after the drag");
  double moved = (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
  CHECK(moved > 0.01, "the drag did not move the camera: (%g %g %g) -> (%g %g %g)", a[0], a[1], a[2], b[0], b[1], b[2]);
  image shot, first;
  CHECK(image_read(scratch_path("shot-0001.exr"), &shot, NULL) == 0 && shot.w == 80 && shot.h == 60, "shot-0001.exr is missing or not 80x60");
  CHECK(access(scratch_path("shot-0001.png"), R_OK) == 0, "shot-0001.png is missing");
  /* the saved view is not the first camera's */
  const char *r[] = {"render", scene(), "--res", "80x60", "--spp", "4", "-q", "-o", scratch_path("first.exr"), NULL};
  CHECK(run_cli(r, 0, 300, g_out, sizeof g_out) == 0, "valo render failed");
  CHECK(image_read(scratch_path("first.exr"), &first, NULL) == 0, "cannot read first.exr");
  double diff = 0, sum = 0;
  for (int i = 0; i < 80 * 60 * 3; i++) { diff += fabsf(shot.rgb[i] - first.rgb[i]); sum += first.rgb[i]; }
  image_free(&shot);
  image_free(&first);
  CHECK(diff > 0.3 * sum, "the saved image is the first camera's (mean difference %.3g of the mean)", diff / sum);
  fprintf(stderr, "camera moved (%g %g %g) -> (%g %g %g); the saved image differs from the first view by %.2f of its mean\n", a[0], a[1], a[2],
          b[0], b[1], b[2], diff / sum);
  return 0;
}

static int xvfb_drag_and_save(void) {
  NEED_VIEWER();
  if (system("command -v Xvfb > /dev/null 2>&1 && command -v xdotool > /dev/null 2>&1") != 0) {
    fprintf(stderr, "Xvfb or xdotool is not installed: %s\n", ci() ? "failing under CI=true" : "skipped");
    return ci() ? 1 : TEST_SKIP;
  }
  char display[16], cmd[300];
  snprintf(display, sizeof display, ":%d", 200 + (int)(getpid() % 500));
  const char *xa[] = {display, "-screen", "0", "800x600x24", "-nolisten", "tcp", NULL};
  pid_t xs = spawn_exe("Xvfb", xa, scratch_path("xvfb.log"));
  int ok = 0;
  snprintf(cmd, sizeof cmd, "DISPLAY=%s timeout 2 xdotool getmouselocation > /dev/null 2>&1", display);
  for (double t0 = wall_now(); wall_now() - t0 < 20 && !ok; nap_ms(100)) ok = system(cmd) == 0;
  int rc = 1;
  if (ok) {
    view_env(display);
    /* SDL dlopens the X libraries and unloads them in SDL_Quit, so what they keep for
     * the process's lifetime shows up from an unknown module that no suppression can
     * name: leaks are checked in the windowless cases only */
    const char *asan = getenv("ASAN_OPTIONS");
    char env[1100];
    snprintf(env, sizeof env, "%s%sdetect_leaks=0", asan ? asan : "", asan && *asan ? ":" : "");
    setenv("ASAN_OPTIONS", env, 1);
    const char *log = scratch_path("view.log");
    const char *va[] = {"view", scene(), "--res", "80x60", "-o", scratch_path("shot"), NULL};
    pid_t v = spawn_cli(va, log);
    rc = drive(display, log, &v);
    if (v > 0) { kill(v, SIGKILL); waitpid(v, NULL, 0); }
    if (rc) {
      char *text = read_text_file(log);
      fprintf(stderr, "the viewer's output:\n%s\n", text ? text : "(none)");
      free(text);
    }
  } else {
    fprintf(stderr, "Xvfb did not start on %s\n", display);
  }
  kill(xs, SIGTERM);
  waitpid(xs, NULL, 0);
  return rc;
}

/* The library calls under the viewer: steps on a still camera add up to valo_render_run's
 * image bit for bit; a moved camera gives another image and moving it back the first;
 * bad cameras, layers and renders are refused. */
static int step_api(void) {
  valo_error err;
  valo_scene *sc;
  CHECK(valo_scene_load(scene(), &sc, &err) == VALO_OK, "%s", err.message);
  valo_options o;
  valo_options_init(&o);
  o.width = 32; o.height = 24; o.spp = 4; o.threads = 2;
  valo_render *a, *b;
  CHECK(valo_render_create(sc, &o, &a, &err) == VALO_OK && valo_render_run(a, NULL, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(valo_render_create(sc, &o, &b, &err) == VALO_OK, "%s", err.message);
  CHECK(valo_render_step(b, 1, 1, &err) == VALO_OK && valo_render_step(b, 3, 0, &err) == VALO_OK, "%s", err.message);
  size_t n = 32 * 24 * 3;
  float *pa = malloc(n * sizeof *pa), *pb = malloc(n * sizeof *pb), *pc = malloc(n * sizeof *pc);
  valo_render_pixels(a, pa);
  CHECK(valo_render_layer(b, "", pb, &err) == VALO_OK, "%s", err.message);
  CHECK(!memcmp(pa, pb, n * sizeof *pa), "steps of 1 and 3 samples differ from a 4-spp render");
  CHECK(valo_render_layer(b, "spp", pc, &err) == VALO_OK && pc[0] == 4 && pc[n - 1] == 4, "the spp layer is not 4");
  CHECK(valo_render_layer(b, "albedo", pc, &err) == VALO_ERR_INVALID && strstr(err.message, "without AOVs"), "albedo without AOVs: %s", err.message);
  CHECK(valo_render_layer(b, "bogus", pc, &err) == VALO_ERR_INVALID, "an unknown layer was taken");
  valo_camera c0, c;
  valo_render_camera(b, &c0);
  c = c0;
  c.pos[0] += 0.5;
  CHECK(valo_render_set_camera(b, &c, &err) == VALO_OK && valo_render_step(b, 4, 1, &err) == VALO_OK, "%s", err.message);
  valo_render_pixels(b, pc);
  CHECK(memcmp(pa, pc, n * sizeof *pa) != 0, "moving the camera changed nothing");
  CHECK(valo_render_set_camera(b, &c0, &err) == VALO_OK && valo_render_step(b, 4, 1, &err) == VALO_OK, "%s", err.message);
  valo_render_pixels(b, pc);
  CHECK(!memcmp(pa, pc, n * sizeof *pa), "moving the camera back did not give the first image");
  c = c0;
  memcpy(c.look_at, c.pos, sizeof c.pos);
  CHECK(valo_render_set_camera(b, &c, &err) == VALO_ERR_INVALID, "a camera looking at itself was taken");
  c = c0;
  c.fov_deg = 0;
  CHECK(valo_render_set_camera(b, &c, &err) == VALO_ERR_INVALID, "a field of view of 0 was taken");
  /* an orthographic camera (its height; the field of view unused) is taken and reported back */
  c.ortho_height = 2;
  CHECK(valo_render_set_camera(b, &c, &err) == VALO_OK && valo_render_step(b, 4, 1, &err) == VALO_OK, "%s", err.message);
  valo_camera back;
  valo_render_camera(b, &back);
  CHECK(back.ortho_height == 2, "the orthographic height came back as %g", back.ortho_height);
  valo_render_pixels(b, pc);
  CHECK(memcmp(pa, pc, n * sizeof *pa) != 0, "an orthographic camera rendered the perspective image");
  c.ortho_height = -1;
  CHECK(valo_render_set_camera(b, &c, &err) == VALO_ERR_INVALID, "a negative orthographic height was taken");
  CHECK(valo_render_set_camera(b, &c0, &err) == VALO_OK, "%s", err.message);
  valo_camera now;
  valo_render_camera(b, &now);
  CHECK(!memcmp(&now, &c0, sizeof now), "a refused camera changed the render's");
  CHECK(valo_render_step(b, 0, 0, &err) == VALO_ERR_INVALID, "a step of 0 samples was taken");
  CHECK(valo_render_step(b, 1, 3, &err) == VALO_ERR_INVALID, "restart 3 was taken");
  /* VALO_STEP_FRESH: a new film of samples no film before used; restart 1 starts at 0 again */
  CHECK(valo_render_step(b, 4, 1, &err) == VALO_OK, "%s", err.message);
  valo_render_pixels(b, pb);
  CHECK(!memcmp(pa, pb, n * sizeof *pa), "restart 1 did not start at sample 0");
  CHECK(valo_render_step(b, 4, VALO_STEP_FRESH, &err) == VALO_OK, "%s", err.message);
  valo_render_pixels(b, pb);
  CHECK(memcmp(pa, pb, n * sizeof *pa) != 0, "a fresh restart repeated samples 0-3");
  CHECK(valo_render_step(b, 4, VALO_STEP_FRESH, &err) == VALO_OK, "%s", err.message);
  valo_render_pixels(b, pc);
  CHECK(memcmp(pc, pb, n * sizeof *pc) != 0, "two fresh restarts gave the same film");
  valo_render_destroy(a);
  valo_render_destroy(b);
  o.adaptive = VALO_ADAPTIVE_ERROR;
  CHECK(valo_render_create(sc, &o, &a, &err) == VALO_OK, "%s", err.message);
  CHECK(valo_render_step(a, 1, 1, &err) == VALO_ERR_INVALID, "a step of an adaptive render was taken");
  valo_render_destroy(a);
  valo_scene_destroy(sc);
  free(pa); free(pb); free(pc);
  return 0;
}

/* valo_render_denoise_live through the public API: refused without AOVs; the same bytes
 * for 1 and 2 threads (path, and restir-di's G-buffer AOVs); its frames lower the error of
 * the raw ones against the converged image; after a jump to a camera that sees only the
 * points behind the last camera (a closed room, turned round), the frame is exactly a fresh
 * render's, where after a turn of a few degrees it is not. And a
 * sequence's AOVs are its own frame's (film_clear empties them too). */
static valo_status albedo_mean(void *user, const valo_render *r, int frame, valo_error *err) {
  double *m = user;
  float px[16 * 12 * 3];
  valo_status st = valo_render_layer(r, "albedo", px, err);
  for (int i = 0; !st && i < 16 * 12 * 3; i++) m[frame] += px[i];
  return st;
}
static int live_denoise(void) {
  valo_error err;
  valo_scene *sc, *room;
  CHECK(valo_scene_load(scene(), &sc, &err) == VALO_OK, "%s", err.message);
  /* a closed room lit by a small lamp, diffuse walls */
  const char *rp = scratch_file("live-room.json",
                                "{\"camera\": {\"position\": [0, 0, 0], \"look_at\": [0.3, -0.2, -1], \"up\": [0, 1, 0], \"fov\": 60},\n"
                                " \"materials\": {\"wall\": {\"type\": \"diffuse\", \"reflectance\": 0.6},\n"
                                "   \"lamp\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": 20}},\n"
                                " \"shapes\": [{\"type\": \"cube\", \"flip_normals\": true, \"transform\": {\"scale\": 3}, \"material\": \"wall\"},\n"
                                "   {\"type\": \"cube\", \"transform\": {\"scale\": 0.8, \"translate\": [0.8, -2.2, -1.5]}, \"material\": \"wall\"},\n"
                                "   {\"type\": \"sphere\", \"center\": [0, 2.2, 0], \"radius\": 0.3, \"material\": \"lamp\"}]}\n");
  CHECK(valo_scene_load(rp, &room, &err) == VALO_OK, "%s", err.message);
  enum { W = 96, H = 72 };
  size_t n = W * H * 3;
  float *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b), *ref = malloc(n * sizeof *ref);
  valo_options o;
  valo_render *r, *r1;
  const char *integ[2] = {"path", "restir-di"};
  for (int k = 0; k < 2; k++) {
    /* the converged image (restir-di: direct light, as path --max-depth 1) */
    valo_options_init(&o);
    o.width = W; o.height = H; o.threads = 2; o.spp = 256; o.max_depth = k ? 1 : -1;
    CHECK(valo_render_create(room, &o, &r, &err) == VALO_OK && valo_render_run(r, NULL, NULL, &err) == VALO_OK, "%s", err.message);
    valo_render_pixels(r, ref);
    CHECK(valo_render_denoise_live(r, a, &err) == VALO_ERR_INVALID && strstr(err.message, "AOVs"), "denoised without AOVs: %s", err.message);
    valo_render_destroy(r);
    o.max_depth = -1;
    snprintf(o.integrator, sizeof o.integrator, "%s", integ[k]);
    if (k) snprintf(o.params, sizeof o.params, "reservoirs=1"); /* the viewer's */
    o.aovs = k ? 1 : 1 | VALO_AOVS_VARIANCE;
    CHECK(valo_render_create(room, &o, &r, &err) == VALO_OK, "%s", err.message);
    o.threads = 1;
    CHECK(valo_render_create(room, &o, &r1, &err) == VALO_OK, "%s", err.message);
    o.threads = 2;
    double e_raw = 0, e_dn = 0;
    for (int f = 0; f < 4; f++) {
      CHECK(valo_render_step(r, 1, k || !f, &err) == VALO_OK && valo_render_denoise_live(r, a, &err) == VALO_OK, "%s", err.message);
      CHECK(valo_render_step(r1, 1, k || !f, &err) == VALO_OK && valo_render_denoise_live(r1, b, &err) == VALO_OK, "%s", err.message);
      CHECK(!memcmp(a, b, n * sizeof *a), "%s: frame %d denoised differs between 1 and 2 threads", integ[k], f);
    }
    valo_render_destroy(r1);
    valo_render_pixels(r, b);
    for (size_t i = 0; i < n; i++) {
      double t = ref[i] > 0.01 ? ref[i] : 0.01;
      e_raw += (b[i] - ref[i]) * (b[i] - ref[i]) / (t * t);
      e_dn += (a[i] - ref[i]) * (a[i] - ref[i]) / (t * t);
    }
    fprintf(stderr, "live_denoise: %s, the fourth frame's relMSE %.4f raw, %.4f denoised\n", integ[k], e_raw / n, e_dn / n);
    CHECK(e_dn * 2 < e_raw, "%s: denoising brought relMSE only from %.4f to %.4f", integ[k], e_raw / n, e_dn / n);
    if (k) { valo_render_destroy(r); continue; }
    /* the jump: from looking one way to looking the other (every point then seen lies
     * behind the last camera) */
    valo_camera c;
    valo_render_camera(r, &c);
    c.look_at[0] = -0.3; c.look_at[2] = 1;
    CHECK(valo_render_set_camera(r, &c, &err) == VALO_OK && valo_render_step(r, 1, 1, &err) == VALO_OK && valo_render_denoise_live(r, a, &err) == VALO_OK, "%s", err.message);
    CHECK(valo_render_create(room, &o, &r1, &err) == VALO_OK && valo_render_set_camera(r1, &c, &err) == VALO_OK, "%s", err.message);
    CHECK(valo_render_step(r1, 1, 1, &err) == VALO_OK && valo_render_denoise_live(r1, b, &err) == VALO_OK, "%s", err.message);
    CHECK(!memcmp(a, b, n * sizeof *a), "after the jump the frame kept history");
    double sum = 0;
    for (size_t i = 0; i < n; i++) sum += a[i];
    CHECK(sum > 0, "the room is black: the test shows nothing");
    /* and a turn of a few degrees keeps most of it */
    c.look_at[0] = -0.25;
    CHECK(valo_render_set_camera(r, &c, &err) == VALO_OK && valo_render_step(r, 1, 1, &err) == VALO_OK && valo_render_denoise_live(r, a, &err) == VALO_OK, "%s", err.message);
    CHECK(valo_render_set_camera(r1, &c, &err) == VALO_OK && valo_render_step(r1, 1, 1, &err) == VALO_OK, "%s", err.message);
    valo_render_denoise_reset(r1);
    CHECK(valo_render_denoise_live(r1, b, &err) == VALO_OK, "%s", err.message);
    CHECK(memcmp(a, b, n * sizeof *a) != 0, "a small turn lost the whole history");
    valo_render_destroy(r1);
    valo_render_destroy(r);
  }
  valo_scene_destroy(room);
  /* a sequence's AOVs */
  valo_options_init(&o);
  o.width = 16; o.height = 12; o.spp = 2; o.frames = 2; o.aovs = 1; o.threads = 2;
  double m[2] = {0, 0};
  CHECK(valo_render_create(sc, &o, &r, &err) == VALO_OK, "%s", err.message);
  valo_render_on_frame(r, albedo_mean, m);
  CHECK(valo_render_run(r, NULL, NULL, &err) == VALO_OK, "%s", err.message);
  valo_render_destroy(r);
  CHECK(m[0] > 0 && fabs(m[1] / m[0] - 1) < 0.05, "the second frame's albedo is %.3f of the first's", m[1] / m[0]);
  valo_scene_destroy(sc);
  free(a); free(b); free(ref);
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"step_api", step_api}, {"live_denoise", live_denoise}, {"benchmark_frames", benchmark_frames}, {"refusals", refusals}, {"xvfb_drag_and_save", xvfb_drag_and_save}, {NULL, NULL}};
  return test_main(argc, argv, cases);
}
