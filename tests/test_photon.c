/* test_photon.c — the photon integrator (src/integrator/photon.c, digest 003):
 *  - on CornellBox-Original and CornellBox-Mirror it matches the independent Cycles
 *    references (mean per channel within 2 %, every lit block-channel within a bound);
 *  - its density estimate converges: with final gathering off, the lit 16x16 blocks'
 *    mean error against the reference falls as the photon count grows, and the mean is
 *    within 2 % at 400 000;
 *  - scenes/caustic.json (a glass sphere's caustic) against Mitsuba 3
 *    (tests/data/caustic-mitsuba.exr): mean within 3 %, every lit 32x32 block-channel
 *    within 10 %; tests/data/caustic-far (a small lamp's sharp caustic, our held-out
 *    kind) the same (32 passes, label reference), and from a camera that sees the lamp
 *    through the ball (no fireflies at the lamp's image);
 *  - progressive radius reduction makes it consistent: with a deliberately wide first
 *    radius, the caustic's error falls with the passes at the default alpha and does not
 *    with alpha = 1 (a fixed radius);
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

/* Per-channel comparison over 16x16 blocks whose reference channel mean is at least 5 %
 * of the image mean: the mean and the worst of their relative errors, and how many. */
typedef struct cmp { double mean_err[3], block_mean, block_worst; int blocks; } cmp;
static void compare(const float *img, const float *ref, int w, int h, cmp *c) {
  double si[3] = {0}, sr[3] = {0};
  for (int i = 0; i < w * h; i++)
    for (int k = 0; k < 3; k++) { si[k] += img[3 * i + k]; sr[k] += ref[3 * i + k]; }
  for (int k = 0; k < 3; k++) c->mean_err[k] = fabs(si[k] / sr[k] - 1);
  double mean = (sr[0] + sr[1] + sr[2]) / (3.0 * w * h), sum = 0;
  int n = 0;
  c->block_worst = 0;
  for (int by = 0; by + 16 <= h; by += 16)
    for (int bx = 0; bx + 16 <= w; bx += 16)
      for (int k = 0; k < 3; k++) {
        double a = 0, b = 0;
        for (int y = by; y < by + 16; y++)
          for (int x = bx; x < bx + 16; x++) { a += img[3 * (y * w + x) + k]; b += ref[3 * (y * w + x) + k]; }
        if (b / 256 < 0.05 * mean) continue;
        double e = fabs(a / b - 1);
        sum += e;
        n++;
        if (e > c->block_worst) c->block_worst = e;
      }
  c->block_mean = n ? sum / n : 1;
  c->blocks = n;
}

static int photon_cornell_reference(void) {
  const char *refp = shared_file("references/cornell-original.exr");
  if (!refp) return TEST_SKIP;
  image ref;
  valo_error err;
  CHECK(image_read(refp, &ref, &err) == VALO_OK, "%s", err.message);
  int w, h;
  int spp = test_full() ? 16 : 4;
  float *img = render_cornell("", spp, &w, &h);
  CHECK(img && w == ref.w && h == ref.h, "render");
  for (int i = 0; i < w * h * 3; i++) CHECK(isfinite(img[i]) && img[i] >= 0, "pixel %d = %g", i, img[i]);
  cmp c;
  compare(img, ref.rgb, w, h, &c);
  fprintf(stderr, "photon (defaults, %d passes): mean error R %.2f%% G %.2f%% B %.2f%%; %d lit 16x16 block-channels: mean %.2f%%, worst %.2f%%\n",
          spp, 100 * c.mean_err[0], 100 * c.mean_err[1], 100 * c.mean_err[2], c.blocks, 100 * c.block_mean, 100 * c.block_worst);
  for (int k = 0; k < 3; k++) CHECK(c.mean_err[k] < 0.02, "channel %d off by %.2f%%", k, 100 * c.mean_err[k]);
  CHECK(c.blocks > 400, "only %d lit block-channels", c.blocks);
  CHECK(c.block_mean < 0.04, "blocks off by %.2f%% on average", 100 * c.block_mean);
  CHECK(c.block_worst < 0.12, "worst block off by %.2f%%", 100 * c.block_worst);
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
    fprintf(stderr, "density estimate alone, %6d photons: mean error R %.2f%% G %.2f%% B %.2f%%; %d lit block-channels: mean %.2f%% worst %.2f%%\n",
            counts[i], 100 * c[i].mean_err[0], 100 * c[i].mean_err[1], 100 * c[i].mean_err[2], c[i].blocks, 100 * c[i].block_mean,
            100 * c[i].block_worst);
    CHECK(c[i].blocks > 400, "only %d lit block-channels", c[i].blocks);
    free(img);
  }
  CHECK(c[1].block_mean < 0.85 * c[0].block_mean && c[2].block_mean < 0.85 * c[1].block_mean, "block error does not fall: %g %g %g",
        c[0].block_mean, c[1].block_mean, c[2].block_mean);
  for (int k = 0; k < 3; k++) CHECK(c[2].mean_err[k] < 0.02, "channel %d off by %.2f%% at 400 000", k, 100 * c[2].mean_err[k]);
  image_free(&ref);
  return 0;
}

