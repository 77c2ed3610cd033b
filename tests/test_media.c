/* test_media.c — participating media and null surfaces against analytic results: a
 * white furnace of a scattering medium (from outside its null boundary and with the
 * camera inside), Beer-Lambert transmittance through an absorbing sphere pixel by pixel,
 * null surfaces that change nothing (AOVs see through them), and the integrators that
 * refuse media. Mitsuba 3's
 * volpath is the independent reference in test_mitsuba (smoke_ball, absorbing_glass);
 * the sampling routines are in test_chi2 (hg_phase, free_flight). */
#include "harness.h"
#include "valo/valo.h"
#include "image/image_io.h"
#include "scene/volume.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A null sphere of radius 1 filled with `medium` (JSON), in a uniform environment of
 * radiance 1, seen by `camera` (JSON). */
static float *media_render(const char *camera, const char *medium, int spp, int res, const valo_options *opt) {
  char json[2048];
  snprintf(json, sizeof json,
           "{ \"camera\": %s,\n"
           "  \"film\": {\"width\": %d, \"height\": %d}, \"render\": {\"spp\": %d, \"seed\": 3},\n"
           "  \"media\": {\"m\": %s},\n"
           "  \"materials\": {\"edge\": {\"type\": \"null\"}},\n"
           "  \"shapes\": [{\"type\": \"sphere\", \"radius\": 1, \"subdivisions\": 5, \"material\": \"edge\", \"interior\": \"m\"}],\n"
           "  \"environment\": {\"type\": \"constant\", \"radiance\": 1} }\n",
           camera, res, res, spp, medium);
  int w, h;
  return render_json_text(json, opt, &w, &h);
}

/* Every channel's mean over the image must be 1 within 5 standard errors (estimated
 * from the pixels' spread: chromatic media give heavy-tailed pixels) plus 0.2 %. */
static int furnace_check(const char *what, const float *px, int n) {
  CHECK(px, "%s: render failed", what);
  double sum[3] = {0}, sum2[3] = {0};
  for (int i = 0; i < n; i++)
    for (int c = 0; c < 3; c++) {
      CHECK(isfinite(px[3 * i + c]) && px[3 * i + c] >= 0, "%s: pixel %d not finite", what, i);
      sum[c] += px[3 * i + c];
      sum2[c] += (double)px[3 * i + c] * px[3 * i + c];
    }
  for (int c = 0; c < 3; c++) {
    double m = sum[c] / n, se = sqrt(fmax(0, sum2[c] / n - m * m) / n);
    fprintf(stderr, "%s: channel %d mean %.5f (expect 1, standard error %.5f)\n", what, c, m, se);
    CHECK(fabs(m - 1) < 5 * se + 0.002, "%s: channel %d mean %g, not 1", what, c, m);
  }
  return 0;
}

/* Albedo 1, chromatic sigma_s, forward and backward lobes: the medium neither adds nor
 * removes light, so every pixel is 1 in expectation, whether the camera looks at the
 * sphere from outside or sits inside the medium (camera.medium). The channels scatter
 * at different rates, so this holds only if picking a channel for free-flight sampling
 * is weighted right (medium.h). */
static int medium_furnace(void) {
  static const char *const media[] = {"{\"type\": \"homogeneous\", \"sigma_a\": 0, \"sigma_s\": [1, 2, 4], \"g\": 0.7}",
                                      "{\"type\": \"homogeneous\", \"sigma_a\": 0, \"sigma_s\": [3, 1, 0.5], \"g\": -0.4}"};
  int spp = test_full() ? 1024 : 256;
  for (int k = 0; k < 2; k++) {
    float *px = media_render("{\"position\": [0, 0, 3.2], \"look_at\": [0, 0, 0], \"fov\": 45}", media[k], spp, 32, NULL);
    int rc = furnace_check(k ? "furnace, backward lobe, from outside" : "furnace, forward lobe, from outside", px, 32 * 32);
    free(px);
    if (rc) return rc;
  }
  float *px = media_render("{\"position\": [0, 0, 0.2], \"look_at\": [0, 0, -1], \"fov\": 90, \"medium\": \"m\"}", media[0], spp, 32, NULL);
  int rc = furnace_check("furnace, camera inside the medium", px, 32 * 32);
  free(px);
  return rc;
}

