/* test_integrators.c — where the classic integrators agree with `path` and where they
 * are documented to differ (docs/integrators.md):
 *  - whitted == path on a scene whose only light paths are point light -> one diffuse
 *    surface -> an ideal mirror -> camera;
 *  - whitted in closed form: a point-lit diffuse floor seen in a vertical mirror, smooth
 *    gold and smooth glass gives reflectance x rho/pi x I cos / d^2, with the Fresnel
 *    terms computed here in complex arithmetic;
 *  - whitted is darker than path in a closed box (no interreflection);
 *  - distribution == path at the same fixed max_depth (both unbiased for the truncated
 *    transport), and darker than unlimited path;
 *  - two lamps that overlap in their plane: the first in the scene's order is the one seen
 *    where they overlap (every integrator that samples lights or shoots particles). */
#include "harness.h"
#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef VALO_SOURCE_DIR
#define VALO_SOURCE_DIR "."
#endif

static double mean_of(const char *json, const char *integrator, int spp, int max_depth) {
  valo_options o;
  valo_options_init(&o);
  snprintf(o.integrator, sizeof o.integrator, "%s", integrator);
  o.spp = spp;
  if (max_depth != VALO_DEPTH_UNSET) o.max_depth = max_depth;
  int w, h;
  float *px = render_json_text(json, &o, &w, &h);
  if (!px) return -1;
  double s = 0;
  for (int i = 0; i < w * h * 3; i++) {
    if (!isfinite(px[i]) || px[i] < 0) { free(px); return -1; }
    s += px[i];
  }
  free(px);
  return s / (w * h * 3);
}

static int whitted_equals_path_mirror(void) {
  /* Camera looks straight down at a mirror tilted 45 degrees; the mirror shows a
   * diffuse wall lit by a point light; everything else is black. Light leaving the wall
   * towards the mirror goes up into the void, so no other paths exist. */
  CHECK(scratch_file("mirror.obj", "v -1 -0.7071 0.7071\nv 1 -0.7071 0.7071\nv 1 0.7071 -0.7071\nv -1 0.7071 -0.7071\nf 1 2 3 4\n"), "write");
  CHECK(scratch_file("wall.obj", "v -3 -1 5\nv -3 0.5 5\nv 3 0.5 5\nv 3 -1 5\nf 1 2 3 4\n"), "write");
  const char *json =
      "{ \"camera\": {\"position\": [0,3,0], \"look_at\": [0,0,0], \"up\": [0,0,-1], \"fov\": 25},\n"
      "  \"film\": {\"width\": 24, \"height\": 24}, \"render\": {\"seed\": 3},\n"
      "  \"materials\": {\"mirror\": {\"type\": \"mirror\", \"reflectance\": 0.9},\n"
      "                \"wall\": {\"type\": \"diffuse\", \"reflectance\": [0.8,0.5,0.3]}},\n"
      "  \"shapes\": [{\"file\": \"mirror.obj\", \"material\": \"mirror\"}, {\"file\": \"wall.obj\", \"material\": \"wall\"}],\n"
      "  \"lights\": [{\"type\": \"point\", \"position\": [0,0.2,3], \"intensity\": 10}] }\n";
  double w = mean_of(json, "whitted", 64, VALO_DEPTH_UNSET), p = mean_of(json, "path", 512, VALO_DEPTH_UNSET);
  double d = mean_of(json, "distribution", 32, VALO_DEPTH_UNSET);
  fprintf(stderr, "mirror scene mean: whitted %.5f, path %.5f, distribution %.5f\n", w, p, d);
  CHECK(w > 0.01, "the wall is not visible in the mirror (mean %g)", w);
  CHECK(fabs(w - p) < 0.01 * p, "whitted %g vs path %g", w, p);
  CHECK(fabs(d - p) < 0.01 * p, "distribution %g vs path %g", d, p);
  return 0;
}

