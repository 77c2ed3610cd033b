/* test_determinism.c — the same seed gives bit-identical images for 1, 2 and 7 threads
 * (pixels and the EXR file bytes), on a self-contained scene exercising every material
 * and light type; a different seed gives a different image. Cancelling keeps the finished
 * passes (cancel_keeps_passes, cancel_mid_pass). A crop window renders that part of the
 * frame's image bit for bit (crop_is_part_of_frame). The walk through participating
 * media too (media_threads_identical, scenes/cornell-media.json). path's wavefront gives
 * one path at a time's image (batch_same_image). */
#include "harness.h"
#include "image/image_io.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *scene_json =
    "{ \"camera\": {\"position\": [0,1,4], \"look_at\": [0,0.5,0], \"up\": [0,1,0], \"fov\": 45},\n"
    "  \"film\": {\"width\": 48, \"height\": 40}, \"render\": {\"spp\": 24, \"seed\": 11},\n"
    "  \"materials\": {\n"
    "    \"floor\": {\"type\": \"diffuse\", \"reflectance\": [0.7,0.6,0.5]},\n"
    "    \"glass\": {\"type\": \"dielectric\", \"ior\": 1.5},\n"
    "    \"gold\": {\"type\": \"conductor\", \"preset\": \"Au\"},\n"
    "    \"plastic\": {\"type\": \"phong\", \"diffuse\": [0.2,0.3,0.6], \"specular\": 0.3, \"exponent\": 40},\n"
    "    \"mirror\": {\"type\": \"mirror\", \"reflectance\": 0.9},\n"
    "    \"lamp\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": [4,4,3]}},\n"
    "  \"shapes\": [\n"
    "    {\"type\": \"sphere\", \"center\": [0,-100,0], \"radius\": 100, \"subdivisions\": 6, \"material\": \"floor\"},\n"
    "    {\"type\": \"sphere\", \"center\": [-1,0.5,0], \"radius\": 0.5, \"subdivisions\": 3, \"material\": \"glass\"},\n"
    "    {\"type\": \"sphere\", \"center\": [0,0.5,-0.5], \"radius\": 0.5, \"subdivisions\": 3, \"material\": \"gold\"},\n"
    "    {\"type\": \"sphere\", \"center\": [1,0.5,0], \"radius\": 0.5, \"subdivisions\": 3, \"material\": \"plastic\"},\n"
    "    {\"type\": \"sphere\", \"center\": [0.4,0.25,0.8], \"radius\": 0.25, \"subdivisions\": 2, \"material\": \"mirror\"},\n"
    "    {\"type\": \"sphere\", \"center\": [0,3,0], \"radius\": 0.3, \"subdivisions\": 2, \"material\": \"lamp\"}],\n"
    "  \"lights\": [{\"type\": \"point\", \"position\": [2,3,2], \"intensity\": 5},\n"
    "             {\"type\": \"spot\", \"position\": [-2,3,1], \"look_at\": [0,0,0], \"intensity\": 20, \"cone_angle\": 25},\n"
    "             {\"type\": \"directional\", \"direction\": [-1,-2,-1], \"irradiance\": 0.5}],\n"
    "  \"environment\": {\"type\": \"constant\", \"radiance\": [0.1,0.15,0.2]} }\n";

static int render_threads(int threads, int64_t seed, float **px, int *w, int *h) {
  valo_options o;
  valo_options_init(&o);
  o.threads = threads;
  o.seed = seed;
  *px = render_json_text(scene_json, &o, w, h);
  return *px ? 0 : 1;
}

static int threads_bit_identical(void) {
  float *a, *b, *c, *d;
  int w, h;
  CHECK(render_threads(1, 11, &a, &w, &h) == 0, "render failed");
  CHECK(render_threads(2, 11, &b, &w, &h) == 0, "render failed");
  CHECK(render_threads(7, 11, &c, &w, &h) == 0, "render failed");
  CHECK(render_threads(2, 12, &d, &w, &h) == 0, "render failed");
  size_t n = (size_t)w * h * 3 * sizeof(float);
  double sum = 0;
  for (int i = 0; i < w * h * 3; i++) { CHECK(isfinite(a[i]) && a[i] >= 0, "bad pixel value %g", a[i]); sum += a[i]; }
  CHECK(sum > 0, "image is black");
  CHECK(memcmp(a, b, n) == 0, "1 and 2 threads differ");
  CHECK(memcmp(a, c, n) == 0, "1 and 7 threads differ");
  CHECK(memcmp(a, d, n) != 0, "a different seed gave the same image");
  free(a); free(b); free(c); free(d);
  return 0;
}

