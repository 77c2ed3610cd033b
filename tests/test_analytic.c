/* test_analytic.c — scenes with exact answers, as pbrt-v4 tests its integrators:
 * white furnaces (a diffuse sphere of albedo 1 and 0.5 under a constant environment of
 * radiance 1: the sphere shows 1 resp. 0.5, the background 1) and a camera inside a
 * closed sphere of albedo 0.5 lit by a point light of intensity pi at its centre, or by
 * its own emission of 0.5 (L = Le / (1 - albedo) = 1 everywhere). Flat facets are used so
 * the answers are exact for the tessellated geometry. Tolerances: region means within
 * 1 %, every pixel within 6 sigma-ish bounds stated per case; all pixels finite. */
#include "harness.h"
#include "image/texture.h"
#include "image/image_io.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *furnace_fmt =
    "{ \"camera\": {\"position\": [0,0,4], \"look_at\": [0,0,0], \"up\": [0,1,0], \"fov\": 40},\n"
    "  \"film\": {\"width\": 32, \"height\": 32}, \"render\": {\"spp\": %d, \"seed\": 5},\n"
    "  \"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": %g}},\n"
    "  \"shapes\": [{\"type\": \"sphere\", \"radius\": 1, \"subdivisions\": 4, \"smooth\": false, \"material\": \"m\"}],\n"
    "  \"environment\": {\"type\": \"constant\", \"radiance\": 1} }\n";

/* Pixels whose centre ray hits well inside the sphere's silhouette, or misses it well
 * outside: radius of the silhouette in pixels for the camera above. */
static int classify_n(int x, int y, int n) {
  float t = tanf(20.0f * 3.14159265f / 180.0f);
  float sx = (2.0f * (x + 0.5f) / n - 1) * t, sy = (1 - 2.0f * (y + 0.5f) / n) * t;
  float r = sqrtf(sx * sx + sy * sy);
  float rs = 1.0f / sqrtf(16.0f - 1.0f); /* tan of the silhouette half-angle */
  if (r < 0.85f * rs) return 1;
  if (r > 1.15f * rs) return 0;
  return -1;
}
static int classify(int x, int y) { return classify_n(x, y, 32); }

static int furnace(float albedo) {
  char json[2048];
  snprintf(json, sizeof json, furnace_fmt, 256, albedo);
  int w, h;
  float *px = render_json_text(json, NULL, &w, &h);
  CHECK(px, "render failed");
  double sum[2] = {0, 0};
  int n[2] = {0, 0};
  double worst = 0;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      for (int c = 0; c < 3; c++) CHECK(isfinite(px[3 * (y * w + x) + c]), "pixel %d,%d not finite", x, y);
      int k = classify(x, y);
      if (k < 0) continue;
      float v = (px[3 * (y * w + x)] + px[3 * (y * w + x) + 1] + px[3 * (y * w + x) + 2]) / 3;
      sum[k] += v; n[k]++;
      float expect = k ? albedo : 1.0f;
      double e = fabs(v - expect) / expect;
      if (e > worst) worst = e;
    }
  free(px);
  double m_sphere = sum[1] / n[1], m_bg = sum[0] / n[0];
  fprintf(stderr, "albedo %.2f: sphere mean %.5f (expect %.5f, %d px), background mean %.5f (%d px), worst pixel %.2f%%\n", albedo,
          m_sphere, albedo, n[1], m_bg, n[0], 100 * worst);
  CHECK(fabs(m_sphere - albedo) < 0.01 * albedo, "sphere mean %g vs %g", m_sphere, albedo);
  CHECK(fabs(m_bg - 1) < 1e-6, "background mean %g vs 1", m_bg);
  /* With MIS each sample is exact only in expectation: pixels carry noise (256 spp). */
  CHECK(worst < 0.08, "worst pixel off by %.2f%%", 100 * worst);
  return 0;
}
static int furnace_albedo_1(void) { return furnace(1.0f); }
static int furnace_albedo_half(void) { return furnace(0.5f); }

static int inside_sphere(const char *extra_material, const char *lights, double expect, int spp) {
  char json[2048];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [0,0,0.3], \"look_at\": [0.2,0.1,-1], \"up\": [0,1,0], \"fov\": 70},\n"
           "  \"film\": {\"width\": 24, \"height\": 24}, \"render\": {\"spp\": %d, \"seed\": 9},\n"
           "  \"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5 %s}},\n"
           "  \"shapes\": [{\"type\": \"sphere\", \"radius\": 1, \"subdivisions\": 5, \"smooth\": false, \"flip_normals\": true, \"material\": \"m\"}],\n"
           "  \"lights\": [%s] }\n",
           spp, extra_material, lights);
  int w, h;
  float *px = render_json_text(json, NULL, &w, &h);
  CHECK(px, "render failed");
  double sum = 0, worst = 0;
  for (int i = 0; i < w * h * 3; i++) {
    CHECK(isfinite(px[i]), "pixel value %d not finite", i);
    sum += px[i];
    double e = expect > 0 ? fabs(px[i] - expect) / expect : fabs(px[i]);
    if (e > worst) worst = e;
  }
  free(px);
  double mean = sum / (w * h * 3);
  fprintf(stderr, "mean %.5f (expect %.5f), worst pixel %.2f%%\n", mean, expect, 100 * worst);
  if (expect == 0) { CHECK(mean == 0, "mean %g, expected black", mean); return 0; }
  CHECK(fabs(mean - expect) < 0.01 * expect, "mean %g vs %g", mean, expect);
  CHECK(worst < 0.12, "worst pixel off by %.2f%%", 100 * worst);
  return 0;
}
static int closed_sphere_point_light(void) {
  return inside_sphere("", "{\"type\": \"point\", \"position\": [0,0,0], \"intensity\": 3.14159265358979}", 1.0, 256);
}
static int closed_sphere_emissive(void) { return inside_sphere(", \"emission\": 0.5", "", 1.0, 256); }
/* Emission is front-sided: with the same sphere's normals facing out, the inside is black. */
static int emission_front_side_only(void) {
  const char *json =
      "{ \"camera\": {\"position\": [0,0,0.3], \"look_at\": [0,0,-1], \"up\": [0,1,0], \"fov\": 70},\n"
      "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 16},\n"
      "  \"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5, \"emission\": 0.5}},\n"
      "  \"shapes\": [{\"type\": \"sphere\", \"radius\": 1, \"subdivisions\": 3, \"material\": \"m\"}] }\n";
  int w, h;
  float *px = render_json_text(json, NULL, &w, &h);
  CHECK(px, "render failed");
  double sum = 0;
  for (int i = 0; i < w * h * 3; i++) sum += px[i];
  free(px);
  /* Light samples on the shading point's own facet meet it at cos ~ 0 and may round to
   * the front side: a contribution of order 1e-9, nothing more. */
  CHECK(sum / (w * h * 3) < 1e-6, "inside of an outward-emitting sphere should be black, got mean %g", sum / (w * h * 3));
  /* ... and two_sided makes it emit inwards too. */
  const char *json2 =
      "{ \"camera\": {\"position\": [0,0,0.3], \"look_at\": [0,0,-1], \"up\": [0,1,0], \"fov\": 70},\n"
      "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 64},\n"
      "  \"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5, \"emission\": 0.5, \"two_sided\": true}},\n"
      "  \"shapes\": [{\"type\": \"sphere\", \"radius\": 1, \"subdivisions\": 3, \"smooth\": false, \"material\": \"m\"}] }\n";
  px = render_json_text(json2, NULL, &w, &h);
  CHECK(px, "render failed");
  sum = 0;
  for (int i = 0; i < w * h * 3; i++) sum += px[i];
  free(px);
  double mean = sum / (w * h * 3);
  CHECK(fabs(mean - 1) < 0.02, "two-sided emissive closed sphere: mean %g, expected 1", mean);
  return 0;
}
/* max_depth 1 inside the point-lit sphere: direct light only, 0.5 exactly (up to the
 * facets' distance from the centre). */
static int max_depth_direct_only(void) {
  const char *json =
      "{ \"camera\": {\"position\": [0,0,0.3], \"look_at\": [0,0,-1], \"up\": [0,1,0], \"fov\": 70},\n"
      "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 4, \"max_depth\": 1},\n"
      "  \"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
      "  \"shapes\": [{\"type\": \"sphere\", \"radius\": 1, \"subdivisions\": 6, \"smooth\": false, \"material\": \"m\"}],\n"
      "  \"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"intensity\": 3.14159265358979}] }\n";
  int w, h;
  float *px = render_json_text(json, NULL, &w, &h);
  CHECK(px, "render failed");
  for (int i = 0; i < w * h * 3; i++) CHECK(fabs(px[i] - 0.5) < 0.002, "pixel value %g, expected 0.5", px[i]);
  free(px);
  return 0;
}

/* A map of constant radiance 1 is the white furnace again: albedo 0.5 shows 0.5. */
/* A diffuse sphere of albedo 0.5 under a constant map of radiance L (file, in the
 * scratch folder): the background must be L and the sphere 0.5 L. */
static int furnace_map(const char *file, double L) {
  char json[2048];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [0,0,4], \"look_at\": [0,0,0], \"up\": [0,1,0], \"fov\": 40},\n"
           "  \"film\": {\"width\": 32, \"height\": 32}, \"render\": {\"spp\": 256, \"seed\": 5},\n"
           "  \"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
           "  \"shapes\": [{\"type\": \"sphere\", \"radius\": 1, \"subdivisions\": 4, \"smooth\": false, \"material\": \"m\"}],\n"
           "  \"environment\": {\"type\": \"map\", \"file\": \"%s\", \"rotation\": 17} }\n", file);
  int w, h;
  float *img = render_json_text(json, NULL, &w, &h);
  CHECK(img, "render failed");
  double sum[2] = {0, 0};
  int n[2] = {0, 0};
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      int k = classify(x, y);
      if (k < 0) continue;
      sum[k] += (img[3 * (y * w + x)] + img[3 * (y * w + x) + 1] + img[3 * (y * w + x) + 2]) / 3;
      n[k]++;
    }
  free(img);
  fprintf(stderr, "constant map %s: sphere %.5f, background %.5f (L = %.5f)\n", file, sum[1] / n[1], sum[0] / n[0], L);
  CHECK(fabs(sum[1] / n[1] - 0.5 * L) < 0.005 * L, "sphere mean %g, expected %g", sum[1] / n[1], 0.5 * L);
  CHECK(fabs(sum[0] / n[0] - L) < 1e-5 * L, "background %g, expected %g", sum[0] / n[0], L);
  return 0;
}