/* Fresnel reflectance of an interface to complex index n (from index 1), unpolarised. */
static double fresnel_complex(double cos_i, double complex n) {
  double complex sin2 = 1 - cos_i * cos_i, cos_t = csqrt(1 - sin2 / (n * n));
  double complex rs = (cos_i - n * cos_t) / (cos_i + n * cos_t), rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
  return 0.5 * (cabs(rs) * cabs(rs) + cabs(rp) * cabs(rp));
}

static int whitted_closed_form(void) {
  /* The camera at (2, 0, 3) looks at Q = (0, 0, 1) on a vertical reflector (the plane
   * x = 0, facing +x) at 45 degrees; the reflected ray meets the floor (z = 0, x >= 0,
   * diffuse 0.5) at P = (1, 0, 0), lit by a point light of intensity 10 at (2, 1, 2).
   * What the reflector transmits leaves towards x < 0, where there is nothing. */
  CHECK(scratch_file("wall.obj", "v 0 -5 0.01\nv 0 5 0.01\nv 0 5 5\nv 0 -5 5\nf 1 2 3 4\n") &&
            scratch_file("floor.obj", "v 0 -50 0\nv 50 -50 0\nv 50 50 0\nv 0 50 0\nf 1 2 3 4\n"),
        "write");
  const double lp[3] = {2, 1, 2}, P[3] = {1, 0, 0}, intensity = 10, rho = 0.5;
  double dl[3] = {lp[0] - P[0], lp[1] - P[1], lp[2] - P[2]}, d2 = dl[0] * dl[0] + dl[1] * dl[1] + dl[2] * dl[2];
  double Lfloor = rho / M_PI * intensity * (dl[2] / sqrt(d2)) / d2, c45 = sqrt(0.5);
  static const struct { const char *mat; double complex n[3]; double ks; } cases[] = {
      {"{\"type\": \"mirror\", \"reflectance\": 0.9}", {0, 0, 0}, 0.9},
      {"{\"type\": \"conductor\", \"eta\": [0.143, 0.374, 1.442], \"k\": [3.983, 2.385, 1.603]}",
       {0.143 + 3.983 * _Complex_I, 0.374 + 2.385 * _Complex_I, 1.442 + 1.603 * _Complex_I}, 0},
      {"{\"type\": \"dielectric\", \"ior\": 1.5}", {1.5, 1.5, 1.5}, 0},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    char json[2048];
    snprintf(json, sizeof json,
             "{ \"camera\": {\"position\": [2,0,3], \"look_at\": [0,0,1], \"up\": [0,0,1], \"fov\": 0.05},\n"
             "  \"film\": {\"width\": 1, \"height\": 1}, \"render\": {\"spp\": 4},\n"
             "  \"materials\": {\"r\": %s, \"floor\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
             "  \"shapes\": [{\"file\": \"wall.obj\", \"material\": \"r\"}, {\"file\": \"floor.obj\", \"material\": \"floor\"}],\n"
             "  \"lights\": [{\"type\": \"point\", \"position\": [2,1,2], \"intensity\": 10}] }\n",
             cases[k].mat);
    valo_options o;
    valo_options_init(&o);
    snprintf(o.integrator, sizeof o.integrator, "whitted");
    int w, h;
    float *px = render_json_text(json, &o, &w, &h);
    CHECK(px, "render failed");
    for (int c = 0; c < 3; c++) {
      double R = cases[k].ks > 0 ? cases[k].ks : fresnel_complex(c45, cases[k].n[c]), want = R * Lfloor;
      fprintf(stderr, "%s channel %d: %.6f, closed form %.6f (R = %.4f)\n", cases[k].mat, c, px[c], want, R);
      CHECK(fabs(px[c] - want) < 1e-3 * want, "%s channel %d: %.6f, closed form %.6f", cases[k].mat, c, px[c], want);
    }
    free(px);
  }
  return 0;
}

