/* test_photon.c — the photon integrator (src/integrator/photon.c, digest 003):
 *  - on CornellBox-Original it matches the independent reference (mean per channel within
 *    2 % at the default 100 000 photons);
 *  - its density estimate converges: with final gathering off, the lit 16x16 blocks'
 *    mean error against the reference falls as the photon count grows, and the mean is
 *    within 2 % at 400 000;
 *  - scenes/caustic.json: the caustic a glass sphere throws on the floor has the
 *    brightness of a converged `path` render (tests/data/caustic-path.exr, 32 768 spp);
 *  - the same image for 1, 2 and 7 threads (photon maps built in fixed chunks). */
#include "harness.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef VALO_SOURCE_DIR
#define VALO_SOURCE_DIR "."
#endif

static float *render_cornell(const char *params, int spp, int *w, int *h) {
  const char *obj = shared_file("scenes/cornell/CornellBox-Original.obj");
  if (!obj) return NULL;
  char json[2048];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [0,1,3.4], \"look_at\": [0,1,0], \"up\": [0,1,0], \"fov\": 40},\n"
           "  \"film\": {\"width\": 256, \"height\": 256},\n"
           "  \"render\": {\"integrator\": \"photon\", \"spp\": %d, \"seed\": 7, \"photon\": {%s}},\n"
           "  \"shapes\": [ {\"file\": \"%s\"} ] }\n", spp, params, obj);
  return render_json_text(json, NULL, w, h);
}

static int fcmp(const void *a, const void *b) { float x = *(const float *)a, y = *(const float *)b; return (x > y) - (x < y); }

typedef struct cmp { double mean_err[3], block_mean, block_worst; } cmp;
static void compare(const float *img, const float *ref, int w, int h, cmp *c) {
  double si[3] = {0}, sr[3] = {0};
  for (int i = 0; i < w * h; i++)
    for (int k = 0; k < 3; k++) { si[k] += img[3 * i + k]; sr[k] += ref[3 * i + k]; }
  for (int k = 0; k < 3; k++) c->mean_err[k] = fabs(si[k] / sr[k] - 1);
  double mean = (sr[0] + sr[1] + sr[2]) / (3.0 * w * h), sum = 0;
  int n = 0;
  c->block_worst = 0;
  for (int by = 0; by + 16 <= h; by += 16)
    for (int bx = 0; bx + 16 <= w; bx += 16) {
      double a = 0, b = 0;
      for (int y = by; y < by + 16; y++)
        for (int x = bx; x < bx + 16; x++)
          for (int k = 0; k < 3; k++) { a += img[3 * (y * w + x) + k]; b += ref[3 * (y * w + x) + k]; }
      if (b / (3 * 256) < 0.05 * mean) continue;
      double e = fabs(a / b - 1);
      sum += e;
      n++;
      if (e > c->block_worst) c->block_worst = e;
    }
  c->block_mean = n ? sum / n : 1;
}

static int photon_cornell_reference(void) {
  const char *refp = shared_file("references/cornell-original.exr");
  if (!refp) return TEST_SKIP;
  image ref;
  valo_error err;
  CHECK(image_read(refp, &ref, &err) == VALO_OK, "%s", err.message);
  int w, h;
  float *img = render_cornell("", 2, &w, &h);
  CHECK(img && w == ref.w && h == ref.h, "render");
  for (int i = 0; i < w * h * 3; i++) CHECK(isfinite(img[i]) && img[i] >= 0, "pixel %d = %g", i, img[i]);
  cmp c;
  compare(img, ref.rgb, w, h, &c);
  fprintf(stderr, "photon (100 000 photons, 32 gather rays, 2 spp): mean error R %.2f%% G %.2f%% B %.2f%%; lit 16x16 blocks: mean %.2f%%, worst %.2f%%\n",
          100 * c.mean_err[0], 100 * c.mean_err[1], 100 * c.mean_err[2], 100 * c.block_mean, 100 * c.block_worst);
  for (int k = 0; k < 3; k++) CHECK(c.mean_err[k] < 0.02, "channel %d off by %.2f%%", k, 100 * c.mean_err[k]);
  CHECK(c.block_mean < 0.06, "blocks off by %.2f%% on average", 100 * c.block_mean);
  free(img);
  image_free(&ref);
  return 0;
}