/* A photon render of scene `path` (options o) against the EXR ref: mean per channel within
 * mean_tol, every lit 32x32 block-channel within block_tol, and (when rel_tol > 0) the
 * image's relMSE below rel_tol. */
static int against(const char *path, const char *refp, valo_options *o, double mean_tol, double block_tol, double rel_tol, cmp_result *out) {
  image ref;
  valo_error err;
  CHECK(image_read(refp, &ref, &err) == VALO_OK, "%s", err.message);
  snprintf(o->integrator, sizeof o->integrator, "photon");
  valo_scene *sc;
  valo_render *r = render_file(path, o, &sc);
  CHECK(r, "render");
  valo_stats st;
  valo_render_stats(r, &st);
  CHECK(st.width == ref.w && st.height == ref.h, "render %dx%d, reference %dx%d", st.width, st.height, ref.w, ref.h);
  float *img = malloc((size_t)ref.w * ref.h * 3 * sizeof *img);
  valo_render_pixels(r, img);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  cmp_result cr;
  compare_images(img, ref.rgb, ref.w, ref.h, 32, &cr);
  double rel = 0;
  for (int i = 0; i < 3 * ref.w * ref.h; i++) rel += (img[i] - ref.rgb[i]) * (img[i] - ref.rgb[i]) / (ref.rgb[i] * ref.rgb[i] + 1e-2);
  rel /= 3.0 * ref.w * ref.h;
  fprintf(stderr,
          "%s, %d passes (%.1f s): relMSE %.5f; mean error R %.2f%% G %.2f%% B %.2f%%; worst of %d lit 32x32 block-channels %.2f%% at (%d,%d,%d)\n",
          path, st.spp_done, st.render_seconds, rel, 100 * cr.mean_err[0], 100 * cr.mean_err[1], 100 * cr.mean_err[2], cr.lit_blocks,
          100 * cr.worst_block, cr.worst_bx, cr.worst_by, cr.worst_c);
  free(img);
  image_free(&ref);
  if (out) *out = cr;
  for (int k = 0; k < 3; k++) CHECK(cr.mean_err[k] < mean_tol, "channel %d mean off by %.2f%%", k, 100 * cr.mean_err[k]);
  CHECK(cr.lit_blocks >= 24, "only %d lit block-channels", cr.lit_blocks);
  CHECK(cr.worst_block < block_tol, "block (%d,%d) channel %d off by %.2f%%", cr.worst_bx, cr.worst_by, cr.worst_c, 100 * cr.worst_block);
  CHECK(rel_tol <= 0 || rel < rel_tol, "relMSE %.5f (allowed %.5f)", rel, rel_tol);
  return 0;
}

static int photon_caustic(void) {
  valo_options o;
  valo_options_init(&o);
  o.spp = test_full() ? 96 : 16;
  return against(VALO_SOURCE_DIR "/scenes/caustic.json", VALO_SOURCE_DIR "/tests/data/caustic-mitsuba.exr", &o, 0.03, 0.10, 0, NULL);
}