static char box_json[4096];
static const char *box_scene(void) {
  snprintf(box_json, sizeof box_json,
           "{ \"camera\": {\"position\": [0,1,3.6], \"look_at\": [0,0.95,0], \"fov\": 40},\n"
           "  \"film\": {\"width\": 32, \"height\": 32}, \"render\": {\"seed\": 4},\n"
           "  \"materials\": {\"plastic\": {\"type\": \"phong\", \"diffuse\": [0.3,0.3,0.5], \"specular\": 0.2, \"exponent\": 20}},\n"
           "  \"shapes\": [{\"file\": \"%s/scenes/cornell-box.obj\"},\n"
           "             {\"type\": \"sphere\", \"center\": [0.2,0.35,0], \"radius\": 0.35, \"subdivisions\": 3, \"material\": \"plastic\"}] }\n",
           VALO_SOURCE_DIR);
  return box_json;
}

static int whitted_darker_in_box(void) {
  double w = mean_of(box_scene(), "whitted", 16, VALO_DEPTH_UNSET), p = mean_of(box_scene(), "path", 64, VALO_DEPTH_UNSET);
  fprintf(stderr, "box mean: whitted %.5f, path %.5f\n", w, p);
  CHECK(w > 0 && p > 0, "render failed");
  /* Interreflection carries about a fifth of this box's light: whitted must miss it. */
  CHECK(w < 0.9 * p, "whitted (%g) should miss the interreflected light of path (%g)", w, p);
  return 0;
}

static int distribution_equals_path_at_depth(void) {
  double d = mean_of(box_scene(), "distribution", 32, 2), p = mean_of(box_scene(), "path", 1024, 2);
  double pu = mean_of(box_scene(), "path", 256, -1);
  fprintf(stderr, "box mean at max_depth 2: distribution %.5f, path %.5f; unlimited path %.5f\n", d, p, pu);
  CHECK(fabs(d - p) < 0.01 * p, "distribution %g vs path %g at max_depth 2", d, p);
  CHECK(d < 0.95 * pu, "depth-2 distribution (%g) should be darker than unlimited path (%g)", d, pu);
  return 0;
}

/* The bundled default scene looks clean at its own budget: isolated bright
 * pixels (fireflies: luminance, clamped to the PNG's range, above twice the median of the
 * 8 neighbours plus 0.1) are at most 0.05 % of the image. Rendered at half resolution, so
 * with 4x fewer samples per unit of image area the count is if anything pessimistic. */
static int cmp_float(const void *a, const void *b) { float x = *(const float *)a, y = *(const float *)b; return (x > y) - (x < y); }
static int default_scene_clean(void) {
  char path[1200];
  snprintf(path, sizeof path, "%s/scenes/default.json", VALO_SOURCE_DIR);
  valo_options o;
  valo_options_init(&o);
  o.width = o.height = 200;
  valo_scene *sc;
  valo_render *r = render_file(path, &o, &sc);
  CHECK(r, "render failed");
  int w = 200, h = 200;
  float *px = malloc((size_t)w * h * 3 * sizeof(float)), *lum = malloc((size_t)w * h * sizeof(float));
  valo_render_pixels(r, px);
  for (int i = 0; i < w * h; i++) {
    float l = 0.2126f * fminf(px[3 * i], 1) + 0.7152f * fminf(px[3 * i + 1], 1) + 0.0722f * fminf(px[3 * i + 2], 1);
    lum[i] = l;
  }
  int flies = 0;
  for (int y = 1; y < h - 1; y++)
    for (int x = 1; x < w - 1; x++) {
      float nb[8];
      int k = 0;
      for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++)
          if (dx || dy) nb[k++] = lum[(y + dy) * w + x + dx];
      qsort(nb, 8, sizeof nb[0], cmp_float);
      float med = 0.5f * (nb[3] + nb[4]);
      if (lum[y * w + x] > 2 * med + 0.1f) flies++;
    }
  valo_stats st;
  valo_render_stats(r, &st);
  fprintf(stderr, "default scene at 200x200, %d spp: %d isolated bright pixels (%.3f %%)\n", st.spp_done, flies, 100.0 * flies / (w * h));
  free(px); free(lum);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  CHECK(flies <= w * h / 2000, "%d fireflies", flies);
  return 0;
}