/* A purely absorbing sphere of radius 1 seen by an orthographic camera against the
 * environment: each pixel is exp(-sigma_a * chord), the chord 2 sqrt(1 - r^2) at the
 * pixel's distance r from the axis (the icosphere's facets lie within 2e-4 of the
 * sphere). The film is box-filtered, so a pixel averages the chord over its square;
 * pixels are compared where that average and the centre's value agree to 0.1 %. */
static int beer_lambert(void) {
  const int res = 48, spp = test_full() ? 1024 : 256;
  const double sa[3] = {0.25, 0.8, 2.0}, half = 1.2; /* view height 2.4 */
  char medium[256];
  snprintf(medium, sizeof medium, "{\"type\": \"homogeneous\", \"sigma_a\": [%g, %g, %g], \"sigma_s\": 0}", sa[0], sa[1], sa[2]);
  float *px = media_render("{\"type\": \"orthographic\", \"height\": 2.4, \"position\": [0, 0, 3], \"look_at\": [0, 0, 0]}", medium, spp, res, NULL);
  CHECK(px, "render failed");
  double worst = 0, sum_err[3] = {0};
  int n = 0;
  for (int y = 0; y < res; y++)
    for (int x = 0; x < res; x++) {
      double want[3] = {0}, centre[3];
      for (int sy = 0; sy < 8; sy++)
        for (int sx = 0; sx < 8; sx++) {
          double u = (x + (sx + 0.5) / 8) / res * 2 * half - half, v = (y + (sy + 0.5) / 8) / res * 2 * half - half;
          double r2 = u * u + v * v, chord = r2 < 1 ? 2 * sqrt(1 - r2) : 0;
          for (int c = 0; c < 3; c++) want[c] += exp(-sa[c] * chord) / 64;
        }
      double u = (x + 0.5) / res * 2 * half - half, v = (y + 0.5) / res * 2 * half - half, r2 = u * u + v * v;
      for (int c = 0; c < 3; c++) centre[c] = exp(-sa[c] * (r2 < 1 ? 2 * sqrt(1 - r2) : 0));
      int smooth = r2 < 0.8 || r2 > 1.2;
      for (int c = 0; c < 3; c++) smooth &= fabs(centre[c] - want[c]) < 1e-3 * want[c];
      if (!smooth) continue;
      n++;
      for (int c = 0; c < 3; c++) {
        double e = (px[3 * (y * res + x) + c] - want[c]) / want[c];
        sum_err[c] += e;
        if (fabs(e) > worst) worst = fabs(e);
      }
    }
  free(px);
  fprintf(stderr, "beer-lambert: %d pixels, mean relative error %.4f %.4f %.4f, worst pixel %.3f\n", n, sum_err[0] / n, sum_err[1] / n,
          sum_err[2] / n, worst);
  CHECK(n > res * res / 4, "only %d pixels compared", n);
  for (int c = 0; c < 3; c++) CHECK(fabs(sum_err[c] / n) < 0.01, "channel %d: mean error %.4f", c, sum_err[c] / n);
  /* each sample passes (weight Tr / mean Tr) or is absorbed (0): a pixel's noise is
   * that of a coin, largest in the densest channel */
  CHECK(worst < (test_full() ? 0.25 : 0.5), "worst pixel off by %.3f", worst);
  return 0;
}

/* Writes a .vol density grid (Mitsuba's format, float32) of n^3 values f(x, y, z) at the
 * texel centres of the box [-h, h]^3 into the scratch folder, beside the scenes; returns
 * its name, or NULL. */