/* The same map as a linear PFM (L = 1) and as an 8-bit PNG, whose bytes are decoded from
 * sRGB: linear 0.5 is stored as 188, which is radiance ((188/255 + 0.055) / 1.055)^2.4. */
static int furnace_constant_map(void) {
  float *px = malloc(sizeof(float) * 32 * 16 * 3);
  char path[1200];
  valo_error err;
  for (int i = 0; i < 32 * 16 * 3; i++) px[i] = 1;
  snprintf(path, sizeof path, "%s/white.pfm", scratch_dir());
  CHECK(image_write(path, 32, 16, px, NULL, &err) == VALO_OK, "%s", err.message);
  for (int i = 0; i < 32 * 16 * 3; i++) px[i] = 0.5f;
  snprintf(path, sizeof path, "%s/grey.png", scratch_dir());
  CHECK(image_write(path, 32, 16, px, NULL, &err) == VALO_OK, "%s", err.message);
  free(px);
  return furnace_map("white.pfm", 1.0) || furnace_map("grey.png", pow((188.0 / 255.0 + 0.055) / 1.055, 2.4));
}

/* Adaptive sampling keeps the image unbiased where paths are rare and bright:
 * the glass sphere's caustic (scenes/caustic.json, path, 64x64, 16 spp), 24 seeds each
 * uniform and adaptive; the mean over the image and over the caustic's block must agree
 * (|z| < 4; a false failure about 1 in 16 000). The digest's rule, which decides on the
 * pixel's own samples, must show its bias here (z above 4), so the test can see one. */
static int adaptive_means(int rule, int seeds, double *mean, double *se, double *cmean, double *cse) {
  double s = 0, ss = 0, c = 0, cc = 0;
  for (int k = 0; k < seeds; k++) {
    valo_options o;
    valo_options_init(&o);
    snprintf(o.integrator, sizeof o.integrator, "path");
    o.width = o.height = 64;
    o.spp = 16;
    o.seed = 100 + k;
    o.adaptive = rule;
    valo_scene *sc;
    valo_render *r = render_file(VALO_SOURCE_DIR "/scenes/caustic.json", &o, &sc);
    if (!r) return -1;
    float *px = malloc(64 * 64 * 3 * sizeof(float));
    valo_render_pixels(r, px);
    valo_render_destroy(r);
    valo_scene_destroy(sc);
    double m = 0, cm = 0;
    for (int i = 0; i < 64 * 64; i++) m += px[3 * i] / (64.0 * 64);
    for (int y = 28; y < 44; y++)
      for (int x = 24; x < 40; x++) cm += px[3 * (y * 64 + x)] / 256.0;
    free(px);
    s += m; ss += m * m; c += cm; cc += cm * cm;
  }
  *mean = s / seeds; *se = sqrt((ss / seeds - *mean * *mean) / (seeds - 1));
  *cmean = c / seeds; *cse = sqrt((cc / seeds - *cmean * *cmean) / (seeds - 1));
  return 0;
}
static int adaptive_unbiased(void) {
  allow_shading_loss(0.02); /* the scene's sphere has interpolated normals */
  const int seeds = test_full() ? 64 : 24;
  double um, us, ucm, ucs, am, as, acm, acs, dm, ds, dcm, dcs;
  CHECK(adaptive_means(0, seeds, &um, &us, &ucm, &ucs) == 0 && adaptive_means(VALO_ADAPTIVE_ERROR, seeds, &am, &as, &acm, &acs) == 0 &&
            adaptive_means(VALO_ADAPTIVE_DIGEST, seeds, &dm, &ds, &dcm, &dcs) == 0,
        "render failed");
  double z = (am - um) / sqrt(us * us + as * as), zc = (acm - ucm) / sqrt(ucs * ucs + acs * acs);
  double zd = (dm - um) / sqrt(us * us + ds * ds), zdc = (dcm - ucm) / sqrt(ucs * ucs + dcs * dcs);
  fprintf(stderr, "image mean: uniform %.5f +- %.5f, adaptive %.5f +- %.5f (z %.2f), digest rule %.5f +- %.5f (z %.2f)\n", um, us, am, as, z, dm, ds,
          zd);
  fprintf(stderr, "caustic block: uniform %.5f +- %.5f, adaptive %.5f +- %.5f (z %.2f), digest rule %.5f +- %.5f (z %.2f)\n", ucm, ucs, acm, acs, zc,
          dcm, dcs, zdc);
  CHECK(fabs(z) < 4 && fabs(zc) < 4, "adaptive sampling is biased: z %.2f over the image, %.2f on the caustic", z, zc);
  CHECK(fabs(zd) > 4 || fabs(zdc) > 4, "the digest rule's bias went unseen (z %.2f, %.2f): the test has no power", zd, zdc);
  return 0;
}

/* Adaptive sampling pays where noise is uneven: on the glass sphere's caustic
 * (scenes/caustic.json, path, 128x128, 256 spp) the default rule's relMSE against
 * tests/data/caustic-path.exr (32 768 spp), summed over two seeds, is at least 1.5x below
 * uniform sampling's at the same samples (measured 1.85x; with a 9x9 neighbourhood 1.57x;
 * bench_adaptive's bound 1.77x at this budget). A rule spending its samples as uniform
 * sampling would fails it. */
static int adaptive_pays_caustic(void) {
  allow_shading_loss(0.02);
  image ref;
  valo_error err;
  CHECK(image_read(VALO_SOURCE_DIR "/tests/data/caustic-path.exr", &ref, &err) == VALO_OK, "%s", err.message);
  double e[2] = {0, 0};
  size_t np = (size_t)ref.w * ref.h;
  float *px = malloc(np * 3 * sizeof *px);
  for (int mode = 0; mode < 2; mode++)
    for (int k = 0; k < 2; k++) {
      valo_options o;
      valo_options_init(&o);
      snprintf(o.integrator, sizeof o.integrator, "path");
      o.width = ref.w;
      o.height = ref.h;
      o.spp = 256;
      o.seed = 40 + k;
      o.adaptive = mode ? VALO_ADAPTIVE_ERROR : 0;
      valo_scene *sc;
      valo_render *r = render_file(VALO_SOURCE_DIR "/scenes/caustic.json", &o, &sc);
      CHECK(r, "render failed");
      valo_render_pixels(r, px);
      valo_render_destroy(r);
      valo_scene_destroy(sc);
      for (size_t i = 0; i < np * 3; i++) {
        double d = px[i] - ref.rgb[i];
        e[mode] += d * d / (ref.rgb[i] * ref.rgb[i] + 0.01);
      }
    }
  free(px);
  image_free(&ref);
  fprintf(stderr, "caustic relMSE at 256 spp: uniform %.5f, adaptive %.5f (%.2fx)\n", e[0] / (6.0 * np), e[1] / (6.0 * np), e[0] / e[1]);
  CHECK(e[0] > 1.5 * e[1], "adaptive sampling gains only %.2fx over uniform on the caustic", e[0] / e[1]);
  return 0;
}

/* Orientation: a map red for u < 0.5, green for u >= 0.5; looking down -z (the map's
 * centre) shows red on the left, green on the right; turned 180 degrees, the reverse. */
static int envmap_orientation(void) {
  float *px = malloc(sizeof(float) * 64 * 32 * 3);
  for (int y = 0; y < 32; y++)
    for (int x = 0; x < 64; x++) {
      px[3 * (y * 64 + x)] = x < 32 ? 1.0f : 0.0f;
      px[3 * (y * 64 + x) + 1] = x < 32 ? 0.0f : 1.0f;
      px[3 * (y * 64 + x) + 2] = y < 16 ? 0.5f : 0.0f; /* blue only in the upper half */
    }
  char path[1200];
  snprintf(path, sizeof path, "%s/halves.pfm", scratch_dir());
  valo_error err;
  CHECK(image_write(path, 64, 32, px, NULL, &err) == VALO_OK, "%s", err.message);
  free(px);
  for (int rot = 0; rot < 2; rot++) {
    char json[1024];
    snprintf(json, sizeof json,
             "{ \"camera\": {\"position\": [0,0,0], \"look_at\": [0,0,-1], \"up\": [0,1,0], \"fov\": 60},\n"
             "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 4},\n"
             "  \"environment\": {\"type\": \"map\", \"file\": \"halves.pfm\", \"rotation\": %d} }\n", rot ? 180 : 0);
    int w, h;
    float *img = render_json_text(json, NULL, &w, &h);
    CHECK(img, "render failed");
    const float *left = &img[3 * (8 * w + 2)], *right = &img[3 * (8 * w + 13)];
    const float *top = &img[3 * (1 * w + 8)], *bottom = &img[3 * (14 * w + 8)];
    if (!rot) CHECK(left[0] > 0.9f && left[1] < 0.1f && right[1] > 0.9f && right[0] < 0.1f, "left (%g %g) right (%g %g)", left[0], left[1], right[0], right[1]);
    else CHECK(left[1] > 0.9f && left[0] < 0.1f && right[0] > 0.9f && right[1] < 0.1f, "rotated: left (%g %g) right (%g %g)", left[0], left[1], right[0], right[1]);
    CHECK(top[2] > 0.4f && bottom[2] < 0.1f, "up is not up: top blue %g, bottom blue %g", top[2], bottom[2]);
    free(img);
  }
  return 0;
}

/* A spherical camera (camera.type "spherical": equirectangular, longitude 0 along the view
 * direction growing to the right, latitude 90 degrees at the top) at the centre of a map
 * of the same layout (u = (x + 0.5)/64 in red, v = (y + 0.5)/32 in green) sees the map
 * itself: looking down -z (the map's centre) each pixel shows its own u and v; looking
 * along +x the longitudes move a quarter turn (u + 0.25). The ramps are linear, so the
 * map's bilinear lookup and the pixel's box average keep them, away from the seam of u
 * and the poles' half texels. */