/* hide_emitters (Mitsuba's): a floor, a lamp facing the camera and a sky. In every
 * integrator, pixels whose camera rays all meet the lamp or the sky (the path tracer's
 * emission-only image is exactly the lamp's or the sky's radiance there) are black with
 * it, and pixels that see no emitter directly are bit for bit as without it. The AO
 * integrators draw no emitters either way: their images do not change. */
static int hide_emitters_every_integrator(void) {
  CHECK(scratch_file("hfloor.obj", "v -3 0 -3\nv -3 0 3\nv 3 0 3\nv 3 0 -3\nf 1 2 3 4\n") &&
            scratch_file("hlamp.obj", "v -0.8 0.3 -1\nv 0.8 0.3 -1\nv 0.8 1.7 -1\nv -0.8 1.7 -1\nf 1 2 3 4\n"),
        "write");
  const char *json = "{ \"camera\": {\"position\": [0, 1, 4], \"look_at\": [0, 0.6, 0], \"fov\": 50},\n"
                     "  \"film\": {\"width\": 32, \"height\": 24},\n"
                     "  \"materials\": {\"floor\": {\"type\": \"diffuse\", \"reflectance\": 0.5},"
                     " \"lamp\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": 5}},\n"
                     "  \"shapes\": [{\"file\": \"hfloor.obj\", \"material\": \"floor\"}, {\"file\": \"hlamp.obj\", \"material\": \"lamp\"}],\n"
                     "  \"environment\": {\"type\": \"constant\", \"radiance\": 0.25} }\n";
  int w, h, n = 32 * 24;
  valo_options o;
  valo_options_init(&o);
  o.spp = 8;
  o.max_depth = 0;
  float *em = render_json_text(json, &o, &w, &h);
  CHECK(em && w * h == n, "the emission-only render failed");
  int lamp = 0, sky = 0, none = 0;
  for (int i = 0; i < n; i++) {
    if (em[3 * i] == 5) lamp++;
    else if (em[3 * i] == 0.25f) sky++;
    else if (em[3 * i] == 0) none++;
  }
  CHECK(lamp > 20 && sky > 100 && none > 100, "%d lamp, %d sky, %d other pixels", lamp, sky, none);
  static const char *integ[] = {"path", "path-spectral", "whitted", "distribution", "photon", "vpl", "vsl", "restir-di", "restir-gi", "ao", "proximity-ao"};
  for (size_t k = 0; k < sizeof integ / sizeof integ[0]; k++) {
    float *img[2];
    for (int hide = 0; hide < 2; hide++) {
      valo_options_init(&o);
      o.spp = 4;
      int spectral = !strcmp(integ[k], "path-spectral");
      snprintf(o.integrator, sizeof o.integrator, "%s", spectral ? "path" : integ[k]);
      if (spectral) o.spectral = 1;
      if (!strcmp(integ[k], "photon")) snprintf(o.params, sizeof o.params, "global=2000 caustic=0 gather=4");
      o.hide_emitters = hide;
      img[hide] = render_json_text(json, &o, &w, &h);
      CHECK(img[hide], "%s: render failed", integ[k]);
    }
    int ao = strstr(integ[k], "ao") != NULL, hidden_bad = 0, kept_bad = 0, changed = 0;
    for (int i = 0; i < n; i++) {
      int seen = em[3 * i] == 5 || em[3 * i] == 0.25f;
      for (int c = 0; c < 3; c++) {
        if (img[0][3 * i + c] != img[1][3 * i + c]) changed++;
        if (seen && !ao && img[1][3 * i + c] != 0) hidden_bad++;
        if (em[3 * i] == 0 && img[0][3 * i + c] != img[1][3 * i + c]) kept_bad++;
      }
    }
    free(img[0]);
    free(img[1]);
    fprintf(stderr, "%-14s %d channel values changed; %d not black where an emitter is seen, %d changed where none is\n", integ[k], changed, hidden_bad,
            kept_bad);
    CHECK(!hidden_bad && !kept_bad, "%s", integ[k]);
    CHECK(ao ? changed == 0 : changed >= 3 * (lamp + sky), "%s: %d values changed", integ[k], changed);
  }
  free(em);
  return 0;
}