/* guided: its trees (and each leaf's learned BSDF fraction) come from fixed-point sums, so
 * the image does not depend on the thread count either. */
static int guided_threads_identical(void) {
  float *px[3];
  int w = 0, h = 0;
  const int threads[3] = {1, 2, 7};
  for (int k = 0; k < 3; k++) {
    valo_options o;
    valo_options_init(&o);
    o.threads = threads[k];
    o.seed = 5;
    o.spp = 16;
    snprintf(o.integrator, sizeof o.integrator, "guided");
    px[k] = render_json_text(scene_json, &o, &w, &h);
    CHECK(px[k], "render failed");
  }
  double sum = 0;
  for (int i = 0; i < w * h * 3; i++) sum += px[0][i];
  CHECK(sum > 0, "image is black");
  size_t n = (size_t)w * h * 3 * sizeof(float);
  CHECK(memcmp(px[0], px[1], n) == 0 && memcmp(px[0], px[2], n) == 0, "1, 2 and 7 threads differ");
  for (int k = 0; k < 3; k++) free(px[k]);
  return 0;
}

/* --crop / film.crop_*: the film is a window of the frame, and each of its pixels takes the
 * frame pixel's random numbers, so a crop is that part of the whole image bit for bit:
 * pixels and depth AOV, for the perspective camera with the Gaussian filter, and for
 * orthographic and spherical cameras (their rays offset by the window's corner). Given
 * alone, crop_x runs to the frame's right edge. */
static int media_threads_identical(void) {
  float *px[2];
  int w = 0, h = 0;
  for (int k = 0; k < 2; k++) {
    valo_options o;
    valo_options_init(&o);
    o.threads = k ? 3 : 1;
    o.width = 40; o.height = 32; o.spp = 8;
    valo_scene *sc;
    valo_render *r = render_file(VALO_SOURCE_DIR "/scenes/cornell-media.json", &o, &sc);
    CHECK(r, "render failed");
    valo_stats st;
    valo_render_stats(r, &st);
    w = st.width; h = st.height;
    px[k] = malloc((size_t)w * h * 3 * sizeof(float));
    valo_render_pixels(r, px[k]);
    valo_render_destroy(r);
    valo_scene_destroy(sc);
  }
  double sum = 0;
  for (int i = 0; i < w * h * 3; i++) sum += px[0][i];
  CHECK(sum > 0, "image is black");
  CHECK(memcmp(px[0], px[1], (size_t)w * h * 3 * sizeof(float)) == 0, "1 and 3 threads differ");
  free(px[0]); free(px[1]);
  return 0;
}

static int crop_is_part_of_frame(void) {
  static const char *const cams[3] = {"", "\"type\": \"orthographic\", \"height\": 3, ", "\"type\": \"spherical\", "};
  for (int k = 0; k < 3; k++) {
    char json[4096];
    const char *at = strstr(scene_json, "\"position\": [0,1,4]");
    CHECK(at, "the scene's camera");
    snprintf(json, sizeof json, "%.*s%s%s", (int)(at - scene_json), scene_json, cams[k], at);
    if (k) { char *fov = strstr(json, ", \"fov\": 45"); CHECK(fov, "fov"); memmove(fov, fov + 11, strlen(fov + 11) + 1); }
    const char *path = scratch_file("crop.json", json);
    valo_options o;
    valo_options_init(&o);
    o.aovs = 1;
    o.threads = 2;
    snprintf(o.filter, sizeof o.filter, "%s", k ? "box" : "gaussian");
    valo_scene *sc, *sc_part; /* each render reads its scene until it is destroyed */
    valo_render *full = render_file(path, &o, &sc);
    CHECK(full, "render failed");
    o.crop_x = 13; o.crop_y = 7; o.crop_width = 20; o.crop_height = 25;
    o.threads = 3;
    valo_render *part = render_file(path, &o, &sc_part);
    CHECK(part, "crop render failed");
    valo_stats st;
    valo_render_stats(part, &st);
    CHECK(st.width == 20 && st.height == 25, "the crop's image is %dx%d", st.width, st.height);
    float *a = malloc(48 * 40 * 3 * sizeof *a), *b = malloc(20 * 25 * 3 * sizeof *b);
    valo_error err;
    for (int layer = 0; layer < 2; layer++) {
      CHECK(valo_render_layer(full, layer ? "depth" : "", a, &err) == VALO_OK && valo_render_layer(part, layer ? "depth" : "", b, &err) == VALO_OK,
            "%s", err.message);
      int differ = 0;
      for (int y = 0; y < 25; y++) differ += memcmp(&b[3 * (y * 20)], &a[3 * ((y + 7) * 48 + 13)], 20 * 3 * sizeof *a) != 0;
      CHECK(!differ, "camera %d, %s: %d rows of the crop differ from the frame's", k, layer ? "depth" : "image", differ);
    }
    valo_render_destroy(part);
    valo_scene_destroy(sc_part);
    o.crop_x = 40; o.crop_y = o.crop_width = o.crop_height = VALO_UNSET;
    part = render_file(path, &o, &sc_part);
    CHECK(part, "crop render failed");
    valo_render_stats(part, &st);
    CHECK(st.width == 8 && st.height == 40, "crop_x 40 alone gives %dx%d, not the frame's last 8 columns", st.width, st.height);
    valo_render_pixels(part, b);
    valo_render_pixels(full, a);
    for (int y = 0; y < 40; y++) CHECK(!memcmp(&b[3 * (y * 8)], &a[3 * (y * 48 + 40)], 8 * 3 * sizeof *a), "row %d of the last columns differs", y);
    valo_render_destroy(part);
    valo_scene_destroy(sc_part);
    valo_render_destroy(full);
    valo_scene_destroy(sc);
    free(a); free(b);
  }
  return 0;
}