static int spherical_camera(void) {
  float *px = malloc(sizeof(float) * 64 * 32 * 3);
  for (int y = 0; y < 32; y++)
    for (int x = 0; x < 64; x++) {
      px[3 * (y * 64 + x)] = (x + 0.5f) / 64;
      px[3 * (y * 64 + x) + 1] = (y + 0.5f) / 32;
      px[3 * (y * 64 + x) + 2] = 0.5f;
    }
  char path[1200];
  snprintf(path, sizeof path, "%s/ramps.pfm", scratch_dir());
  valo_error err;
  CHECK(image_write(path, 64, 32, px, NULL, &err) == VALO_OK, "%s", err.message);
  free(px);
  for (int turn = 0; turn < 2; turn++) {
    char json[1024];
    snprintf(json, sizeof json,
             "{ \"camera\": {\"type\": \"spherical\", \"position\": [0,0,0], \"look_at\": [%d,0,%d], \"up\": [0,1,0]},\n"
             "  \"film\": {\"width\": 64, \"height\": 32}, \"render\": {\"spp\": 16},\n"
             "  \"environment\": {\"type\": \"map\", \"file\": \"ramps.pfm\"} }\n", turn ? 1 : 0, turn ? 0 : -1);
    int w, h;
    float *img = render_json_text(json, NULL, &w, &h);
    CHECK(img && w == 64 && h == 32, "render failed");
    double worst = 0;
    int wx = 0, wy = 0;
    for (int y = 1; y < 31; y++)
      for (int x = 0; x < 64; x++) {
        double u = (x + 0.5) / 64 + 0.25 * turn;
        u -= floor(u);
        if (u < 1.5 / 64 || u > 1 - 1.5 / 64) continue; /* the map's seam: bilinear across it */
        double e = fmax(fabs(img[3 * (y * 64 + x)] - u), fabs(img[3 * (y * 64 + x) + 1] - (y + 0.5) / 32));
        if (e > worst) { worst = e; wx = x; wy = y; }
      }
    fprintf(stderr, "spherical camera looking along %s: largest difference from the map %.4f at (%d, %d)\n", turn ? "+x" : "-z", worst, wx, wy);
    free(img);
    CHECK(worst < 0.01, "looking along %s the image differs from the map by %.4f at (%d, %d)", turn ? "+x" : "-z", worst, wx, wy);
  }
  return 0;
}

/* Irradiance from a map: a 64x32 map with a vertical gradient and a hot spot,
 * turned 30 degrees, lights a diffuse quad facing +x (albedo 0.8, nothing else in the
 * scene). Its radiance must be 0.8 E / pi, with E integrated here over the map as the
 * docs define it (texel (i, j) centred at ((i + .5)/W, (j + .5)/H), bilinear, u wrapping,
 * v clamped; the map's centre looking down -z, u towards +x, turned about +y): 12x12
 * points per texel, each weighted by its solid angle. Within 1 %; unturned, E differs by
 * more than 5 %, so the rotation is checked too. */
static double map_texel(const float *px, int w, int h, int x, int y, int c) {
  x = ((x % w) + w) % w;
  y = y < 0 ? 0 : y >= h ? h - 1 : y;
  return px[3 * (y * w + x) + c];
}
static double map_irradiance(const float *px, int w, int h, double rot_deg, const double n[3], int c) {
  double r = rot_deg * M_PI / 180, E = 0;
  const int sub = 12;
  for (int j = 0; j < h * sub; j++) {
    double v = (j + 0.5) / (h * sub), th = v * M_PI;
    for (int i = 0; i < w * sub; i++) {
      double u = (i + 0.5) / (w * sub), ph = (u - 0.5) * 2 * M_PI;
      double d[3] = {sin(th) * sin(ph), cos(th), -sin(th) * cos(ph)};
      double wd[3] = {cos(r) * d[0] + sin(r) * d[2], d[1], -sin(r) * d[0] + cos(r) * d[2]}; /* map -> world */
      double cs = wd[0] * n[0] + wd[1] * n[1] + wd[2] * n[2];
      if (cs <= 0) continue;
      double x = u * w - 0.5, y = v * h - 0.5;
      int x0 = (int)floor(x), y0 = (int)floor(y);
      double fx = x - x0, fy = y - y0;
      double L = (1 - fy) * ((1 - fx) * map_texel(px, w, h, x0, y0, c) + fx * map_texel(px, w, h, x0 + 1, y0, c)) +
                 fy * ((1 - fx) * map_texel(px, w, h, x0, y0 + 1, c) + fx * map_texel(px, w, h, x0 + 1, y0 + 1, c));
      E += L * cs * sin(th);
    }
  }
  return E * (M_PI / (h * sub)) * (2 * M_PI / (w * sub));
}
static int envmap_irradiance(void) {
  const int w = 64, h = 32;
  float *px = malloc(sizeof(float) * w * h * 3);
  CHECK(px, "oom");
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      double g = 0.3 + 0.7 * (1 - (y + 0.5) / h);
      int hot = x >= 40 && x <= 42 && y >= 10 && y <= 11;
      px[3 * (y * w + x)] = (float)(hot ? 30 : g);
      px[3 * (y * w + x) + 1] = (float)(hot ? 20 : 0.9 * g);
      px[3 * (y * w + x) + 2] = (float)(hot ? 10 : 1.1 * g);
    }
  char path[1200];
  snprintf(path, sizeof path, "%s/hotspot.pfm", scratch_dir());
  valo_error err;
  CHECK(image_write(path, w, h, px, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(scratch_file("wallx.obj", "v 0 -1 -1\nv 0 1 -1\nv 0 1 1\nv 0 -1 1\nf 1 2 3 4\n"), "write");
  const double n[3] = {1, 0, 0};
  double E30[3], E0[3];
  for (int c = 0; c < 3; c++) { E30[c] = map_irradiance(px, w, h, 30, n, c); E0[c] = map_irradiance(px, w, h, 0, n, c); }
  free(px);
  fprintf(stderr, "irradiance of the +x face: turned 30 degrees (%.4f %.4f %.4f), unturned (%.4f %.4f %.4f)\n", E30[0], E30[1], E30[2], E0[0], E0[1],
          E0[2]);
  CHECK(fabs(E30[0] - E0[0]) > 0.05 * E30[0], "the rotation hardly matters for this map (%.4f vs %.4f): the test would not see it", E30[0], E0[0]);
  const char *json = "{ \"camera\": {\"position\": [4,0,0], \"look_at\": [0,0,0], \"up\": [0,1,0], \"fov\": 10},\n"
                     "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 256},\n"
                     "  \"materials\": {\"wall\": {\"type\": \"diffuse\", \"reflectance\": 0.8}},\n"
                     "  \"shapes\": [{\"file\": \"wallx.obj\", \"material\": \"wall\"}],\n"
                     "  \"environment\": {\"type\": \"map\", \"file\": \"hotspot.pfm\", \"rotation\": 30} }\n";
  int iw, ih;
  float *img = render_json_text(json, NULL, &iw, &ih);
  CHECK(img, "render failed");
  double m[3] = {0};
  for (int y = 4; y < 12; y++)
    for (int x = 4; x < 12; x++)
      for (int c = 0; c < 3; c++) m[c] += img[3 * (y * iw + x) + c] / 64.0;
  free(img);
  for (int c = 0; c < 3; c++) {
    double want = 0.8 * E30[c] / M_PI;
    fprintf(stderr, "channel %d: rendered %.5f, 0.8 E / pi = %.5f (%+.2f %%)\n", c, m[c], want, 100 * (m[c] / want - 1));
    CHECK(fabs(m[c] / want - 1) < 0.01, "channel %d: %.5f vs %.5f", c, m[c], want);
  }
  return 0;
}

/* Cube maps: six 64x64 faces, each marked with its index (red) and its left/right and
 * top/bottom halves (green, blue). A camera at the centre facing each face in turn (up
 * +y for the sides; looking up or down from facing -z for +y and -y) sees that face,
 * upright and not mirrored, as envmap.h defines the convention. */
static int envmap_cube(void) {
  static const char *const names[6] = {"px", "nx", "py", "ny", "pz", "nz"};
  float *px = malloc(sizeof(float) * 64 * 64 * 3);
  CHECK(px, "oom");
  valo_error err;
  for (int f = 0; f < 6; f++) {
    for (int y = 0; y < 64; y++)
      for (int x = 0; x < 64; x++) {
        float *p = &px[3 * (y * 64 + x)];
        p[0] = (f + 1) / 8.0f; p[1] = x < 32 ? 0.25f : 0.75f; p[2] = y < 32 ? 0.25f : 0.75f;
      }
    char path[1200];
    snprintf(path, sizeof path, "%s/cube_%s.pfm", scratch_dir(), names[f]);
    CHECK(image_write(path, 64, 64, px, NULL, &err) == VALO_OK, "%s", err.message);
  }
  free(px);
  /* look direction, up, expected face */
  static const float views[6][7] = {{0, 0, -1, 0, 1, 0, 4}, {0, 0, 1, 0, 1, 0, 5}, {1, 0, 0, 0, 1, 0, 0},
                                    {-1, 0, 0, 0, 1, 0, 1}, {0, 1, 0, 0, 0, 1, 2}, {0, -1, 0, 0, 0, -1, 3}};
  for (int v = 0; v < 6; v++) {
    const float *V = views[v];
    char json[1024];
    snprintf(json, sizeof json,
             "{ \"camera\": {\"position\": [0,0,0], \"look_at\": [%g,%g,%g], \"up\": [%g,%g,%g], \"fov\": 30},\n"
             "  \"film\": {\"width\": 16, \"height\": 16}, \"render\": {\"spp\": 4},\n"
             "  \"environment\": {\"type\": \"cube\", \"faces\": [\"cube_px.pfm\", \"cube_nx.pfm\", \"cube_py.pfm\", \"cube_ny.pfm\", \"cube_pz.pfm\", \"cube_nz.pfm\"]} }\n",
             V[0], V[1], V[2], V[3], V[4], V[5]);
    int w, h;
    float *img = render_json_text(json, NULL, &w, &h);
    CHECK(img, "render failed");
    const float *left = &img[3 * (8 * w + 2)], *right = &img[3 * (8 * w + 13)];
    const float *top = &img[3 * (1 * w + 8)], *bottom = &img[3 * (14 * w + 8)];
    float face = (V[6] + 1) / 8.0f;
    fprintf(stderr, "looking (%g %g %g): face red %.3f (expected %.3f), left/right green %.3f/%.3f, top/bottom blue %.3f/%.3f\n", V[0], V[1],
            V[2], left[0], face, left[1], right[1], top[2], bottom[2]);
    int ok = fabsf(left[0] - face) < 0.01f && fabsf(right[0] - face) < 0.01f && fabsf(left[1] - 0.25f) < 0.05f &&
             fabsf(right[1] - 0.75f) < 0.05f && fabsf(top[2] - 0.25f) < 0.05f && fabsf(bottom[2] - 0.75f) < 0.05f;
    free(img);
    CHECK(ok, "wrong face or orientation when looking along (%g %g %g)", V[0], V[1], V[2]);
  }
  return 0;
}

/* AOVs of a plane facing the camera: albedo = its reflectance, normal = +z (towards the
 * camera, though the plane's winding faces away), depth = distance along each ray. */
static int aovs(void) {
  CHECK(scratch_file("plane.obj", "v -5 -5 0\nv -5 5 0\nv 5 5 0\nv 5 -5 0\nf 1 2 3 4\n"), "write");
  const char *path = scratch_file("aov.json",
      "{ \"camera\": {\"position\": [0,0,3], \"look_at\": [0,0,0], \"fov\": 30},\n"
      "  \"film\": {\"width\": 9, \"height\": 9}, \"render\": {\"spp\": 8},\n"
      "  \"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": [0.2,0.4,0.6]}},\n"
      "  \"shapes\": [{\"file\": \"plane.obj\", \"material\": \"m\"}],\n"
      "  \"lights\": [{\"type\": \"point\", \"position\": [0,0,2], \"intensity\": 1}] }\n");
  valo_options o;
  valo_options_init(&o);
  o.aovs = 1;
  valo_error err;
  valo_scene *sc;
  valo_render *r = render_file(path, &o, &sc);
  CHECK(r, "render failed");
  const char *names[3] = {"albedo", "normal", "depth"};
  image im[3];
  for (int k = 0; k < 3; k++) CHECK(read_aov(r, names[k], &im[k]) == 0, "cannot write or read the %s AOV", names[k]);
  const float *a = &im[0].rgb[3 * (4 * 9 + 4)], *n = &im[1].rgb[3 * (4 * 9 + 4)], *d = &im[2].rgb[3 * (4 * 9 + 4)];
  CHECK(fabsf(a[0] - 0.2f) < 1e-5f && fabsf(a[1] - 0.4f) < 1e-5f && fabsf(a[2] - 0.6f) < 1e-5f, "albedo (%g %g %g)", a[0], a[1], a[2]);
  CHECK(fabsf(n[2] - 1) < 1e-5f, "normal (%g %g %g)", n[0], n[1], n[2]);
  CHECK(fabsf(d[0] - 3) < 0.01f, "centre depth %g, expected 3 (within the pixel's jitter)", d[0]);
  const float *dc = &im[2].rgb[0];
  float tanh = tanf(15.0f * 3.14159265f / 180) * (1 - 1.0f / 9); /* corner pixel centre */
  float expect = 3 * sqrtf(1 + 2 * tanh * tanh);
  CHECK(fabsf(dc[0] - expect) < 0.05f, "corner depth %g, expected about %g", dc[0], expect);
  for (int k = 0; k < 3; k++) image_free(&im[k]);
  /* As PNG: normals n/2 + 1/2, depth over its largest value, sample counts
   * over the largest, stored linearly in the 8 bits. */
  static const char *const pngs[3] = {"normal", "depth", "spp"};
  for (int k = 0; k < 3; k++) {
    char file[1200], spec[1300];
    snprintf(file, sizeof file, "%s/aov_%s.png", scratch_dir(), pngs[k]);
    snprintf(spec, sizeof spec, "%s:%s", pngs[k], file);
    CHECK(valo_render_write(r, spec, NULL, &err) == VALO_OK, "%s", err.message);
    texture t;
    CHECK(texture_load_file(&t, file, 0, &err) == VALO_OK, "%s", err.message);
    float c[4], corner[4];
    texture_texel(&t, 4, 4, c);
    texture_texel(&t, 0, 0, corner);
    texture_free(&t);
    if (k == 0) CHECK(fabsf(c[0] - 0.5f) < 0.01f && fabsf(c[1] - 0.5f) < 0.01f && c[2] > 0.99f, "normal PNG (%g %g %g)", c[0], c[1], c[2]);
    if (k == 1) CHECK(fabsf(c[0] - 3 / expect) < 0.01f && corner[0] > 0.99f, "depth PNG centre %g (expected %g), corner %g", c[0], 3 / expect, corner[0]);
    if (k == 2) CHECK(c[0] > 0.99f, "spp PNG %g (every pixel has the largest count)", c[0]);
  }
  /* The denoised image of the lit plane (variance estimated, the film kept no squares):
   * the same light, the noise gone (the raw centre column's spread is the bound). */
  image dn;
  float raw[81 * 3];
  valo_render_pixels(r, raw);
  CHECK(read_aov(r, "denoised", &dn) == 0, "cannot write or read the denoised image");
  double sr = 0, sd = 0;
  for (int i = 0; i < 81 * 3; i++) { sr += raw[i]; sd += dn.rgb[i]; }
  fprintf(stderr, "denoised plane: mean %.5f against the raw %.5f\n", sd / 243, sr / 243);
  CHECK(fabs(sd / sr - 1) < 0.02, "the denoised plane's mean moved by %.2f %%", 100 * (sd / sr - 1));
  image_free(&dn);
  /* The ao AOVs cost a ray per sample: without the VALO_AOVS_AO bit they were not
   * recorded, and asking for them is a clear error. */
  CHECK(valo_render_write(r, "ao:x.exr", NULL, &err) == VALO_ERR_INVALID && strstr(err.message, "VALO_AOVS_AO"), "ao AOV without the bit accepted");
  /* Without aovs set, asking for one is a clear error. */
  valo_render_destroy(r);
  CHECK(valo_render_create(sc, NULL, &r, &err) == VALO_OK, "%s", err.message);
  CHECK(valo_render_write(r, "albedo:x.exr", NULL, &err) == VALO_ERR_INVALID, "AOV without aovs accepted");
  CHECK(valo_render_write(r, "denoised:x.exr", NULL, &err) == VALO_ERR_INVALID, "denoised without aovs accepted");
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  return 0;
}

