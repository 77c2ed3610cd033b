/* test_reference.c — valo's `path` renders against independent Blender Cycles references
 * (../shared/references): mean radiance per channel within 1 %, every lit block within
 * 3 % (16x16 blocks; 32x32 for scenes with caustics). Sample counts are chosen so valo's
 * own block noise is several times below the tolerance (see docs/performance.md). */
#include "harness.h"
#include "valo/valo.h"
#include "image/image_io.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int run_reference_with(const char *obj_rel, const char *ref_rel, int spp, int block, const char *integrator) {
  const char *obj = shared_file(obj_rel), *refp = shared_file(ref_rel);
  if (!obj || !refp) return TEST_SKIP;
  char json[4096];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [0,1,3.4], \"look_at\": [0,1,0], \"up\": [0,1,0], \"fov\": 40},\n"
           "  \"film\": {\"width\": 256, \"height\": 256},\n"
           "  \"render\": {\"spp\": %d, \"seed\": 7, \"integrator\": \"%s\"},\n"
           "  \"shapes\": [ {\"file\": \"%s\"} ] }\n", spp, integrator, obj);
  const char *scene_path = scratch_file("ref.json", json);
  valo_error err;
  valo_scene *sc;
  CHECK(valo_scene_load(scene_path, &sc, &err) == VALO_OK, "%s", err.message);
  valo_render *r;
  CHECK(valo_render_create(sc, NULL, &r, &err) == VALO_OK, "%s", err.message);
  CHECK(valo_render_run(r, NULL, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(!check_losses(r), "samples lost");
  float *img = malloc(256 * 256 * 3 * sizeof(float));
  valo_render_pixels(r, img);
  image ref;
  CHECK(image_read(refp, &ref, &err) == VALO_OK, "%s", err.message);
  CHECK(ref.w == 256 && ref.h == 256, "reference is %dx%d", ref.w, ref.h);
  for (int i = 0; i < 256 * 256 * 3; i++) CHECK(isfinite(img[i]) && img[i] >= 0, "pixel value %g at %d", img[i], i);
  cmp_result cr;
  compare_images(img, ref.rgb, 256, 256, block, &cr);
  valo_stats st;
  valo_render_stats(r, &st);
  fprintf(stderr, "%s, %s at %d spp (%.1f s): mean error R %.3f%% G %.3f%% B %.3f%%; worst of %d lit %dx%d blocks %.2f%% at (%d,%d)\n",
          obj_rel, integrator, spp, st.render_seconds, 100 * cr.mean_err[0], 100 * cr.mean_err[1], 100 * cr.mean_err[2], cr.lit_blocks, block,
          block, 100 * cr.worst_block, cr.worst_bx, cr.worst_by);
  if (getenv("VALO_TEST_KEEP")) {
    valo_render_write(r, "reference-test-valo.exr", NULL, &err);
  }
  free(img);
  image_free(&ref);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  for (int c = 0; c < 3; c++) CHECK(cr.mean_err[c] < 0.01, "channel %d mean differs by %.3f%%", c, 100 * cr.mean_err[c]);
  int nblocks = 3 * (256 / block) * (256 / block); /* block-channels, as compare_images counts them */
  CHECK(4 * cr.lit_blocks > 3 * nblocks, "only %d of %d block-channels lit", cr.lit_blocks, nblocks);
  CHECK(cr.worst_block < 0.03, "block (%d,%d) differs by %.2f%%", cr.worst_bx, cr.worst_by, 100 * cr.worst_block);
  return 0;
}

static int run_reference(const char *obj_rel, const char *ref_rel, int spp, int block) {
  return run_reference_with(obj_rel, ref_rel, spp, block, "path");
}

static int cornell_original(void) { return run_reference("scenes/cornell/CornellBox-Original.obj", "references/cornell-original.exr", 512, 16); }
/* The mirror sphere's caustic is the noisiest part: 32x32 blocks need 2048 spp to stay
 * within 3 % (1.26 %; at 1024 spp one reached 3.10 %), the full form; by default 1024 spp
 * and 64x64 blocks, whose noise is that of 32x32 ones at 4096. */
static int cornell_mirror(void) {
  return run_reference("scenes/cornell/CornellBox-Mirror.obj", "references/cornell-mirror.exr", test_full() ? 2048 : 1024, test_full() ? 32 : 64);
}

/* veach-mis against the Tungsten render beside it: with its own camera, the
 * four rough plates must show the lights' highlights where Tungsten does. For each plate,
 * the luminance profile across the plate (clamped to [0,1], as the PNG is) is compared
 * with the reference's by correlation. Tungsten uses Beckmann, valo GGX, whose longer
 * tails brighten the plates between highlights, so the profiles' shapes are compared,
 * not their levels (the roughest plate, one glow in both, by level). */
static double plate_profile(const float *rgb, int w, int h, int stride_rgba, double y0, double y1, double *prof, int nb) {
  for (int b = 0; b < nb; b++) prof[b] = 0;
  int cnt[64] = {0};
  for (int y = (int)(y0 * h); y < (int)(y1 * h); y++)
    for (int x = (int)(0.30 * w); x < (int)(0.72 * w); x++) {
      const float *p = &rgb[(size_t)(stride_rgba ? 4 : 3) * ((size_t)y * w + x)];
      double l = 0.2126 * fmin(p[0], 1) + 0.7152 * fmin(p[1], 1) + 0.0722 * fmin(p[2], 1);
      int b = (int)((x - 0.30 * w) / (0.42 * w) * nb);
      if (b >= nb) b = nb - 1;
      prof[b] += l;
      cnt[b]++;
    }
  for (int b = 0; b < nb; b++) prof[b] /= cnt[b] ? cnt[b] : 1;
  return 0;
}
static double correlation(const double *a, const double *b, int n) {
  double ma = 0, mb = 0, sab = 0, saa = 0, sbb = 0;
  for (int i = 0; i < n; i++) { ma += a[i]; mb += b[i]; }
  ma /= n; mb /= n;
  for (int i = 0; i < n; i++) { sab += (a[i] - ma) * (b[i] - mb); saa += (a[i] - ma) * (a[i] - ma); sbb += (b[i] - mb) * (b[i] - mb); }
  return saa > 0 && sbb > 0 ? sab / sqrt(saa * sbb) : 0;
}

#include "image/texture.h"
static int veach_mis_tungsten(void) {
  const char *obj = shared_file("scenes/veach-mis/veach-mis.obj"), *png = shared_file("scenes/veach-mis/mitsuba-source/TungstenRender.png");
  if (!obj || !png) return TEST_SKIP;
  int w = 320, h = 180;
  char json[4096];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [28.2792,3.5,0], \"look_at\": [27.2792,3.5,0], \"up\": [0,1,0], \"fov\": 20.1143},\n"
           "  \"film\": {\"width\": %d, \"height\": %d}, \"render\": {\"spp\": %d, \"seed\": 3},\n"
           "  \"shapes\": [ {\"file\": \"%s\"} ] }\n", w, h, test_full() ? 512 : 96, obj);
  valo_options o;
  valo_options_init(&o);
  int rw, rh;
  float *img = render_json_text(json, &o, &rw, &rh);
  CHECK(img, "render failed");
  texture ref;
  valo_error err;
  CHECK(texture_load_file(&ref, png, 1, &err) == VALO_OK, "%s", err.message);
  static const double band[4][2] = {{0.38, 0.50}, {0.54, 0.64}, {0.68, 0.76}, {0.81, 0.90}};
  int bad = 0;
  for (int p = 0; p < 4; p++) {
    double a[24], b[24];
    plate_profile(img, w, h, 0, band[p][0], band[p][1], a, 24);
    plate_profile(ref.px, ref.w, ref.h, 1, band[p][0], band[p][1], b, 24);
    double c = correlation(a, b, 24);
    fprintf(stderr, "plate %d: profile correlation with Tungsten %.3f\n  valo:    ", p + 1, c);
    for (int i = 0; i < 24; i++) fprintf(stderr, " %.2f", a[i]);
    fprintf(stderr, "\n  Tungsten:");
    for (int i = 0; i < 24; i++) fprintf(stderr, " %.2f", b[i]);
    fprintf(stderr, "\n");
    /* The roughest plate (alpha 0.25) blurs the lights into one glow in both: compare its
     * level instead (within 0.05 everywhere). */
    if (p < 3 && c < 0.9) bad++;
    if (p == 3)
      for (int i = 0; i < 24; i++) if (fabs(a[i] - b[i]) > 0.05) { bad++; break; }
  }
  texture_free(&ref);
  free(img);
  CHECK(bad == 0, "%d plates whose highlights do not line up with Tungsten's", bad);
  return 0;
}