static int read_all(const char *path, unsigned char **buf, long *len) {
  FILE *f = fopen(path, "rb");
  if (!f) return -1;
  fseek(f, 0, SEEK_END);
  *len = ftell(f);
  fseek(f, 0, SEEK_SET);
  *buf = malloc(*len);
  size_t got = fread(*buf, 1, *len, f);
  fclose(f);
  return got == (size_t)*len ? 0 : -1;
}

static int exr_bytes_identical(void) {
  const char *path = scratch_file("det.json", scene_json);
  char out[3][1200];
  int threads[3] = {1, 2, 7};
  for (int i = 0; i < 3; i++) {
    valo_options o;
    valo_options_init(&o);
    o.threads = threads[i];
    valo_error err;
    valo_scene *sc;
    valo_render *r = render_file(path, &o, &sc);
    CHECK(r, "render failed");
    snprintf(out[i], sizeof out[i], "%s/det%d.exr", scratch_dir(), threads[i]);
    CHECK(valo_render_write(r, out[i], NULL, &err) == VALO_OK, "%s", err.message);
    valo_render_destroy(r);
    valo_scene_destroy(sc);
  }
  unsigned char *b0, *b1;
  long l0, l1;
  CHECK(read_all(out[0], &b0, &l0) == 0, "cannot read %s", out[0]);
  for (int i = 1; i < 3; i++) {
    CHECK(read_all(out[i], &b1, &l1) == 0, "cannot read %s", out[i]);
    CHECK(l0 == l1 && memcmp(b0, b1, l0) == 0, "EXR bytes differ between 1 and %d threads", threads[i]);
    free(b1);
  }
  free(b0);
  return 0;
}

/* Adaptive sampling decides between rounds from deterministic sums: still identical. */
static int adaptive_threads_identical(void) {
  float *px[3];
  int w, h, threads[3] = {1, 2, 7};
  for (int i = 0; i < 3; i++) {
    valo_options o;
    valo_options_init(&o);
    o.threads = threads[i];
    o.adaptive = 1;
    px[i] = render_json_text(scene_json, &o, &w, &h);
    CHECK(px[i], "render failed");
  }
  size_t n = (size_t)w * h * 3 * sizeof(float);
  CHECK(memcmp(px[0], px[1], n) == 0 && memcmp(px[0], px[2], n) == 0, "adaptive renders differ between thread counts");
  for (int i = 0; i < 3; i++) free(px[i]);
  return 0;
}

/* path's wavefront (--batch N: N camera samples traced stage by stage, the shadow rays of
 * a stage queried together) adds the same terms in the same order as one path at a time:
 * on the kd-tree (one query at a time either way) the image and its depth AOV are the
 * same bytes for batches of 1, 7 (stages that end mid-pixel) and 256, with the filter
 * sampled and splatted (the film's rounds), and for adaptive sampling (its targets per
 * pixel). With Embree a batch's shadow rays go through rtcOccluded1M, whose packets may
 * decide a grazing ray differently: at most 0.5 % of the channels may differ there,
 * and the mean by at most 0.1 %. The 1-thread batch of 256 is also the 3-thread one. */