/* Thin lens: a tiny emitter at distance D, focus at F, aperture radius A spreads into a
 * uniform disk of angular radius atan(A |1 - F/D| / F) (plus the emitter's own size);
 * in focus it stays a dot. */
static double spot_radius(const char *json, const valo_options *opt) {
  int w, h;
  float *px = render_json_text(json, opt, &w, &h);
  if (!px) return -1;
  /* Energy-weighted second moment of the spot: a uniform disk of radius R has
   * E[r^2] = R^2 / 2. */
  double sum = 0, m2 = 0;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      double v = px[3 * (y * w + x) + 1], dx = x + 0.5 - w / 2.0, dy = y + 0.5 - h / 2.0;
      sum += v; m2 += v * (dx * dx + dy * dy);
    }
  free(px);
  return sum > 0 ? sqrt(2 * m2 / sum) : -1;
}
#define SPOT_SCENE_TAIL                                                                            \
  "  \"film\": {\"width\": 96, \"height\": 96}, \"render\": {\"spp\": 256},\n"                     \
  "  \"materials\": {\"e\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": 1000}},\n"   \
  "  \"shapes\": [%s{\"type\": \"sphere\", \"center\": [%g,0,-4], \"radius\": 0.005, \"subdivisions\": 2, \"material\": \"e\"}] }\n"
static double spot_radius_px(double aperture, double focus) {
  char json[1024];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [0,0,0], \"look_at\": [0,0,-1], \"fov\": 20, \"aperture_radius\": %g, \"focus_distance\": %g},\n" SPOT_SCENE_TAIL,
           aperture, focus, "", 0.0);
  return spot_radius(json, NULL);
}
static int thin_lens_circle_of_confusion(void) {
  double A = 0.1, F = 2, D = 4;
  double tan_half = tan(10.0 * M_PI / 180);
  double predicted = A * fabs(1 - F / D) / F / tan_half * 48; /* pixels: half the film spans tan_half */
  double r = spot_radius_px(A, F), r_focus = spot_radius_px(A, D), r_pin = spot_radius_px(0, F);
  fprintf(stderr, "spot radius: defocused %.2f px (predicted %.2f), in focus %.2f px, pinhole %.2f px\n", r, predicted, r_focus, r_pin);
  CHECK(r > 0 && r_focus >= 0 && r_pin >= 0, "render failed");
  CHECK(fabs(r - predicted) < 0.05 * predicted + 0.5, "defocus radius %.2f px, predicted %.2f", r, predicted);
  CHECK(r_focus < 1.5 && r_pin < 1.5, "in focus the spot should stay within a pixel or so (%.2f, %.2f)", r_focus, r_pin);
  return 0;
}

/* The same lens through restir-di and restir-gi: their G-buffer's camera rays are the
 * tile loop's (camera_ray), so the spot spreads to the same predicted radius and stays
 * sharp in focus. */