static int photon_converges(void) {
  const char *refp = shared_file("references/cornell-original.exr");
  if (!refp) return TEST_SKIP;
  image ref;
  valo_error err;
  CHECK(image_read(refp, &ref, &err) == VALO_OK, "%s", err.message);
  const int counts[3] = {20000, 100000, 400000};
  cmp c[3];
  for (int i = 0; i < 3; i++) {
    char p[128];
    snprintf(p, sizeof p, "\"gather\": 0, \"global\": %d", counts[i]);
    int w, h;
    float *img = render_cornell(p, 1, &w, &h);
    CHECK(img, "render");
    compare(img, ref.rgb, w, h, &c[i]);
    fprintf(stderr, "density estimate alone, %6d photons: mean error R %.2f%% G %.2f%% B %.2f%%; lit blocks mean %.2f%% worst %.2f%%\n",
            counts[i], 100 * c[i].mean_err[0], 100 * c[i].mean_err[1], 100 * c[i].mean_err[2], 100 * c[i].block_mean, 100 * c[i].block_worst);
    free(img);
  }
  CHECK(c[1].block_mean < 0.85 * c[0].block_mean && c[2].block_mean < 0.85 * c[1].block_mean, "block error does not fall: %g %g %g",
        c[0].block_mean, c[1].block_mean, c[2].block_mean);
  for (int k = 0; k < 3; k++) CHECK(c[2].mean_err[k] < 0.02, "channel %d off by %.2f%% at 400 000", k, 100 * c[2].mean_err[k]);
  image_free(&ref);
  return 0;
}

static int photon_caustic(void) {
  image ref;
  valo_error err;
  CHECK(image_read(VALO_SOURCE_DIR "/tests/data/caustic-path.exr", &ref, &err) == VALO_OK, "%s", err.message);
  valo_options o;
  valo_options_init(&o);
  o.spp = 8;
  valo_scene *sc;
  valo_render *r = render_file(VALO_SOURCE_DIR "/scenes/caustic.json", &o, &sc);
  CHECK(r, "render");
  int w = ref.w, h = ref.h;
  float *img = malloc((size_t)w * h * 3 * sizeof *img);
  valo_render_pixels(r, img);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  /* the caustic: pixels of the reference brighter than 3x the floor's median outside it */
  float *lum = malloc((size_t)w * h * sizeof *lum), *sorted = malloc((size_t)w * h * sizeof *sorted);
  for (int i = 0; i < w * h; i++) sorted[i] = lum[i] = ref.rgb[3 * i + 1];
  qsort(sorted, (size_t)w * h, sizeof *sorted, fcmp);
  float med = sorted[w * h / 2];
  double sa = 0, sb = 0;
  int n = 0;
  for (int i = 0; i < w * h; i++)
    if (lum[i] > 3 * med) { sa += img[3 * i + 1]; sb += ref.rgb[3 * i + 1]; n++; }
  fprintf(stderr, "caustic: %d pixels above 3x the median %.3f; photon %.4f, path reference %.4f (ratio %.3f)\n", n, med, sa / n, sb / n, sa / sb);
  CHECK(n > 100, "caustic region of %d pixels", n);
  CHECK(fabs(sa / sb - 1) < 0.05, "caustic brightness off by %.1f%%", 100 * fabs(sa / sb - 1));
  free(lum); free(sorted); free(img);
  image_free(&ref);
  return 0;
}

static int photon_threads(void) {
  valo_options o;
  valo_options_init(&o);
  o.spp = 2;
  o.width = o.height = 40;
  snprintf(o.params, sizeof o.params, "global=8000 caustic=3000 gather=8");
  float *img[3] = {NULL, NULL, NULL};
  const int th[3] = {1, 2, 7};
  for (int i = 0; i < 3; i++) {
    o.threads = th[i];
    valo_scene *sc;
    snprintf(o.integrator, sizeof o.integrator, "photon");
    valo_render *r = render_file(VALO_SOURCE_DIR "/scenes/default.json", &o, &sc);
    CHECK(r, "render");
    img[i] = malloc(40 * 40 * 3 * sizeof(float));
    valo_render_pixels(r, img[i]);
    valo_render_destroy(r);
    valo_scene_destroy(sc);
  }
  CHECK(!memcmp(img[0], img[1], 40 * 40 * 3 * sizeof(float)) && !memcmp(img[0], img[2], 40 * 40 * 3 * sizeof(float)), "threads change the image");
  for (int i = 0; i < 3; i++) free(img[i]);
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"photon_cornell_reference", photon_cornell_reference},
                                    {"photon_converges", photon_converges},
                                    {"photon_caustic", photon_caustic},
                                    {"photon_threads", photon_threads},
                                    {NULL, NULL}};
  return test_main(argc, argv, cases);
}