/* Adaptive sampling against uniform at the same sample count, relMSE against the Cycles
 * references: no worse than uniform (+5 %) on CornellBox-Mirror (mirror caustics) and
 * CornellBox-Original (even noise). Measured 0.87x and 0.95x. The rule that gave 0.17x on
 * the Mirror box decided on each pixel's own samples and darkened rare bright paths
 * (test_analytic adaptive_unbiased shows the digest rule doing so); an unbiased rule gains
 * only where the noise is far from even. (Equal time is what docs/performance.md
 * reports; equal samples is what a test can check without timing.) */
static double relmse_of(const char *obj_rel, const char *ref_rel, int spp, int adaptive) {
  const char *obj = shared_file(obj_rel), *refp = shared_file(ref_rel);
  if (!obj || !refp) return -1;
  char json[4096];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [0,1,3.4], \"look_at\": [0,1,0], \"up\": [0,1,0], \"fov\": 40},\n"
           "  \"film\": {\"width\": 256, \"height\": 256}, \"render\": {\"spp\": %d, \"seed\": 11},\n"
           "  \"shapes\": [ {\"file\": \"%s\"} ] }\n", spp, obj);
  valo_options o;
  valo_options_init(&o);
  o.adaptive = adaptive ? VALO_ADAPTIVE_ERROR : 0;
  int w, h;
  float *img = render_json_text(json, &o, &w, &h);
  image ref;
  valo_error err;
  if (!img || image_read(refp, &ref, &err)) { free(img); return -2; }
  double e = 0;
  for (int i = 0; i < w * h * 3; i++) e += (img[i] - ref.rgb[i]) * (img[i] - ref.rgb[i]) / (ref.rgb[i] * ref.rgb[i] + 0.01);
  free(img);
  image_free(&ref);
  return e / (w * h * 3);
}
static int adaptive_relmse(void) {
  double mu = relmse_of("scenes/cornell/CornellBox-Mirror.obj", "references/cornell-mirror.exr", 64, 0);
  if (mu == -1) return TEST_SKIP;
  double ma = relmse_of("scenes/cornell/CornellBox-Mirror.obj", "references/cornell-mirror.exr", 64, 1);
  double ou = relmse_of("scenes/cornell/CornellBox-Original.obj", "references/cornell-original.exr", 64, 0);
  double oa = relmse_of("scenes/cornell/CornellBox-Original.obj", "references/cornell-original.exr", 64, 1);
  fprintf(stderr, "relMSE at 64 spp: Mirror uniform %.6f adaptive %.6f (%.2fx); Original uniform %.6f adaptive %.6f (%.2fx)\n", mu, ma,
          ma / mu, ou, oa, oa / ou);
  CHECK(mu > 0 && ma > 0 && ou > 0 && oa > 0, "renders failed");
  CHECK(ma < 1.05 * mu, "adaptive on CornellBox-Mirror: %.6f, more than 5 %% above uniform %.6f", ma, mu);
  CHECK(oa < 1.05 * ou, "adaptive on CornellBox-Original: %.6f, more than 5 %% above uniform %.6f", oa, ou);
  return 0;
}

/* guided (path guiding) on the mirror box, where the floor's light through the mirror is
 * what it learns: its mean and 64x64 blocks (32x32 in the full form) against Cycles. */
static int cornell_mirror_guided(void) {
  return run_reference_with("scenes/cornell/CornellBox-Mirror.obj", "references/cornell-mirror.exr", test_full() ? 1024 : 128,
                            test_full() ? 32 : 64, "guided");
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"cornell_original", cornell_original}, {"cornell_mirror", cornell_mirror},
                                    {"cornell_mirror_guided", cornell_mirror_guided},
                                    {"veach_mis_tungsten", veach_mis_tungsten}, {"adaptive_relmse", adaptive_relmse}, {NULL, NULL}};
  return test_main(argc, argv, cases);
}