static int thin_lens_restir(void) {
  double A = 0.1, F = 2, D = 4;
  double predicted = A * fabs(1 - F / D) / F / tan(10.0 * M_PI / 180) * 48;
  const char *integ[2] = {"restir-di", "restir-gi"};
  for (int k = 0; k < 2; k++) {
    char json[1024];
    valo_options o;
    valo_options_init(&o);
    snprintf(o.integrator, sizeof o.integrator, "%s", integ[k]);
    o.spp = 64;
    double r[2];
    for (int focus = 0; focus < 2; focus++) {
      snprintf(json, sizeof json,
               "{ \"camera\": {\"position\": [0,0,0], \"look_at\": [0,0,-1], \"fov\": 20, \"aperture_radius\": %g, \"focus_distance\": %g},\n" SPOT_SCENE_TAIL,
               A, focus ? D : F, "", 0.0);
      r[focus] = spot_radius(json, &o);
    }
    fprintf(stderr, "%s spot radius: defocused %.2f px (predicted %.2f), in focus %.2f px\n", integ[k], r[0], predicted, r[1]);
    CHECK(r[0] > 0 && r[1] >= 0, "%s: render failed", integ[k]);
    CHECK(fabs(r[0] - predicted) < 0.05 * predicted + 0.5, "%s: defocus radius %.2f px, predicted %.2f", integ[k], r[0], predicted);
    CHECK(r[1] < 1.5, "%s: in focus the spot should stay within a pixel or so (%.2f)", integ[k], r[1]);
  }
  return 0;
}

/* The same lens on a glTF camera (glTF has no aperture): the camera node sits at x = 1
 * looking down -z with a 20 degree yfov; the JSON file takes it with camera.from_file
 * and adds the lens, or the render options add it (as --aperture/--focus do). With no
 * focus distance a file camera focuses on the surface at the image centre: the spot. */
static const char gltf_camera[] =
    "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0, 1]}],\n"
    " \"nodes\": [{\"camera\": 0, \"translation\": [1, 0, 0], \"name\": \"cam\"}, {\"mesh\": 0}],\n"
    " \"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 0.34906585, \"aspectRatio\": 1.0, \"znear\": 0.01}}],\n"
    " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}}]}],\n"
    " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", \"min\": [0,0,10], \"max\": [0.1,0.1,10]}],\n"
    " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}],\n"
    " \"buffers\": [{\"byteLength\": 36, \"uri\": \"data:application/octet-stream;base64,AAAAAAAAAAAAACBBzczMPQAAAAAAACBBAAAAAM3MzD0AACBB\"}]}\n";
static int thin_lens_gltf_camera(void) {
  double A = 0.1, F = 2;
  double predicted = A * fabs(1 - F / 4) / F / tan(10.0 * M_PI / 180) * 48;
  CHECK(scratch_file("lens_camera.gltf", gltf_camera), "cannot write the glTF file");
  const char *shape = "{\"file\": \"lens_camera.gltf\"}, "; /* beside the JSON file */
  char json[2400];
  snprintf(json, sizeof json, "{ \"camera\": {\"from_file\": true, \"aperture_radius\": %g, \"focus_distance\": %g},\n" SPOT_SCENE_TAIL, A, F, shape, 1.0);
  double r_json = spot_radius(json, NULL);
  snprintf(json, sizeof json, "{ \"camera\": {\"from_file\": true},\n" SPOT_SCENE_TAIL, shape, 1.0);
  valo_options o;
  valo_options_init(&o);
  o.aperture_radius = A;
  o.focus_distance = F;
  double r_opt = spot_radius(json, &o);
  o.focus_distance = VALO_UNSET; /* autofocus: on the spot itself */
  double r_auto = spot_radius(json, &o);
  double r_pin = spot_radius(json, NULL);
  fprintf(stderr, "glTF camera spot radius: JSON lens %.2f px, option lens %.2f px (predicted %.2f), autofocus %.2f px, pinhole %.2f px\n",
          r_json, r_opt, predicted, r_auto, r_pin);
  CHECK(r_json > 0 && r_opt > 0 && r_auto >= 0 && r_pin >= 0, "render failed (is the spot in view?)");
  CHECK(fabs(r_json - predicted) < 0.05 * predicted + 0.5, "from_file lens: %.2f px, predicted %.2f", r_json, predicted);
  CHECK(fabs(r_opt - predicted) < 0.05 * predicted + 0.5, "option lens: %.2f px, predicted %.2f", r_opt, predicted);
  CHECK(r_auto < 1.5 && r_pin < 1.5, "autofocus and pinhole should keep the spot sharp (%.2f, %.2f)", r_auto, r_pin);
  return 0;
}

/* An orthographic camera (camera.type "orthographic", height H): rays run along the view
 * axis from their own point of the camera plane, so an object's size on the film does not
 * depend on its distance. Two emitting spheres of radius 0.5, one at distance 2 and one
 * at 30, each cover pi (0.5 * 64 / H)^2 pixels centred where their centres project, and
 * the depth AOV is the distance from the camera plane (1.5 at the near one's front). The
 * thin lens spreads a point at depth D focused at F into a disk of radius A |1 - D/F| in
 * scene units; in focus it stays a dot. */
static int orthographic_camera(void) {
  const double H = 4, ppu = 64 / H; /* pixels per scene unit */
  const char *json = scratch_file("ortho.json",
      "{ \"camera\": {\"type\": \"orthographic\", \"height\": 4, \"position\": [0,0,0], \"look_at\": [0,0,-1]},\n"
      "  \"film\": {\"width\": 96, \"height\": 64}, \"render\": {\"spp\": 64},\n"
      "  \"materials\": {\"e\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": 1}},\n"
      "  \"shapes\": [{\"type\": \"sphere\", \"center\": [-1,0,-2], \"radius\": 0.5, \"subdivisions\": 5, \"material\": \"e\"},\n"
      "             {\"type\": \"sphere\", \"center\": [1,0,-30], \"radius\": 0.5, \"subdivisions\": 5, \"material\": \"e\"}] }\n");
  valo_options o;
  valo_options_init(&o);
  o.aovs = 1;
  valo_scene *sc;
  valo_render *r = render_file(json, &o, &sc);
  CHECK(r, "render failed");
  float *px = malloc(96 * 64 * 3 * sizeof *px), *depth = malloc(96 * 64 * 3 * sizeof *depth);
  valo_error err;
  valo_render_pixels(r, px);
  CHECK(valo_render_layer(r, "depth", depth, &err) == VALO_OK, "%s", err.message);
  double area[2] = {0, 0}, cx[2] = {0, 0}, cy[2] = {0, 0};
  for (int y = 0; y < 64; y++)
    for (int x = 0; x < 96; x++) {
      double v = px[3 * (y * 96 + x) + 1];
      int k = x >= 48;
      area[k] += v; cx[k] += v * (x + 0.5); cy[k] += v * (y + 0.5);
    }
  double d_near = depth[3 * (32 * 96 + 32)], d_far = depth[3 * (32 * 96 + 64)];
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  free(px); free(depth);
  double want = M_PI * (0.5 * ppu) * (0.5 * ppu);
  for (int k = 0; k < 2; k++) { cx[k] /= area[k]; cy[k] /= area[k]; }
  fprintf(stderr, "orthographic: sphere areas %.1f and %.1f px (predicted %.1f), centres (%.2f, %.2f) and (%.2f, %.2f) "
          "(predicted (32, 32) and (64, 32)), depth %.4f and %.4f (predicted 1.5 and 29.5)\n",
          area[0], area[1], want, cx[0], cy[0], cx[1], cy[1], d_near, d_far);
  for (int k = 0; k < 2; k++) {
    CHECK(fabs(area[k] - want) < 0.02 * want, "sphere %d covers %.1f px, predicted %.1f", k, area[k], want);
    CHECK(fabs(cx[k] - (k ? 64 : 32)) < 0.05 && fabs(cy[k] - 32) < 0.05, "sphere %d centred at (%.2f, %.2f)", k, cx[k], cy[k]);
  }
  CHECK(fabs(d_near - 1.5) < 0.01 && fabs(d_far - 29.5) < 0.01, "depth %.4f and %.4f, predicted 1.5 and 29.5", d_near, d_far);
  /* The lens: a point at depth 4 seen through radius 0.1 focused at 2 (or 4), H = 2. */
  double A = 0.1, predicted = A * fabs(1 - 4.0 / 2.0) * 48, rr[3];
  for (int k = 0; k < 3; k++) {
    char text[1024];
    snprintf(text, sizeof text,
             "{ \"camera\": {\"type\": \"orthographic\", \"height\": 2, \"position\": [0,0,0], \"look_at\": [0,0,-1], "
             "\"aperture_radius\": %g, \"focus_distance\": %g},\n" SPOT_SCENE_TAIL,
             k == 2 ? 0 : A, k == 1 ? 4.0 : 2.0, "", 0.0);
    rr[k] = spot_radius(text, NULL);
  }
  fprintf(stderr, "orthographic spot radius: defocused %.2f px (predicted %.2f), in focus %.2f px, pinhole %.2f px\n", rr[0], predicted, rr[1], rr[2]);
  CHECK(rr[0] > 0 && rr[1] >= 0 && rr[2] >= 0, "render failed");
  CHECK(fabs(rr[0] - predicted) < 0.05 * predicted + 0.5, "defocus radius %.2f px, predicted %.2f", rr[0], predicted);
  CHECK(rr[1] < 1.5 && rr[2] < 1.5, "in focus the spot should stay within a pixel or so (%.2f, %.2f)", rr[1], rr[2]);
  return 0;
}

/* A glTF orthographic camera (xmag 3, ymag 1.5, at z = 5 looking down -z) over a 2 x 2
 * square at z = 0 and its twin at z = -10 behind it: the film takes the camera's aspect
 * (512 x 256) and the square covers a third of its width and two thirds of its height,
 * whatever its distance. camera.from_file takes it; "height" there overrides ymag and
 * "fov" is refused. */