/* Two lamps that overlap in their plane: where they overlap, the first in the scene's
 * order is seen (light.h) and the other emits nothing, for camera, BSDF-sampled and
 * shadow rays and light particles alike. So a warm 2 x 2 lamp A and a cool 2 x 2 lamp B
 * sharing a 1 x 2 strip light the floor and wall as A beside the 1 x 2 rest of B does,
 * and with B first as B beside the rest of A. Light sampling that counted both lamps
 * over the strip (a shadow ray stopping short of their plane cannot see the other) read
 * the overlapped room 20-30 % brighter, and photons and VPLs leaving both brightened its
 * indirect light. Triangles that only share an edge (each lamp's two, two lamps side by
 * side) are not overlaps. */
static const char *overlap_fmt =
    "{ \"camera\": {\"position\": [0, 0.9, 3.2], \"look_at\": [0, 0.3, 0], \"fov\": 45},\n"
    "  \"film\": {\"width\": 64, \"height\": 48},\n"
    "  \"materials\": {\"white\": {\"type\": \"diffuse\", \"reflectance\": 0.7},\n"
    "                \"warm\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": [4, 2.5, 1]},\n"
    "                \"cool\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": [1, 2, 4]}},\n"
    "  \"shapes\": [ {\"type\": \"rectangle\", \"material\": \"white\", \"transform\": {\"scale\": 3, \"rotate_x\": -90}},\n"
    "    {\"type\": \"rectangle\", \"material\": \"white\", \"transform\": {\"scale\": 3, \"translate\": [0, 0, -1.5]}},\n"
    "    %s ] }\n";
static const char *lamp_fmt =
    "{\"type\": \"rectangle\", \"material\": \"%s\", \"transform\": {\"scale\": [%g, 1, 1], \"rotate_x\": 90, \"translate\": [%g, 1, 0]}}";

/* lamps: material (0 warm, 1 cool), half-width in x, centre x */
typedef struct lamp_def { int cool; double half, x; } lamp_def;
static int lamps_json(char *out, size_t cap, const lamp_def *lamps, int n) {
  char shapes[1024] = "", one[256];
  for (int i = 0; i < n; i++) {
    snprintf(one, sizeof one, lamp_fmt, lamps[i].cool ? "cool" : "warm", lamps[i].half, lamps[i].x);
    if (i) strcat(shapes, ", ");
    strcat(shapes, one);
  }
  return snprintf(out, cap, overlap_fmt, shapes) < (int)cap;
}

static int mean_rgb(const char *json, const char *integrator, const char *params, int spp, int max_depth, double m[3]) {
  valo_options o;
  valo_options_init(&o);
  snprintf(o.integrator, sizeof o.integrator, "%s", integrator);
  if (params) snprintf(o.params, sizeof o.params, "%s", params);
  o.spp = spp;
  if (max_depth != VALO_DEPTH_UNSET) o.max_depth = max_depth;
  int w, h;
  float *px = render_json_text(json, &o, &w, &h);
  if (!px) return -1;
  m[0] = m[1] = m[2] = 0;
  for (int i = 0; i < w * h * 3; i++) {
    if (!isfinite(px[i]) || px[i] < 0) { free(px); return -1; }
    m[i % 3] += px[i] / (w * h);
  }
  free(px);
  return 0;
}