static const char *write_vol(const char *name, int n, float h, float (*f)(float, float, float)) {
  char path[1200];
  snprintf(path, sizeof path, "%s/%s", scratch_dir(), name);
  FILE *fp = fopen(path, "wb");
  if (!fp) return NULL;
  int32_t head[5] = {1, n, n, n, 1};
  float box[6] = {-h, -h, -h, h, h, h};
  fwrite("VOL\3", 1, 4, fp);
  fwrite(head, 4, 5, fp);
  fwrite(box, 4, 6, fp);
  for (int z = 0; z < n; z++)
    for (int y = 0; y < n; y++)
      for (int x = 0; x < n; x++) {
        float v = f(-h + 2 * h * (x + 0.5f) / n, -h + 2 * h * (y + 0.5f) / n, -h + 2 * h * (z + 0.5f) / n);
        fwrite(&v, 4, 1, fp);
      }
  fclose(fp);
  return name;
}
static float ramp_x(float x, float y, float z) { (void)y; (void)z; return 1.0f + 0.6f * x; }
static float blobs(float x, float y, float z) {
  float a = (x - 0.3f) * (x - 0.3f) + y * y + z * z, b = (x + 0.4f) * (x + 0.4f) + (y - 0.3f) * (y - 0.3f) + (z + 0.2f) * (z + 0.2f);
  return 3 * expf(-a / 0.08f) + 1.5f * expf(-b / 0.15f) + 0.2f;
}

/* A grid medium: the furnace again (albedo 1, chromatic sigma_s, a density of two blobs:
 * spectral tracking must keep every channel's mean at 1), and Beer-Lambert through a
 * density ramp d = 1 + 0.6 x (linear between texel centres, so exact): each pixel is
 * exp(-sigma_a (1 + 0.6 x) chord) (ratio tracking's transmittance, and tracking's
 * passes, unbiased). */
static int grid_medium(void) {
  const char *vol = write_vol("blobs.vol", 24, 1.2f, blobs);
  CHECK(vol, "cannot write the grid");
  char medium[1600];
  snprintf(medium, sizeof medium, "{\"type\": \"grid\", \"file\": \"%s\", \"sigma_a\": 0, \"sigma_s\": [1, 2, 3.5], \"g\": 0.5}", vol);
  int spp = test_full() ? 1024 : 256;
  float *px = media_render("{\"position\": [0, 0, 3.2], \"look_at\": [0, 0, 0], \"fov\": 45}", medium, spp, 32, NULL);
  int rc = furnace_check("grid furnace", px, 32 * 32);
  free(px);
  if (rc) return rc;
  vol = write_vol("ramp.vol", 24, 1.2f, ramp_x);
  CHECK(vol, "cannot write the grid");
  const double sa[3] = {0.2, 0.5, 1.2}, half = 1.2;
  snprintf(medium, sizeof medium, "{\"type\": \"grid\", \"file\": \"%s\", \"sigma_a\": [%g, %g, %g], \"sigma_s\": 0}", vol, sa[0], sa[1], sa[2]);
  const int res = 32;
  px = media_render("{\"type\": \"orthographic\", \"height\": 2.4, \"position\": [0, 0, 3], \"look_at\": [0, 0, 0]}", medium, spp, res, NULL);
  CHECK(px, "render failed");
  double sum_err[3] = {0};
  int n = 0;
  for (int y = 0; y < res; y++)
    for (int x = 0; x < res; x++) {
      double want[3] = {0};
      for (int sy = 0; sy < 8; sy++)
        for (int sx = 0; sx < 8; sx++) {
          double u = (x + (sx + 0.5) / 8) / res * 2 * half - half, v = half - (y + (sy + 0.5) / 8) / res * 2 * half;
          double r2 = u * u + v * v, chord = r2 < 1 ? 2 * sqrt(1 - r2) : 0;
          for (int c = 0; c < 3; c++) want[c] += exp(-sa[c] * (1 + 0.6 * u) * chord) / 64;
        }
      double u = (x + 0.5) / res * 2 * half - half, v = half - (y + 0.5) / res * 2 * half, r2 = u * u + v * v;
      if (!(r2 < 0.8 || r2 > 1.2)) continue; /* the silhouette's pixels: facets */
      n++;
      for (int c = 0; c < 3; c++) sum_err[c] += (px[3 * (y * res + x) + c] - want[c]) / want[c];
    }
  free(px);
  fprintf(stderr, "grid beer-lambert: %d pixels, mean relative error %.4f %.4f %.4f\n", n, sum_err[0] / n, sum_err[1] / n, sum_err[2] / n);
  for (int c = 0; c < 3; c++) CHECK(fabs(sum_err[c] / n) < 0.01, "channel %d: mean error %.4f", c, sum_err[c] / n);
  return 0;
}