static const char gltf_ortho[] =
    "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0, 1]}],\n"
    " \"nodes\": [{\"camera\": 0, \"translation\": [0, 0, 5], \"name\": \"cam\"}, {\"mesh\": 0}],\n"
    " \"cameras\": [{\"type\": \"orthographic\", \"orthographic\": {\"xmag\": 3, \"ymag\": 1.5, \"znear\": 0.01, \"zfar\": 100}}],\n"
    " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1}]}],\n"
    " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 8, \"type\": \"VEC3\", \"min\": [-1,-1,-10], \"max\": [1,1,0]},\n"
    "                {\"bufferView\": 1, \"componentType\": 5125, \"count\": 12, \"type\": \"SCALAR\"}],\n"
    " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 96}, {\"buffer\": 0, \"byteOffset\": 96, \"byteLength\": 48}],\n"
    " \"buffers\": [{\"byteLength\": 144, \"uri\": \"data:application/octet-stream;base64,"
    "AACAvwAAgL8AAAAAAACAPwAAgL8AAAAAAACAPwAAgD8AAAAAAACAvwAAgD8AAAAAAACAvwAAgL8AACDBAACAPwAAgL8AACDBAACAPwAAgD8AACDBAACAvwAAgD8AACDB"
    "AAAAAAEAAAACAAAAAAAAAAIAAAADAAAABAAAAAUAAAAGAAAABAAAAAYAAAAHAAAA\"}]}\n";
static double ortho_square_share(const char *path, int *w, int *h) {
  valo_options o;
  valo_options_init(&o);
  o.spp = 16;
  valo_scene *sc;
  valo_render *r = render_file(path, &o, &sc);
  if (!r) return -1;
  valo_stats st;
  valo_render_stats(r, &st);
  *w = st.width; *h = st.height;
  float *px = malloc((size_t)st.width * st.height * 3 * sizeof *px);
  valo_render_pixels(r, px);
  long n = 0;
  for (int i = 0; i < st.width * st.height; i++) n += px[3 * i + 1] < 0.9f; /* the square; the white environment is 1 */
  free(px);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  return (double)n / ((double)st.width * st.height);
}
static int orthographic_gltf_camera(void) {
  const char *gltf = scratch_file("ortho_camera.gltf", gltf_ortho);
  CHECK(gltf, "cannot write the glTF file");
  int w, h;
  double share = ortho_square_share(gltf, &w, &h);
  fprintf(stderr, "glTF orthographic camera: film %dx%d, the square covers %.4f of it (predicted %.4f)\n", w, h, share, 2.0 / 9);
  CHECK(w == 512 && h == 256, "film %dx%d, expected the camera's aspect 512x256", w, h);
  CHECK(fabs(share - 2.0 / 9) < 0.01, "the square covers %.4f of the film, predicted 2/9", share);
  /* camera.from_file with height 2.5 on this JSON's 512 x 256 film: a view of 5 x 2.5,
   * of which the square covers 2/5 x 4/5. */
  const char *json = scratch_file("ortho_from_file.json",
      "{ \"camera\": {\"from_file\": true, \"height\": 2.5}, \"film\": {\"width\": 512, \"height\": 256},\n"
      "  \"environment\": {\"type\": \"constant\", \"radiance\": 1}, \"shapes\": [{\"file\": \"ortho_camera.gltf\"}] }\n");
  share = ortho_square_share(json, &w, &h);
  fprintf(stderr, "from_file with height 2.5: the square covers %.4f (predicted %.4f)\n", share, 0.32);
  CHECK(fabs(share - 0.32) < 0.01, "from_file height 2.5: the square covers %.4f, predicted 0.32", share);
  json = scratch_file("ortho_fov.json", "{ \"camera\": {\"from_file\": true, \"fov\": 30}, \"shapes\": [{\"file\": \"ortho_camera.gltf\"}] }\n");
  valo_scene *sc;
  valo_error err;
  CHECK(valo_scene_load(json, &sc, &err) == VALO_ERR_INVALID && strstr(err.message, "camera.fov") && strstr(err.message, "orthographic"),
        "a field of view for an orthographic file camera was taken (%s)", err.message);
  return 0;
}

/* A user's orthographic camera: a scene Blender 3.4 rendered with Cycles and exported as
 * glTF with its own exporter (scripts/blender-ortho-gltf.py: Suzanne, a cube and a sphere
 * under a white world, an orthographic camera of ortho_scale 5 at an oblique angle). valo
 * renders the glTF (lit by its white environment) at Cycles' 160 x 100; where the objects
 * are (pixels darker than the background, 0.97) must agree with Cycles' image: overlap
 * over union at least 0.97 and centroids within 1 pixel. The materials differ (Blender's
 * default surface is not glTF's default), so only the silhouettes are compared. */
static int orthographic_blender_gltf(void) {
  valo_options o;
  valo_options_init(&o);
  o.width = 160;
  o.height = 100;
  o.spp = 16;
  allow_shading_loss(0.03); /* Suzanne's smooth normals on its coarse mesh refuse 1.5 % */
  valo_scene *sc;
  valo_render *r = render_file(VALO_SOURCE_DIR "/tests/data/blender-ortho/scene.gltf", &o, &sc);
  CHECK(r, "render failed");
  float *px = malloc(160 * 100 * 3 * sizeof *px);
  valo_render_pixels(r, px);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  image ref;
  valo_error err;
  CHECK(image_read(VALO_SOURCE_DIR "/tests/data/blender-ortho/cycles.exr", &ref, &err) == VALO_OK && ref.w == 160 && ref.h == 100, "%s", err.message);
  long both = 0, either = 0, n[2] = {0, 0};
  double cx[2] = {0, 0}, cy[2] = {0, 0};
  for (int y = 0; y < 100; y++)
    for (int x = 0; x < 160; x++) {
      int in[2] = {px[3 * (y * 160 + x) + 1] < 0.97f, ref.rgb[3 * (y * 160 + x) + 1] < 0.97f};
      both += in[0] && in[1];
      either += in[0] || in[1];
      for (int k = 0; k < 2; k++)
        if (in[k]) { n[k]++; cx[k] += x; cy[k] += y; }
    }
  free(px);
  image_free(&ref);
  CHECK(n[0] > 1000 && n[1] > 1000, "too few object pixels (%ld, %ld)", n[0], n[1]);
  for (int k = 0; k < 2; k++) { cx[k] /= (double)n[k]; cy[k] /= (double)n[k]; }
  double iou = (double)both / (double)either, dc = hypot(cx[0] - cx[1], cy[0] - cy[1]);
  fprintf(stderr, "Blender's orthographic glTF camera: %ld object pixels in valo, %ld in Cycles, overlap/union %.3f, centroids %.2f px apart\n",
          n[0], n[1], iou, dc);
  CHECK(iou >= 0.97 && dc < 1, "the objects sit elsewhere than in Cycles' image (overlap/union %.3f, centroids %.2f px apart)", iou, dc);
  return 0;
}

/* Pixel filters (film.filter): an orthographic view, one scene unit per pixel, of an
 * emitting half-plane whose edge crosses the film at x = 8.3 pixels. With filter
 * importance sampling a pixel whose centre lies d pixels left of the edge sees the share
 * of the filter beyond d: for the box 1/2 - d/(2r) clipped to [0, 1], for the tent,
 * Mitsuba's windowed Gaussian and Cycles' Blackman-Harris their integrals (the last two by
 * quadrature here, independent of valo's tables), and so Mitchell's and Catmull-Rom's cubics
 * and Lanczos' windowed sinc, whose negative lobes overshoot above 1 and below 0 beside
 * the edge (a sample's negative weight, sign x integral |f| / integral f, is what makes
 * them: |f| alone would give a monotone profile). Every row must show that profile. */
static double filter_share(const char *name, double r, double d) {
  if (d >= r) return 0;
  if (d <= -r) return 1;
  if (!strcmp(name, "box")) return 0.5 - d / (2 * r);
  if (!strcmp(name, "tent")) { double t = 1 - fabs(d) / r; return d > 0 ? 0.5 * t * t : 1 - 0.5 * t * t; }
  double sd = r / 4, a = -1 / (2 * sd * sd), bias = exp(a * r * r), all = 0, part = 0;
  for (int j = 0; j < 20000; j++) {
    double x = -r + (j + 0.5) * 2 * r / 20000, v = 2 * M_PI * (x / (2 * r) + 0.5), t = fabs(2 * x / r), px = M_PI * x;
    double g = !strcmp(name, "gaussian")          ? exp(a * x * x) - bias
               : !strcmp(name, "blackman-harris") ? 0.35875 - 0.48829 * cos(v) + 0.14128 * cos(2 * v) - 0.01168 * cos(3 * v)
               : !strcmp(name, "lanczos")         ? sin(px) / px * sin(px / r) / (px / r)
               : !strcmp(name, "mitchell")        ? (t < 1 ? 7 * t * t * t - 12 * t * t + 16.0 / 3 : -7.0 / 3 * t * t * t + 12 * t * t - 20 * t + 32.0 / 3)
                                                  : (t < 1 ? 1.5 * t * t * t - 2.5 * t * t + 1 : -0.5 * t * t * t + 2.5 * t * t - 4 * t + 2); /* catmull-rom */
    all += g;
    if (x > d) part += g;
  }
  return part / all;
}
/* The edge scene through filter `name` of radius r at spp samples per pixel: 16 x 16 RGB
 * pixels (malloc'd), or NULL. */