static float *render_batch(const char *accel, int batch, int threads, int variant, float **depth, int *w, int *h) {
  const char *path = scratch_file("batch.json", scene_json);
  valo_options o;
  valo_options_init(&o);
  o.threads = threads;
  o.batch = batch;
  o.aovs = 1;
  o.spp = 12;
  snprintf(o.accel, sizeof o.accel, "%s", accel);
  if (variant == 1) { snprintf(o.filter, sizeof o.filter, "gaussian"); o.splat = 1; }
  if (variant == 2) o.adaptive = 1;
  valo_scene *sc;
  valo_render *r = render_file(path, &o, &sc);
  if (!r) return NULL;
  valo_stats st;
  valo_render_stats(r, &st);
  *w = st.width; *h = st.height;
  float *px = malloc((size_t)*w * *h * 3 * sizeof *px);
  *depth = malloc((size_t)*w * *h * 3 * sizeof **depth);
  valo_error err;
  valo_render_pixels(r, px);
  if (valo_render_layer(r, "depth", *depth, &err) != VALO_OK) { free(px); px = NULL; }
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  return px;
}

static int batch_same_image(void) {
  static const char *const accels[2] = {"kdtree", "embree"};
  for (int a = 0; a < 2; a++)
    for (int variant = 0; variant < 3; variant++) {
      float *ref_d, *ref = NULL;
      int w, h, n;
      ref = render_batch(accels[a], 1, 2, variant, &ref_d, &w, &h);
      CHECK(ref, "render failed");
      n = w * h * 3;
      double sum_ref = 0;
      for (int i = 0; i < n; i++) { CHECK(isfinite(ref[i]) && ref[i] >= 0, "bad pixel %g", ref[i]); sum_ref += ref[i]; }
      CHECK(sum_ref > 0, "black image");
      static const int batches[3][2] = {{7, 2}, {256, 2}, {256, 3}};
      for (int k = 0; k < 3; k++) {
        float *d, *px = render_batch(accels[a], batches[k][0], batches[k][1], variant, &d, &w, &h);
        CHECK(px, "render failed");
        int differ = 0;
        double sum = 0;
        for (int i = 0; i < n; i++) { differ += px[i] != ref[i]; sum += px[i]; }
        if (a == 0) {
          CHECK(differ == 0, "kd-tree, variant %d, batch %d: %d of %d channels differ from one path at a time", variant, batches[k][0], differ, n);
          CHECK(!memcmp(d, ref_d, (size_t)n * sizeof *d), "kd-tree, variant %d, batch %d: the depth AOV differs", variant, batches[k][0]);
        } else {
          CHECK(differ <= n / 200 && fabs(sum / sum_ref - 1) < 1e-3, "embree, variant %d, batch %d: %d of %d channels differ, mean ratio %g",
                variant, batches[k][0], differ, n, sum / sum_ref);
        }
        free(px); free(d);
      }
      free(ref); free(ref_d);
    }
  return 0;
}

/* Cancelling keeps what is finished: a progress callback that cancels after
 * the third pass leaves the film holding exactly those passes, bit-identical to a render
 * asked for that many samples; a cancel from another thread mid-pass leaves a finite,
 * lit image with every pixel holding at least the whole passes. */
static int cancel_after(void *user, double frac, int spp_done, double seconds) {
  (void)frac; (void)seconds;
  int *calls = user;
  (void)spp_done;
  return ++*calls >= 3;
}