/* The .vol reader and the lookup: a 4 x 3 x 2 grid of v = x + 10 y + 100 z (texel
 * indices) in the box [0, 4] x [0, 3] x [0, 2], so texel (i, j, k) is centred at
 * (i + 0.5, j + 0.5, k + 0.5): exact at the centres, linear between them, the edge
 * texel's value within half a texel of the box's face, 0 outside; uint8 values / 255. */
static int grid_lookup(void) {
  for (int enc = 1; enc <= 3; enc += 2) {
    char path[1200];
    snprintf(path, sizeof path, "%s/lookup%d.vol", scratch_dir(), enc);
    FILE *f = fopen(path, "wb");
    CHECK(f, "write");
    int32_t head[5] = {enc, 4, 3, 2, 1};
    float box[6] = {0, 0, 0, 4, 3, 2};
    fwrite("VOL\3", 1, 4, f);
    fwrite(head, 4, 5, f);
    fwrite(box, 4, 6, f);
    for (int k = 0; k < 2; k++)
      for (int j = 0; j < 3; j++)
        for (int i = 0; i < 4; i++) {
          float v = (float)(i + 10 * j + 100 * k);
          unsigned char b = (unsigned char)v;
          if (enc == 1) fwrite(&v, 4, 1, f);
          else fwrite(&b, 1, 1, f);
        }
    fclose(f);
    density_grid *g;
    valo_error err;
    CHECK(density_grid_load(path, &g, &err) == VALO_OK, "%s", err.message);
    float unit = enc == 1 ? 1 : 1 / 255.0f;
    CHECK(fabsf(g->dmax - 123 * unit) < 1e-6f, "largest density %g", (double)g->dmax);
    struct { vec3 p; float want; } at[] = {
        {{0.5f, 0.5f, 0.5f}, 0}, {{3.5f, 2.5f, 1.5f}, 123}, {{1.5f, 0.5f, 0.5f}, 1},              /* centres */
        {{1.0f, 0.5f, 0.5f}, 0.5f}, {{2.0f, 1.0f, 1.0f}, 1.5f + 5 + 50}, {{1.25f, 2.0f, 0.75f}, 0.75f + 15 + 25}, /* between */
        {{0.1f, 0.2f, 0.3f}, 0}, {{3.9f, 2.9f, 1.9f}, 123},                                     /* edge texels */
        {{-0.01f, 1, 1}, -1}, {{4.01f, 1, 1}, -1}, {{1, 1, 2.5f}, -1}};                          /* outside: 0 */
    for (size_t q = 0; q < sizeof at / sizeof at[0]; q++) {
      float got = density_grid_at(g, at[q].p), want = at[q].want < 0 ? 0 : at[q].want * unit;
      CHECK(fabsf(got - want) < 1e-4f * (1 + want), "encoding %d: density at (%g, %g, %g) is %g, want %g", enc, (double)at[q].p.x,
            (double)at[q].p.y, (double)at[q].p.z, (double)got, (double)want);
    }
    density_grid_free(g);
  }
  return 0;
}

static float one(float x, float y, float z) { (void)x; (void)y; (void)z; return 1; }
/* Emission (the source term sigma_a Le): an absorbing sphere that glows, seen by the
 * orthographic camera against a black environment, is Le (1 - exp(-sigma_a chord)) in
 * each pixel; homogeneous, and as a grid of density 1 (tracking's emission estimate), and
 * a scattering one whose albedo is 0.5 in a medium of the same sigma_a stays below that
 * value for the absorption alone with the same emission (scattering moves light, it
 * does not add any). */