static float *edge_render_by(const char *name, double r, int spp, const char *integrator, int *w, int *h) {
  if (!scratch_file("halfplane.obj", "v 0.3 -100 -1\nv 100 -100 -1\nv 100 100 -1\nv 0.3 100 -1\nf 1 2 3 4\n")) return NULL;
  char json[1024];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"type\": \"orthographic\", \"height\": 16, \"position\": [0,0,0], \"look_at\": [0,0,-1]},\n"
           "  \"film\": {\"width\": 16, \"height\": 16, \"filter\": \"%s\", \"filter_radius\": %g}, \"render\": {\"spp\": %d, \"integrator\": \"%s\"},\n"
           "  \"materials\": {\"e\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": 1}},\n"
           "  \"shapes\": [{\"file\": \"halfplane.obj\", \"material\": \"e\"}] }\n", name, r, spp, integrator);
  return render_json_text(json, NULL, w, h);
}
static float *edge_render(const char *name, double r, int spp, int *w, int *h) { return edge_render_by(name, r, spp, "path", w, h); }
static int pixel_filter_edge(void) {
  static const struct { const char *name; double radius; } fs[] = {{"box", 0.5}, {"box", 1.5}, {"tent", 1}, {"gaussian", 2}, {"gaussian", 1.2}, {"blackman-harris", 1.5},
                                                                      {"mitchell", 2}, {"catmull-rom", 2}, {"lanczos", 3}, {"lanczos", 2}};
  for (size_t k = 0; k < sizeof fs / sizeof fs[0]; k++) {
    int w, h;
    float *px = edge_render(fs[k].name, fs[k].radius, k < 6 ? 256 : 16384, &w, &h); /* negative weights: noisier */
    CHECK(px, "%s: render failed", fs[k].name);
    double worst = 0;
    int wx = -1;
    for (int y = 0; y < h; y++)
      for (int x = 0; x < w; x++) {
        double e = fabs(px[3 * (y * w + x) + 1] - filter_share(fs[k].name, fs[k].radius, 8.3 - (x + 0.5)));
        if (e > worst) { worst = e; wx = x; }
      }
    fprintf(stderr, "filter %s radius %g: row 8 ", fs[k].name, fs[k].radius);
    for (int x = 4; x < 13; x++) fprintf(stderr, "%.3f/%.3f ", px[3 * (8 * w + x) + 1], filter_share(fs[k].name, fs[k].radius, 8.3 - (x + 0.5)));
    fprintf(stderr, "(rendered/predicted); worst %.4f at column %d\n", worst, wx);
    free(px);
    CHECK(worst < 0.01, "%s radius %g: a pixel differs from the predicted profile by %.4f (column %d)", fs[k].name, fs[k].radius, worst, wx);
  }
  return 0;
}

/* The edge through each of n filters (names, radii) at spp against the renderer's images
 * of the same filters (tests/data/filters/PREFIX-NAME.exr): worst[k * n + j] is the largest
 * pixel difference of valo's filter k from the reference's filter j. 0, or 1 (said). */
static int edge_against(const char *prefix, const char *const *names, const double *radii, int n, int spp, double *worst) {
  image ref[3];
  valo_error err;
  for (int k = 0; k < n; k++) {
    char path[1024];
    snprintf(path, sizeof path, VALO_SOURCE_DIR "/tests/data/filters/%s-edge-%s.exr", prefix, names[k]);
    CHECK(image_read(path, &ref[k], &err) == VALO_OK && ref[k].w == 16 && ref[k].h == 16, "%s", err.message);
  }
  for (int k = 0; k < n; k++) {
    int w, h;
    float *px = edge_render(names[k], radii[k], spp, &w, &h);
    CHECK(px && w == 16 && h == 16, "%s: render failed", names[k]);
    for (int j = 0; j < n; j++) {
      worst[k * n + j] = 0;
      for (int i = 0; i < 16 * 16 * 3; i++) worst[k * n + j] = fmax(worst[k * n + j], fabs(px[i] - ref[j].rgb[i]));
    }
    free(px);
  }
  for (int k = 0; k < n; k++) image_free(&ref[k]);
  return 0;
}

/* The same edge against Blender Cycles (scripts/cycles-filter-edge.py: Cycles 3.4 at 4096
 * samples through its Blackman-Harris filter of width 1.5 and its box of width 1): valo's
 * blackman-harris and box at their defaults must each be within 0.005 of Cycles' image of
 * the same filter in every pixel, where the two filters differ by 0.027 at the edge. */
static int pixel_filter_cycles(void) {
  static const char *const names[2] = {"blackman-harris", "box"};
  static const double radii[2] = {1.5, 0.5};
  double worst[2][2];
  if (edge_against("cycles", names, radii, 2, 1024, &worst[0][0])) return 1;
  fprintf(stderr, "against Cycles, largest pixel difference: blackman-harris %.4f (against Cycles' box %.4f), box %.4f (against Cycles' "
          "blackman-harris %.4f)\n", worst[0][0], worst[0][1], worst[1][1], worst[1][0]);
  CHECK(worst[0][0] < 0.005 && worst[1][1] < 0.005, "valo's filters differ from Cycles' by %.4f (blackman-harris) and %.4f (box)", worst[0][0], worst[1][1]);
  CHECK(worst[0][1] > 0.02 && worst[1][0] > 0.02, "the two filters' images are too alike to tell them apart (%.4f, %.4f)", worst[0][1], worst[1][0]);
  return 0;
}

/* The same edge against Mitsuba 3 (scripts/mitsuba-filter-edge.py: Mitsuba 3.9.1 at 65 536
 * samples through its mitchell, catmullrom and lanczos filters, splatted and divided by
 * the weights' sum): valo's mitchell, catmull-rom and lanczos at their defaults, sampled in
 * proportion to |filter| with signed weights, must each be within 0.006 of Mitsuba's
 * image of the same filter in every pixel, and more than 0.02 from the next one's (the
 * overshoots beside the edge differ by 0.017 to 0.03). restir-di, whose frames take the
 * same camera samples, gives path's image bit for bit. */
static int pixel_filter_mitsuba(void) {
  static const char *const names[3] = {"mitchell", "catmull-rom", "lanczos"};
  static const double radii[3] = {2, 2, 3}; /* the defaults */
  double worst[3][3];
  if (edge_against("mitsuba", names, radii, 3, 16384, &worst[0][0])) return 1;
  /* ReSTIR's frames take the same camera samples and their weights: the same image */
  int w, h;
  float *a = edge_render("lanczos", 3, 64, &w, &h), *b = edge_render_by("lanczos", 3, 64, "restir-di", &w, &h);
  CHECK(a && b && !memcmp(a, b, 16 * 16 * 3 * sizeof(float)), "restir-di's image through lanczos differs from path's");
  free(a);
  free(b);
  int rc = 0;
  for (int k = 0; k < 3; k++) {
    int o = (k + 1) % 3;
    fprintf(stderr, "against Mitsuba, largest pixel difference: %s %.4f (against Mitsuba's %s %.4f)\n", names[k], worst[k][k], names[o], worst[k][o]);
    if (!(worst[k][k] < 0.006 && worst[k][o] > 0.02)) {
      fprintf(stderr, "check failed: %s differs from Mitsuba's by %.4f, from its %s by %.4f\n", names[k], worst[k][k], names[o], worst[k][o]);
      rc = 1;
    }
  }
  return rc;
}

/* Adaptive sampling on the albedo-0.5 furnace (64x64): the budget is used exactly,
 * background pixels (zero variance, away from the sphere: the rule looks at 17x17
 * neighbourhoods) get no more than the first pass (half the budget), sphere pixels get
 * more, the image still shows 0.5 and 1, progress follows the samples taken, and a
 * loose noise threshold stops after the first pass. */
/* Progress of an adaptive render with a sample budget: the largest gap between the
 * reported fraction and the share of the budget's samples taken. */
typedef struct progress_gap { double worst; int calls; } progress_gap;
static int adaptive_progress(void *user, double frac, int spp_done, double seconds) {
  progress_gap *g = user;
  (void)seconds;
  double d = fabs(frac - spp_done / 64.0);
  if (d > g->worst) g->worst = d;
  g->calls++;
  return 0;
}

static int adaptive_sampling(void) {
  enum { N = 64 };
  char json[2048];
  snprintf(json, sizeof json, furnace_fmt, 64, 0.5);
  const char *path = scratch_file("adaptive.json", json);
  for (int pass = 0; pass < 2; pass++) {
    valo_options o;
    valo_options_init(&o);
    o.adaptive = 1;
    o.width = o.height = N;
    if (pass == 1) o.noise_threshold = 10;
    valo_error err;
    valo_scene *sc;
    valo_render *r;
    CHECK(valo_scene_load(path, &sc, &err) == VALO_OK, "%s", err.message);
    CHECK(valo_render_create(sc, &o, &r, &err) == VALO_OK, "%s", err.message);
    progress_gap gap = {0, 0};
    CHECK(valo_render_run(r, adaptive_progress, &gap, &err) == VALO_OK, "%s", err.message);
    CHECK(!check_losses(r), "samples lost");
    /* the bar moves with the samples through both phases (it once showed a quarter at the
     * end of a first pass of half the samples) */
    CHECK(gap.calls > 2 && gap.worst < 0.03, "progress strays %.3f from the samples taken (%d reports)", gap.worst, gap.calls);
    char mp[1200], out[1300];
    snprintf(mp, sizeof mp, "%s/spp%d.pfm", scratch_dir(), pass);
    snprintf(out, sizeof out, "spp:%s", mp);
    CHECK(valo_render_write(r, out, NULL, &err) == VALO_OK, "%s", err.message);
    float *px = malloc(sizeof(float) * N * N * 3);
    valo_render_pixels(r, px);
    image cnt;
    CHECK(image_read(mp, &cnt, &err) == VALO_OK, "%s", err.message);
    double total = 0, sum[2] = {0, 0}, nsum[2] = {0, 0};
    int n[2] = {0, 0};
    float bg_max = 0;
    for (int y = 0; y < N; y++)
      for (int x = 0; x < N; x++) {
        float c = cnt.rgb[3 * (y * N + x)];
        total += c;
        int k = classify_n(x, y, N);
        if (k < 0) continue;
        n[k]++;
        nsum[k] += c;
        sum[k] += (px[3 * (y * N + x)] + px[3 * (y * N + x) + 1] + px[3 * (y * N + x) + 2]) / 3;
        int interior = 1; /* background with only background around (the rule looks at 17x17) */
        for (int dy = -8; dy <= 8; dy++)
          for (int dx = -8; dx <= 8; dx++) {
            int xx = x + dx, yy = y + dy;
            if (xx >= 0 && yy >= 0 && xx < N && yy < N && classify_n(xx, yy, N) != 0) interior = 0;
          }
        if (k == 0 && interior && c > bg_max) bg_max = c;
      }
    image_free(&cnt);
    free(px);
    valo_render_destroy(r);
    valo_scene_destroy(sc);
    fprintf(stderr, "%s: %.0f samples (budget %d), background max %.0f per pixel, sphere mean %.1f; sphere %.4f, background %.4f\n",
            pass ? "threshold 10" : "budget", total, 64 * N * N, bg_max, nsum[1] / n[1], sum[1] / n[1], sum[0] / n[0]);
    if (pass == 0) {
      CHECK(total == 64 * N * N, "used %.0f samples of a budget of %d", total, 64 * N * N);
      CHECK(bg_max == 32, "zero-variance background pixels got %.0f samples, expected only the first pass's 32", bg_max);
      CHECK(nsum[1] / n[1] > 64, "sphere pixels average %.1f samples, expected more than the mean 64", nsum[1] / n[1]);
      CHECK(fabs(sum[1] / n[1] - 0.5) < 0.01, "sphere mean %g", sum[1] / n[1]);
    } else {
      CHECK(total == 32 * N * N, "a threshold every pixel meets should stop after the first pass (%.0f samples)", total);
    }
    CHECK(fabs(sum[0] / n[0] - 1) < 1e-5, "background %g", sum[0] / n[0]);
  }
  return 0;
}