static int photon_caustic_far(void) {
  valo_options o;
  valo_options_init(&o);
  o.spp = 32;
  return against(VALO_SOURCE_DIR "/tests/data/caustic-far/caustic-far.json", VALO_SOURCE_DIR "/tests/data/caustic-far/caustic-far-mitsuba.exr", &o,
                 0.03, 0.10, 0, NULL);
}

/* The same scene from a camera that sees the lamp through the ball (a view the method was
 * not tuned on): the lamp's image in the glass is emission reached through a delta chain,
 * and neither the final gather nor the caustic map may add fireflies there (issue 58's
 * 35 % block). Against Mitsuba 3's path tracer at 131 072 spp; the relMSE bound is a
 * quarter of what path's own fireflies leave there at 1 024 spp (0.060). */
static int photon_lamp_through_glass(void) {
  valo_options o;
  valo_options_init(&o);
  o.spp = 32;
  return against(VALO_SOURCE_DIR "/tests/data/caustic-far/caustic-lampview.json",
                 VALO_SOURCE_DIR "/tests/data/caustic-far/caustic-lampview-mitsuba.exr", &o, 0.03, 0.10, 0.02, NULL);
}

static int photon_cornell_mirror(void) {
  const char *obj = shared_file("scenes/cornell/CornellBox-Mirror.obj"), *refp = shared_file("references/cornell-mirror.exr");
  if (!obj || !refp) return TEST_SKIP;
  char json[2048];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [0,1,3.4], \"look_at\": [0,1,0], \"up\": [0,1,0], \"fov\": 40},\n"
           "  \"film\": {\"width\": 256, \"height\": 256},\n"
           "  \"render\": {\"seed\": 7},\n"
           "  \"shapes\": [ {\"file\": \"%s\"} ] }\n", obj);
  valo_options o;
  valo_options_init(&o);
  o.spp = test_full() ? 16 : 4;
  return against(scratch_file("mirror.json", json), refp, &o, 0.02, 0.10, 0, NULL);
}

/* The caustic's error (lit 16x16 block-channels, mean) at 2 and at 24 passes with a first
 * caustic radius eight times the automatic one's bound: it must fall to under 60 % with
 * the default alpha, and it must not (a fixed radius's blur stays) with alpha = 1. */
static double caustic_block_error(const char *params, int spp) {
  image ref;
  valo_error err;
  if (image_read(VALO_SOURCE_DIR "/tests/data/caustic-mitsuba.exr", &ref, &err) != VALO_OK) return -1;
  valo_options o;
  valo_options_init(&o);
  o.spp = spp;
  snprintf(o.integrator, sizeof o.integrator, "photon");
  snprintf(o.params, sizeof o.params, "%s", params);
  valo_scene *sc;
  valo_render *r = render_file(VALO_SOURCE_DIR "/scenes/caustic.json", &o, &sc);
  if (!r) return -1;
  float *img = malloc((size_t)ref.w * ref.h * 3 * sizeof *img);
  valo_render_pixels(r, img);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  /* mean relative error of the lit 16x16 block-channels */
  cmp c;
  compare(img, ref.rgb, ref.w, ref.h, &c);
  free(img);
  image_free(&ref);
  return c.block_mean;
}