static int medium_emission(void) {
  const int res = 32, spp = test_full() ? 1024 : 256;
  const double sa[3] = {0.3, 1.0, 2.5}, Le[3] = {2, 1, 0.5}, half = 1.2;
  const char *vol = write_vol("one.vol", 4, 1.2f, one);
  CHECK(vol, "cannot write the grid");
  for (int grid = 0; grid < 2; grid++) {
    char medium[1200], json[2048];
    snprintf(medium, sizeof medium, "{\"type\": \"%s\", %s%s%s\"sigma_a\": [%g, %g, %g], \"sigma_s\": 0, \"emission\": [%g, %g, %g]}",
             grid ? "grid" : "homogeneous", grid ? "\"file\": \"" : "", grid ? vol : "", grid ? "\", " : "", sa[0], sa[1], sa[2], Le[0], Le[1], Le[2]);
    snprintf(json, sizeof json,
             "{ \"camera\": {\"type\": \"orthographic\", \"height\": 2.4, \"position\": [0, 0, 3], \"look_at\": [0, 0, 0]},\n"
             "  \"film\": {\"width\": %d, \"height\": %d}, \"render\": {\"spp\": %d, \"seed\": 3},\n"
             "  \"media\": {\"m\": %s}, \"materials\": {\"edge\": {\"type\": \"null\"}},\n"
             "  \"shapes\": [{\"type\": \"sphere\", \"radius\": 1, \"subdivisions\": 5, \"material\": \"edge\", \"interior\": \"m\"}] }\n",
             res, res, spp, medium);
    int w, h;
    float *px = render_json_text(json, NULL, &w, &h);
    CHECK(px, "render failed");
    double sum_err[3] = {0};
    int n = 0;
    for (int y = 0; y < res; y++)
      for (int x = 0; x < res; x++) {
        double u = (x + 0.5) / res * 2 * half - half, v = half - (y + 0.5) / res * 2 * half, r2 = u * u + v * v;
        if (!(r2 < 0.8)) continue; /* inside the silhouette, away from its facets */
        double want[3] = {0};
        for (int sy = 0; sy < 8; sy++)
          for (int sx = 0; sx < 8; sx++) {
            double uu = (x + (sx + 0.5) / 8) / res * 2 * half - half, vv = half - (y + (sy + 0.5) / 8) / res * 2 * half;
            double chord = 2 * sqrt(fmax(0, 1 - uu * uu - vv * vv));
            for (int c = 0; c < 3; c++) want[c] += Le[c] * (1 - exp(-sa[c] * chord)) / 64;
          }
        n++;
        for (int c = 0; c < 3; c++) sum_err[c] += (px[3 * (y * res + x) + c] - want[c]) / want[c];
      }
    free(px);
    fprintf(stderr, "emission (%s): %d pixels, mean relative error %.4f %.4f %.4f\n", grid ? "grid" : "homogeneous", n, sum_err[0] / n, sum_err[1] / n,
            sum_err[2] / n);
    for (int c = 0; c < 3; c++) CHECK(fabs(sum_err[c] / n) < 0.01, "%s: channel %d mean error %.4f", grid ? "grid" : "homogeneous", c, sum_err[c] / n);
  }
  return 0;
}

/* A null sphere that bounds no medium is not there: the Cornell-like scene with and
 * without one around the diffuse ball agrees within its noise (the null scene goes
 * through the media walk, the other through path's own). */
static int null_surface_invisible(void) {
  const char *fmt = "{ \"camera\": {\"position\": [0, 1, 4], \"look_at\": [0, 0.5, 0], \"fov\": 40},\n"
                    "  \"film\": {\"width\": 32, \"height\": 32}, \"render\": {\"spp\": %d, \"seed\": 4},\n"
                    "  \"materials\": {\"ball\": {\"type\": \"diffuse\", \"reflectance\": 0.6}, \"edge\": {\"type\": \"null\"},\n"
                    "                 \"lamp\": {\"type\": \"diffuse\", \"reflectance\": 0, \"emission\": 10}},\n"
                    "  \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0.5, 0], \"radius\": 0.5, \"material\": \"ball\"},\n"
                    "             {\"type\": \"sphere\", \"center\": [0.5, 2.5, 0], \"radius\": 0.3, \"material\": \"lamp\"}%s],\n"
                    "  \"environment\": {\"type\": \"constant\", \"radiance\": 0.2} }\n";
  char a[2048], b[2048];
  int spp = test_full() ? 1024 : 256, w, h;
  snprintf(a, sizeof a, fmt, spp, "");
  snprintf(b, sizeof b, fmt, spp, ", {\"type\": \"sphere\", \"center\": [0, 0.5, 0], \"radius\": 0.8, \"material\": \"edge\"}");
  float *pa = render_json_text(a, NULL, &w, &h), *pb = render_json_text(b, NULL, &w, &h);
  CHECK(pa && pb, "render failed");
  cmp_result cr;
  compare_images(pb, pa, w, h, 8, &cr);
  free(pa);
  free(pb);
  fprintf(stderr, "null sphere: mean differences %.3f%% %.3f%% %.3f%%, worst 8x8 block %.2f%%\n", 100 * cr.mean_err[0], 100 * cr.mean_err[1],
          100 * cr.mean_err[2], 100 * cr.worst_block);
  for (int c = 0; c < 3; c++) CHECK(cr.mean_err[c] < 0.01, "channel %d differs by %.2f%%", c, 100 * cr.mean_err[c]);
  CHECK(cr.worst_block < 0.05, "a block differs by %.2f%%", 100 * cr.worst_block);
  return 0;
}