static int overlapping_lamps(void) {
  /* A warm lamp over x in [-1.5, 0.5], a cool one over [-0.5, 1.5]; the strip [-0.5, 0.5]
   * is the first one's. */
  static const lamp_def warm_first[2] = {{0, 1, -0.5}, {1, 1, 0.5}}, warm_split[2] = {{0, 1, -0.5}, {1, 0.5, 1}};
  static const lamp_def cool_first[2] = {{1, 1, 0.5}, {0, 1, -0.5}}, cool_split[2] = {{1, 1, 0.5}, {0, 0.5, -1}};
  static const lamp_def side[2] = {{0, 0.75, -0.75}, {0, 0.75, 0.75}};
  char j[5][4096];
  const lamp_def *defs[5] = {warm_first, warm_split, cool_first, cool_split, side};
  for (int k = 0; k < 5; k++) CHECK(lamps_json(j[k], sizeof j[k], defs[k], 2), "json");
  const unsigned expect[5] = {4, 0, 4, 0, 0};
  for (int k = 0; k < 5; k++) {
    valo_scene *sc;
    valo_error err;
    CHECK(valo_scene_load(scratch_file("overlap.json", j[k]), &sc, &err) == VALO_OK, "%s", err.message);
    unsigned ov = valo_scene_overlapping_lights(sc);
    valo_scene_destroy(sc);
    CHECK(ov == expect[k], "scene %d: %u lights flagged as overlapping, expected %u", k, ov, expect[k]);
  }
  static const struct { const char *integ, *params; int spp, depth; } runs[] = {
      {"path", NULL, 256, 1}, {"whitted", NULL, 256, VALO_DEPTH_UNSET}, {"restir-di", NULL, 64, VALO_DEPTH_UNSET},
      {"path", NULL, 256, VALO_DEPTH_UNSET}, {"restir-gi", NULL, 64, VALO_DEPTH_UNSET},
      {"photon", "global=20000 caustic=0 gather=8", 64, VALO_DEPTH_UNSET}, {"vpl", "count=256", 64, VALO_DEPTH_UNSET}};
  for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
    double m[4][3];
    for (int k = 0; k < 4; k++)
      CHECK(!mean_rgb(j[k], runs[i].integ, runs[i].params, runs[i].spp, runs[i].depth, m[k]), "%s: render failed", runs[i].integ);
    for (int pair = 0; pair < 2; pair++) {
      const double *a = m[2 * pair], *b = m[2 * pair + 1];
      fprintf(stderr, "%-9s depth %2d, %s lamp first: overlapping %.4f %.4f %.4f, split %.4f %.4f %.4f\n", runs[i].integ,
              runs[i].depth == VALO_DEPTH_UNSET ? -1 : runs[i].depth, pair ? "cool" : "warm", a[0], a[1], a[2], b[0], b[1], b[2]);
      for (int ch = 0; ch < 3; ch++)
        CHECK(fabs(a[ch] / b[ch] - 1) < 0.015, "%s, %s lamp first, channel %d: the overlapping lamps give %.4f of the split lamps' light",
              runs[i].integ, pair ? "cool" : "warm", ch, a[ch] / b[ch]);
    }
  }
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"whitted_equals_path_mirror", whitted_equals_path_mirror},
                                    {"whitted_darker_in_box", whitted_darker_in_box}, {"whitted_closed_form", whitted_closed_form},
                                    {"distribution_equals_path_at_depth", distribution_equals_path_at_depth},
                                    {"default_scene_clean", default_scene_clean},
                                    {"hide_emitters_every_integrator", hide_emitters_every_integrator},
                                    {"overlapping_lamps", overlapping_lamps},
                                    {NULL, NULL}};
  return test_main(argc, argv, cases);
}