static int photon_consistent(void) {
  const char *wide = "caustic_radius=0.5 gather=1 global=5000";
  char p[256];
  double e[2][2];
  const char *alpha[2] = {"0.7", "1"};
  for (int a = 0; a < 2; a++)
    for (int i = 0; i < 2; i++) {
      snprintf(p, sizeof p, "%s alpha=%s", wide, alpha[a]);
      e[a][i] = caustic_block_error(p, i ? 24 : 2);
      CHECK(e[a][i] >= 0, "render");
    }
  fprintf(stderr, "caustic block error, wide first radius: alpha 0.7: %.2f%% at 2 passes, %.2f%% at 24; alpha 1: %.2f%%, %.2f%%\n",
          100 * e[0][0], 100 * e[0][1], 100 * e[1][0], 100 * e[1][1]);
  CHECK(e[0][1] < 0.6 * e[0][0], "the error does not fall with the passes (%.2f%% -> %.2f%%)", 100 * e[0][0], 100 * e[0][1]);
  CHECK(e[1][1] > 0.8 * e[1][0], "a fixed radius's error fell (%.2f%% -> %.2f%%): the test cannot tell", 100 * e[1][0], 100 * e[1][1]);
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

/* A blend of diffuse 0.8 and a mirror at weight 0.5 against the same surface as one
 * material (mirror of reflectance 0.5 over diffuse 0.4): a spot lights the floor only, and
 * the camera sees the wall, lit only from the floor (its diffuse part by the global map,
 * its mirror part by the caustic map). Light paths store photons on a blend whichever
 * material it picked (stored only on the diffuse pick, the wall was half as bright); vpl,
 * on the same light paths, keeps its lights where the pick can scatter to the camera. */
static int photon_blend(void) {
  CHECK(scratch_file("pb-floor.obj", "v -3 0 -3\nv -3 0 3\nv 3 0 3\nv 3 0 -3\nf 1 2 3 4\n"), "write");
  CHECK(scratch_file("pb-wall.obj", "v -3 0 -2\nv 3 0 -2\nv 3 3 -2\nv -3 3 -2\nf 1 2 3 4\n"), "write");
  const char *mats[2] = {"\"d\": {\"type\": \"diffuse\", \"reflectance\": 0.8}, \"m\": {\"type\": \"mirror\"},"
                         " \"f\": {\"type\": \"blend\", \"weight\": 0.5, \"materials\": [\"d\", \"m\"]}",
                         "\"f\": {\"type\": \"mirror\", \"reflectance\": 0.5, \"diffuse\": 0.4}"};
  const char *integ[2] = {"photon", "vpl"};
  for (int q = 0; q < 2; q++) {
    double mean[2];
    for (int k = 0; k < 2; k++) {
      char json[1400];
      snprintf(json, sizeof json,
               "{ \"camera\": {\"position\": [0, 1.2, 3], \"look_at\": [0, 1.2, -2], \"fov\": 20},\n"
               "  \"film\": {\"width\": 24, \"height\": 24}, \"render\": {\"spp\": 8, \"integrator\": \"%s\"},\n"
               "  \"materials\": {%s, \"w\": {\"type\": \"diffuse\", \"reflectance\": 0.7}},\n"
               "  \"shapes\": [{\"file\": \"pb-floor.obj\", \"material\": \"f\"}, {\"file\": \"pb-wall.obj\", \"material\": \"w\"}],\n"
               "  \"lights\": [{\"type\": \"spot\", \"position\": [0, 1.5, 0], \"look_at\": [0, 0, 0], \"intensity\": 20, \"cone_angle\": 30}] }\n",
               integ[q], mats[k]);
      mean[k] = render_json_mean_green(json);
      CHECK(mean[k] >= 0, "render failed");
    }
    fprintf(stderr, "%s: wall lit from the floor: blend %.5f, one material %.5f\n", integ[q], mean[0], mean[1]);
    CHECK(mean[1] > 0 && fabs(mean[0] / mean[1] - 1) < 0.05, "%s: the wall over a blend is %.5f, over the same surface as one material %.5f", integ[q],
          mean[0], mean[1]);
  }
  return 0;
}

static int cmp_float_asc(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

/* Caustic photons aimed at the specular objects (param aim, Jensen's projection maps)
 * against photons shot in every direction: the caustic through a glass ball lit by the
 * scene's one-sided area lamp, and by a point light, is the same (the mean over the
 * caustic's pixels within 4 %, the whole image within 1.5 %) — paths that miss the
 * ball's sphere could not have stored a caustic photon. */
static int photon_aim(void) {
  const char *lights[2] = {"", "\"lights\": [{\"type\": \"point\", \"position\": [2.5, 3.5, 0], \"intensity\": 12}],"};
  const char *lamp[2] = {"{ \"file\": \"%s/scenes/caustic-light.obj\", \"material\": \"lamp\" },", ""};
  for (int q = 0; q < 2; q++) {
    float *img[2] = {NULL, NULL};
    int w = 64, h = 64;
    for (int a = 0; a < 2; a++) {
      char shape[600], json[2400];
      snprintf(shape, sizeof shape, lamp[q], VALO_SOURCE_DIR);
      snprintf(json, sizeof json,
               "{ \"camera\": { \"position\": [-0.9, 3.2, 2.2], \"look_at\": [-0.7, 0, 0], \"up\": [0, 1, 0], \"fov\": 40 },\n"
               "  \"film\": { \"width\": %d, \"height\": %d }, \"render\": { \"integrator\": \"photon\", \"spp\": 8, \"seed\": 3 },\n"
               "  \"materials\": { \"glass\": { \"type\": \"dielectric\", \"ior\": 1.5 }, \"floor\": { \"type\": \"diffuse\", \"reflectance\": 0.7 },\n"
               "    \"lamp\": { \"type\": \"diffuse\", \"reflectance\": 0, \"emission\": 60 } }, %s\n"
               "  \"shapes\": [ { \"file\": \"%s/scenes/caustic-floor.obj\", \"material\": \"floor\" }, %s\n"
               "    { \"type\": \"sphere\", \"center\": [0, 0.75, 0], \"radius\": 0.5, \"material\": \"glass\" } ] }\n",
               w, h, lights[q], VALO_SOURCE_DIR, shape);
      const char *path = scratch_file(a ? "aim1.json" : "aim0.json", json);
      valo_options o;
      valo_options_init(&o);
      snprintf(o.params, sizeof o.params, "photon.aim=%d photon.gather=1 photon.caustic=50000 photon.global=20000", a);
      valo_scene *sc;
      valo_render *r = render_file(path, &o, &sc);
      CHECK(r, "render");
      img[a] = malloc((size_t)w * h * 3 * sizeof(float));
      valo_render_pixels(r, img[a]);
      valo_render_destroy(r);
      valo_scene_destroy(sc);
    }
    /* the caustic: pixels of the floor (under the ball's shadow side) at least 3x the image's median */
    float *g = malloc((size_t)w * h * sizeof *g);
    for (int i = 0; i < w * h; i++) g[i] = img[0][3 * i + 1];
    qsort(g, (size_t)w * h, sizeof *g, cmp_float_asc);
    float med = g[w * h / 2];
    free(g);
    double c0 = 0, c1 = 0, m0 = 0, m1 = 0;
    int nc = 0;
    for (int i = 0; i < w * h; i++) {
      m0 += img[0][3 * i + 1];
      m1 += img[1][3 * i + 1];
      if (img[0][3 * i + 1] > 3 * med && img[0][3 * i + 1] < 50 * med) { c0 += img[0][3 * i + 1]; c1 += img[1][3 * i + 1]; nc++; }
    }
    fprintf(stderr, "%s: the caustic (%d pixels) %.4f aimed, %.4f not; the image %.5f, %.5f\n", q ? "point light" : "area lamp", nc, c1 / nc, c0 / nc,
            m1 / (w * h), m0 / (w * h));
    CHECK(nc >= 20, "only %d caustic pixels: the test sees no caustic", nc);
    CHECK(fabs(c1 / c0 - 1) < 0.04, "the aimed caustic is %.3f of the other", c1 / c0);
    CHECK(fabs(m1 / m0 - 1) < 0.015, "the aimed image's mean is %.4f of the other's", m1 / m0);
    free(img[0]);
    free(img[1]);
  }
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"photon_cornell_reference", photon_cornell_reference},
                                    {"photon_converges", photon_converges},
                                    {"photon_caustic", photon_caustic},
                                    {"photon_caustic_far", photon_caustic_far},
                                    {"photon_lamp_through_glass", photon_lamp_through_glass},
                                    {"photon_cornell_mirror", photon_cornell_mirror},
                                    {"photon_consistent", photon_consistent},
                                    {"photon_threads", photon_threads}, {"photon_blend", photon_blend}, {"photon_aim", photon_aim},
                                    {NULL, NULL}};
  return test_main(argc, argv, cases);
}