/* AOVs describe the first surface that is not null: a plane seen through a smoke-filled
 * null sphere has the plane's albedo, normal and depth (3) at the centre, and its ao is
 * 1 though the sphere hangs 0.7 above it within the ao rays' length (3). */
static int aovs_through_null(void) {
  CHECK(scratch_file("media_plane.obj", "v -5 -5 0\nv -5 5 0\nv 5 5 0\nv 5 -5 0\nf 1 2 3 4\n"), "write");
  const char *path = scratch_file("media_aov.json",
      "{ \"camera\": {\"position\": [0,0,3], \"look_at\": [0,0,0], \"fov\": 30},\n"
      "  \"film\": {\"width\": 9, \"height\": 9}, \"render\": {\"spp\": 8},\n"
      "  \"media\": {\"smoke\": {\"type\": \"homogeneous\", \"sigma_a\": 0.5, \"sigma_s\": 2}},\n"
      "  \"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": [0.2,0.4,0.6]}, \"edge\": {\"type\": \"null\"}},\n"
      "  \"shapes\": [{\"file\": \"media_plane.obj\", \"material\": \"m\"},\n"
      "             {\"type\": \"sphere\", \"center\": [0,0,1.5], \"radius\": 0.8, \"material\": \"edge\", \"interior\": \"smoke\"}],\n"
      "  \"lights\": [{\"type\": \"point\", \"position\": [0,2,2], \"intensity\": 1}] }\n");
  valo_options o;
  valo_options_init(&o);
  o.aovs = 1 | VALO_AOVS_AO;
  snprintf(o.params, sizeof o.params, "ao.distance=3");
  valo_scene *sc;
  valo_render *r = render_file(path, &o, &sc);
  CHECK(r, "render failed");
  const char *names[4] = {"albedo", "normal", "depth", "ao"};
  image im[4];
  for (int k = 0; k < 4; k++) CHECK(read_aov(r, names[k], &im[k]) == 0, "cannot write or read the %s AOV", names[k]);
  const float *ao = &im[3].rgb[3 * (4 * 9 + 4)];
  fprintf(stderr, "centre ao %g\n", ao[0]);
  CHECK(ao[0] == 1, "ao %g under the null sphere, want 1", ao[0]);
  image_free(&im[3]);
  const float *a = &im[0].rgb[3 * (4 * 9 + 4)], *n = &im[1].rgb[3 * (4 * 9 + 4)], *d = &im[2].rgb[3 * (4 * 9 + 4)];
  fprintf(stderr, "centre: albedo %g %g %g, normal %g %g %g, depth %g\n", a[0], a[1], a[2], n[0], n[1], n[2], d[0]);
  CHECK(fabsf(a[0] - 0.2f) < 1e-5f && fabsf(a[1] - 0.4f) < 1e-5f && fabsf(a[2] - 0.6f) < 1e-5f, "albedo (%g %g %g)", a[0], a[1], a[2]);
  CHECK(fabsf(n[2] - 1) < 1e-5f, "normal (%g %g %g)", n[0], n[1], n[2]);
  CHECK(fabsf(d[0] - 3) < 0.01f, "centre depth %g, expected 3", d[0]);
  for (int k = 0; k < 3; k++) image_free(&im[k]);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  return 0;
}

/* Only path renders media (in RGB and --spectral): the others are refused, naming why. */
static int media_need_path(void) {
  static const char *const others[] = {"whitted", "distribution", "restir-di", "vpl", "photon", "ao"};
  const char *medium = "{\"type\": \"homogeneous\", \"sigma_a\": 0.1, \"sigma_s\": 1}";
  for (size_t k = 0; k < sizeof others / sizeof others[0]; k++) {
    valo_options o;
    valo_options_init(&o);
    snprintf(o.integrator, sizeof o.integrator, "%s", others[k]);
    fprintf(stderr, "%s: ", others[k]);
    float *px = media_render("{\"position\": [0, 0, 3.2], \"look_at\": [0, 0, 0]}", medium, 1, 8, &o);
    CHECK(!px, "rendered a scene with media");
  }
  return 0;
}