static int cancel_keeps_passes(void) {
  const char *path = scratch_file("cancel.json", scene_json);
  valo_error err;
  valo_scene *sc = NULL;
  CHECK(valo_scene_load(path, &sc, &err) == VALO_OK, "%s", err.message);
  valo_options o;
  valo_options_init(&o);
  o.spp = 1000;
  o.threads = 2;
  valo_render *r = NULL;
  CHECK(valo_render_create(sc, &o, &r, &err) == VALO_OK, "%s", err.message);
  int calls = 0;
  valo_status st = valo_render_run(r, cancel_after, &calls, &err);
  CHECK(st == VALO_ERR_CANCELLED, "status %d after cancelling", (int)st);
  CHECK(!check_losses(r), "samples lost");
  valo_stats s;
  valo_render_stats(r, &s);
  fprintf(stderr, "cancelled after %d passes: %d spp, %llu samples (%s)\n", calls, s.spp_done, (unsigned long long)s.samples, err.message);
  CHECK(s.spp_done > 0 && s.spp_done < 1000, "spp_done %d", s.spp_done);
  CHECK(s.samples == (uint64_t)s.spp_done * s.width * s.height, "samples %llu for %d whole passes", (unsigned long long)s.samples, s.spp_done);
  size_t n = (size_t)s.width * s.height * 3;
  float *a = malloc(n * sizeof *a);
  valo_render_pixels(r, a);
  char out[1200];
  snprintf(out, sizeof out, "%s/cancelled.exr", scratch_dir());
  CHECK(valo_render_write(r, out, NULL, &err) == VALO_OK, "%s", err.message);
  valo_render_destroy(r);
  o.spp = s.spp_done;
  float *b = NULL;
  int w, h;
  b = render_json_text(scene_json, &o, &w, &h);
  CHECK(b, "render failed");
  double sum = 0;
  for (size_t i = 0; i < n; i++) sum += a[i];
  CHECK(sum > 0, "the cancelled film is black");
  CHECK(memcmp(a, b, n * sizeof *a) == 0, "the cancelled film differs from a %d-spp render", s.spp_done);
  image im;
  CHECK(image_read(out, &im, &err) == VALO_OK, "%s", err.message);
  CHECK(im.w == s.width && im.h == s.height && memcmp(im.rgb, a, n * sizeof *a) == 0, "the written EXR is not the film");
  image_free(&im);
  free(a); free(b);
  valo_scene_destroy(sc);
  return 0;
}

#include <pthread.h>
#include <stdatomic.h>
#include <time.h>
/* The canceller waits until the first pass has finished (so at least one whole pass is
 * kept whatever the machine's speed), then cancels a little later, mid-pass. */
typedef struct canceller { valo_render *r; atomic_int passes; } canceller;
static int count_pass(void *user, double frac, int spp_done, double seconds) {
  (void)frac; (void)spp_done; (void)seconds;
  atomic_fetch_add(&((canceller *)user)->passes, 1);
  return 0;
}
static void *cancel_soon(void *user) {
  canceller *c = user;
  struct timespec ts = {0, 5000000};
  while (atomic_load(&c->passes) == 0) nanosleep(&ts, NULL);
  struct timespec later = {0, 150000000};
  nanosleep(&later, NULL);
  valo_render_cancel(c->r);
  return NULL;
}
static int cancel_mid_pass(void) {
  const char *path = scratch_file("cancel2.json", scene_json);
  valo_error err;
  valo_scene *sc = NULL;
  CHECK(valo_scene_load(path, &sc, &err) == VALO_OK, "%s", err.message);
  valo_options o;
  valo_options_init(&o);
  o.spp = 1000000;
  o.width = 160; o.height = 120;
  valo_render *r = NULL;
  CHECK(valo_render_create(sc, &o, &r, &err) == VALO_OK, "%s", err.message);
  canceller c;
  c.r = r;
  atomic_init(&c.passes, 0);
  pthread_t th;
  pthread_create(&th, NULL, cancel_soon, &c);
  valo_status st = valo_render_run(r, count_pass, &c, &err);
  pthread_join(th, NULL);
  CHECK(st == VALO_ERR_CANCELLED, "status %d", (int)st);
  CHECK(!check_losses(r), "samples lost");
  valo_stats s;
  valo_render_stats(r, &s);
  fprintf(stderr, "cancelled mid-render: %d spp, %llu samples\n", s.spp_done, (unsigned long long)s.samples);
  CHECK(s.spp_done > 0, "no whole pass kept");
  CHECK(s.samples >= (uint64_t)s.spp_done * s.width * s.height, "fewer samples than whole passes");
  size_t n = (size_t)s.width * s.height * 3;
  float *a = malloc(n * sizeof *a);
  valo_render_pixels(r, a);
  double sum = 0;
  for (size_t i = 0; i < n; i++) { CHECK(isfinite(a[i]) && a[i] >= 0, "pixel value %g", a[i]); sum += a[i]; }
  CHECK(sum > 0, "black image");
  free(a);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"threads_bit_identical", threads_bit_identical}, {"guided_threads_identical", guided_threads_identical}, {"crop_is_part_of_frame", crop_is_part_of_frame}, {"media_threads_identical", media_threads_identical}, {"exr_bytes_identical", exr_bytes_identical},
                                    {"adaptive_threads_identical", adaptive_threads_identical}, {"batch_same_image", batch_same_image},
                                    {"cancel_keeps_passes", cancel_keeps_passes}, {"cancel_mid_pass", cancel_mid_pass}, {NULL, NULL}};
  return test_main(argc, argv, cases);
}