/* Automatic framing: a mesh file without a camera is framed tightly from the
 * front: the open Cornell box fills the frame (before: two thirds of it); with --up z a
 * z-up scan (nefertiti) stands upright, so what it covers is taller than wide. */
static int frame_coverage(const char *path, const char *up, int w, int h, double *cover, int *bw, int *bh) {
  valo_load_options lo;
  valo_load_options_init(&lo);
  snprintf(lo.up, sizeof lo.up, "%s", up);
  valo_error err;
  valo_scene *sc;
  if (valo_scene_load_with(path, &lo, &sc, &err)) { fprintf(stderr, "%s\n", err.message); return -1; }
  valo_options o;
  valo_options_init(&o);
  o.aovs = 1; o.spp = 1; o.width = w; o.height = h;
  valo_render *r;
  if (valo_render_create(sc, &o, &r, &err) || valo_render_run(r, NULL, NULL, &err)) { fprintf(stderr, "%s\n", err.message); return -1; }
  if (check_losses(r)) return -1;
  image d;
  if (read_aov(r, "depth", &d)) return -1;
  int n = 0, x0 = w, x1 = -1, y0 = h, y1 = -1;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      if (d.rgb[3 * (y * w + x)] > 0) {
        n++;
        x0 = x < x0 ? x : x0; x1 = x > x1 ? x : x1; y0 = y < y0 ? y : y0; y1 = y > y1 ? y : y1;
      }
  *cover = (double)n / (w * h);
  *bw = x1 - x0 + 1; *bh = y1 - y0 + 1;
  image_free(&d);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  return 0;
}
static int auto_framing(void) {
  const char *box = shared_file("scenes/cornell/CornellBox-Original.obj"), *nef = shared_file("scenes/models/nefertiti.obj");
  if (!box || !nef) return TEST_SKIP;
  double c;
  int bw, bh;
  CHECK(frame_coverage(box, "y", 64, 64, &c, &bw, &bh) == 0, "render failed");
  fprintf(stderr, "Cornell box, auto-framed 64x64: %.1f %% of the pixels see it (%dx%d)\n", 100 * c, bw, bh);
  CHECK(c > 0.9, "the box covers only %.1f %% of the frame", 100 * c);
  CHECK(frame_coverage(box, "y", 96, 48, &c, &bw, &bh) == 0, "render failed");
  fprintf(stderr, "Cornell box, auto-framed 96x48: covers %dx%d\n", bw, bh);
  CHECK(bh >= 46 && bw < 96, "a wide film: the box should fill the height (%dx%d)", bw, bh);
  CHECK(frame_coverage(nef, "z", 64, 64, &c, &bw, &bh) == 0, "render failed");
  fprintf(stderr, "nefertiti --up z: covers %dx%d\n", bw, bh);
  CHECK(bh >= 50 && bh > 1.5 * bw, "nefertiti is not upright and tightly framed (%dx%d)", bw, bh);
  return 0;
}

/* Emitting spheres sampled by their cones (light.h, light_sphere_at) against the same
 * spheres sampled triangle by triangle: the same means (both unbiased), in the grid's and
 * the power sampler's selection, with a blocker half across one lamp and a rough metal
 * plate (the MIS weights of BSDF-sampled hits); and less noise. */
static int sphere_light_cone(void) {
  const char *json =
      "{ \"camera\": {\"position\": [0, 3.2, 3.2], \"look_at\": [0, 0, 0], \"fov\": 45},\n"
      "  \"film\": {\"width\": 48, \"height\": 48},\n"
      "  \"materials\": {\"floor\": {\"type\": \"diffuse\", \"reflectance\": 0.5},\n"
      "    \"metal\": {\"type\": \"conductor\", \"preset\": \"Cu\", \"roughness\": 0.3},\n"
      "    \"big\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": 4},\n"
      "    \"small\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": 300}},\n"
      "  \"shapes\": [{\"type\": \"rectangle\", \"transform\": {\"rotate_x\": -90, \"scale\": 3}, \"material\": \"floor\"},\n"
      "    {\"type\": \"rectangle\", \"transform\": {\"rotate_x\": -60, \"scale\": 0.6, \"translate\": [0.9, 0.4, 0.6]}, \"material\": \"metal\"},\n"
      "    {\"type\": \"cube\", \"transform\": {\"scale\": [0.6, 0.02, 0.6], \"translate\": [-0.9, 0.9, 0.5]}, \"material\": \"floor\"},\n"
      "    {\"type\": \"sphere\", \"center\": [-0.6, 1.3, 0], \"radius\": 0.35, \"subdivisions\": 3, \"material\": \"big\"},\n"
      "    {\"type\": \"sphere\", \"center\": [0.7, 1.6, -0.4], \"radius\": 0.05, \"subdivisions\": 2, \"material\": \"small\"}] }\n";
  const int spp = test_full() ? 4096 : 1024;
  for (int power = 0; power < 2; power++) {
    float *img[2][2];
    int w = 0, h = 0;
    for (int mode = 0; mode < 2; mode++)
      for (int k = 0; k < 2; k++) {
        valo_options o;
        valo_options_init(&o);
        o.spp = spp;
        o.seed = 11 + 2 * k + 7 * power;
        snprintf(o.sphere_lights, sizeof o.sphere_lights, "%s", mode ? "triangles" : "cone");
        snprintf(o.light_sampler, sizeof o.light_sampler, "%s", power ? "power" : "grid");
        img[mode][k] = render_json_text(json, &o, &w, &h);
        CHECK(img[mode][k], "render failed");
      }
    /* Means of the two seeds together; noise from the two seeds' difference. */
    double mean[2] = {0, 0}, var[2] = {0, 0}, blk_worst = 0;
    enum { B = 12 };
    for (int mode = 0; mode < 2; mode++)
      for (int i = 0; i < w * h * 3; i++) {
        double a = img[mode][0][i], b = img[mode][1][i];
        mean[mode] += (a + b) / 2;
        /* the noise of lit surfaces: the lamps' own pixels only measure antialiasing */
        if (img[0][0][i] < 3 && img[0][1][i] < 3 && img[1][0][i] < 3 && img[1][1][i] < 3) var[mode] += (a - b) * (a - b) / 2;
      }
    for (int by = 0; by < h / B; by++)
      for (int bx = 0; bx < w / B; bx++) {
        double m[2] = {0, 0};
        for (int mode = 0; mode < 2; mode++)
          for (int y = by * B; y < (by + 1) * B; y++)
            for (int x = bx * B; x < (bx + 1) * B; x++)
              for (int c = 0; c < 3; c++) m[mode] += img[mode][0][3 * (y * w + x) + c] + img[mode][1][3 * (y * w + x) + c];
        double d = fabs(m[0] - m[1]) / fmax(m[1], 1e-9);
        if (d > blk_worst) blk_worst = d;
      }
    for (int mode = 0; mode < 2; mode++)
      for (int k = 0; k < 2; k++) free(img[mode][k]);
    double rel = fabs(mean[0] - mean[1]) / mean[1];
    fprintf(stderr, "%s sampler, %d spp x 2: cone mean %.5f, triangles %.5f (%.3f %%); worst %dx%d block %.2f %%; variance cone / triangles %.3f\n",
            power ? "power" : "grid", spp, mean[0] / (w * h * 3), mean[1] / (w * h * 3), 100 * rel, B, B, 100 * blk_worst, var[0] / var[1]);
    CHECK(rel < 0.003, "the means differ by %.3f %%", 100 * rel);
    CHECK(blk_worst < 0.02, "a block differs by %.2f %%", 100 * blk_worst);
    CHECK(var[0] < 0.8 * var[1], "cone sampling is not less noisy (variance ratio %.3f)", var[0] / var[1]);
  }
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"furnace_albedo_1", furnace_albedo_1}, {"sphere_light_cone", sphere_light_cone},
                                    {"furnace_albedo_half", furnace_albedo_half},
                                    {"closed_sphere_point_light", closed_sphere_point_light},
                                    {"closed_sphere_emissive", closed_sphere_emissive},
                                    {"emission_front_side_only", emission_front_side_only},
                                    {"max_depth_direct_only", max_depth_direct_only},
                                    {"furnace_constant_map", furnace_constant_map},
                                    {"envmap_orientation", envmap_orientation}, {"envmap_cube", envmap_cube}, {"envmap_irradiance", envmap_irradiance},
                                    {"aovs", aovs},
                                    {"thin_lens_circle_of_confusion", thin_lens_circle_of_confusion},
                                    {"thin_lens_gltf_camera", thin_lens_gltf_camera},
                                    {"orthographic_camera", orthographic_camera}, {"orthographic_gltf_camera", orthographic_gltf_camera},
                                    {"orthographic_blender_gltf", orthographic_blender_gltf},
                                    {"pixel_filter_edge", pixel_filter_edge}, {"pixel_filter_cycles", pixel_filter_cycles},
                                    {"pixel_filter_mitsuba", pixel_filter_mitsuba},
                                    {"spherical_camera", spherical_camera}, {"thin_lens_restir", thin_lens_restir},
                                    {"adaptive_sampling", adaptive_sampling}, {"adaptive_unbiased", adaptive_unbiased},
                                    {"adaptive_pays_caustic", adaptive_pays_caustic}, {"auto_framing", auto_framing},
                                    {NULL, NULL}};
  return test_main(argc, argv, cases);
}