/* --spectral through media: the furnaces again (a chromatic sigma_s upsampled to each
 * path's wavelengths, homogeneous and in a grid: every channel's mean 1, the film's
 * white being the flat spectrum), and Beer-Lambert through a grey absorber, exact at
 * every wavelength. The furnaces' colour is mild: the spectral film clamps each sample's
 * negative RGB at 0 (core/spectrum.h), which strongly chromatic media trip often
 * (sigma_s = (1, 2, 4): 9 % of samples, +0.3 % in red and blue; docs/integrators.md). */
static int spectral_media(void) {
  valo_options o;
  valo_options_init(&o);
  o.spectral = 1;
  int spp = test_full() ? 1024 : 256;
  float *px = media_render("{\"position\": [0, 0, 3.2], \"look_at\": [0, 0, 0], \"fov\": 45}",
                           "{\"type\": \"homogeneous\", \"sigma_a\": 0, \"sigma_s\": [1.5, 2, 2.5], \"g\": 0.7}", spp, 32, &o);
  int rc = furnace_check("spectral furnace", px, 32 * 32);
  free(px);
  if (rc) return rc;
  const char *vol = write_vol("sblobs.vol", 24, 1.2f, blobs);
  CHECK(vol, "cannot write the grid");
  char medium[1200];
  snprintf(medium, sizeof medium, "{\"type\": \"grid\", \"file\": \"%s\", \"sigma_a\": 0, \"sigma_s\": [1.5, 2, 2.5], \"g\": 0.5}", vol);
  px = media_render("{\"position\": [0, 0, 3.2], \"look_at\": [0, 0, 0], \"fov\": 45}", medium, spp, 32, &o);
  rc = furnace_check("spectral grid furnace", px, 32 * 32);
  free(px);
  if (rc) return rc;
  const int res = 32;
  const double sa = 0.8, half = 1.2;
  px = media_render("{\"type\": \"orthographic\", \"height\": 2.4, \"position\": [0, 0, 3], \"look_at\": [0, 0, 0]}",
                    "{\"type\": \"homogeneous\", \"sigma_a\": 0.8, \"sigma_s\": 0}", spp, res, &o);
  CHECK(px, "render failed");
  double sum_err[3] = {0};
  int n = 0;
  for (int y = 0; y < res; y++)
    for (int x = 0; x < res; x++) {
      double u = (x + 0.5) / res * 2 * half - half, v = half - (y + 0.5) / res * 2 * half;
      if (!(u * u + v * v < 0.8)) continue;
      double want = 0;
      for (int sy = 0; sy < 8; sy++)
        for (int sx = 0; sx < 8; sx++) {
          double uu = (x + (sx + 0.5) / 8) / res * 2 * half - half, vv = half - (y + (sy + 0.5) / 8) / res * 2 * half;
          want += exp(-sa * 2 * sqrt(fmax(0, 1 - uu * uu - vv * vv))) / 64;
        }
      n++;
      for (int c = 0; c < 3; c++) sum_err[c] += (px[3 * (y * res + x) + c] - want) / want;
    }
  free(px);
  fprintf(stderr, "spectral beer-lambert: %d pixels, mean relative error %.4f %.4f %.4f\n", n, sum_err[0] / n, sum_err[1] / n, sum_err[2] / n);
  for (int c = 0; c < 3; c++) CHECK(fabs(sum_err[c] / n) < 0.01, "channel %d: mean error %.4f", c, sum_err[c] / n);
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"medium_furnace", medium_furnace},
                                    {"beer_lambert", beer_lambert},
                                    {"grid_medium", grid_medium},
                                    {"grid_lookup", grid_lookup},
                                    {"medium_emission", medium_emission},
                                    {"null_surface_invisible", null_surface_invisible},
                                    {"aovs_through_null", aovs_through_null},
                                    {"media_need_path", media_need_path},
                                    {"spectral_media", spectral_media},
                                    {NULL, NULL}};
  return test_main(argc, argv, cases);
}
