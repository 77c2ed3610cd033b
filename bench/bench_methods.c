/* bench_methods.c — the seeds' methods measured side by side (docs/performance.md):
 *  1. the seed's table: proximity-ao (splatting, kd-tree build, search, shading timed
 *     apart) against ray-traced ao with 256 rays per pixel, on CornellBox-Original with
 *     the Stanford bunny, Sponza and the dragon; each one's error against a converged ao
 *     image (ao at 4096 rays; 1024 with --quick);
 *  2. photon against path at equal time on CornellBox-Original (the Cycles reference) and
 *     on scenes/caustic.json (tests/data/caustic-path.exr): relMSE against time;
 *  3. seed 002's many-light methods: path, vpl (clamped; compensated) and vsl with equal
 *     time budgets on CornellBox-Original, scenes/cornell-glossy.json
 *     (tests/data/cornell-glossy-path.exr, 64x64) and Sponza under a sun
 *     (bench/sponza-sun.json, bench/references/sponza-sun-path.exr: path, 2048 spp),
 *     relMSE at each budget;
 *  4. the "when to use each method" table: photon, vpl, vsl and restir-gi at their
 *     defaults against path at equal time (10 s; 3 with --quick; --seconds S) on
 *     CornellBox-Original and -Mirror, caustic-far and scenes/manylight.json, and
 *     restir-di against path with one bounce on manylight.json's direct light.
 * Usage: bench_methods [--quick] [--only ao|photon|manylight|table] [--seconds S] */
#include "valo/valo.h"
#include "bench_util.h"
#include "scene/scene.h"
#include "load/load.h"
#include "geometry/accel.h"
#include "geometry/pointtree.h"
#include "scene/splat.h"
#include "image/image_io.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#ifndef VALO_SHARED_DIR
#define VALO_SHARED_DIR "../shared"
#endif
#ifndef VALO_SOURCE_DIR
#define VALO_SOURCE_DIR "."
#endif


static int g_last_spp; /* spp of the last render */

static const char *shared(void) { const char *r = getenv("VALO_SHARED"); return r && *r ? r : VALO_SHARED_DIR; }

/* Renders scene file `path` with the integrator and spp (path length at most max_depth,
 * -1: unlimited); returns pixels and the wall-clock seconds of create + run, less the
 * kd-tree build every method needs. */
static float *render_depth(const char *path, const char *integ, int spp, double budget, const char *params, int max_depth, int w, int h,
                           double *secs) {
  valo_error err;
  valo_scene *sc;
  if (valo_scene_load(path, &sc, &err)) { fprintf(stderr, "%s\n", err.message); return NULL; }
  valo_options o;
  valo_options_init(&o);
  snprintf(o.integrator, sizeof o.integrator, "%s", integ);
  if (params) snprintf(o.params, sizeof o.params, "%s", params);
  o.spp = spp;
  if (budget > 0) o.time_budget = budget;
  o.width = w; o.height = h;
  o.threads = 2;
  o.seed = 5;
  o.max_depth = max_depth;
  valo_render *r;
  double t0 = bench_now();
  if (valo_render_create(sc, &o, &r, &err) || valo_render_run(r, NULL, NULL, &err)) { fprintf(stderr, "%s\n", err.message); return NULL; }
  valo_stats st;
  valo_render_stats(r, &st);
  g_last_spp = st.spp_done;
  *secs = bench_now() - t0 - st.build_seconds; /* the ray-tracing structure is common to all */
  float *px = malloc((size_t)w * h * 3 * sizeof *px);
  valo_render_pixels(r, px);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  return px;
}

static float *render_budget(const char *path, const char *integ, int spp, double budget, const char *params, int w, int h, double *secs) {
  return render_depth(path, integ, spp, budget, params, -1, w, h, secs);
}

static float *render(const char *path, const char *integ, int spp, const char *params, int w, int h, double *secs) {
  return render_budget(path, integ, spp, 0, params, w, h, secs);
}

static double rmse(const float *a, const float *b, int n) {
  double e = 0;
  for (int i = 0; i < n; i++) e += (a[3 * i + 1] - b[3 * i + 1]) * (a[3 * i + 1] - b[3 * i + 1]);
  return sqrt(e / n);
}
static double corr(const float *a, const float *b, int n) {
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (int i = 0; i < n; i++) {
    double x = a[3 * i + 1], y = b[3 * i + 1];
    sa += x; sb += y; saa += x * x; sbb += y * y; sab += x * y;
  }
  return (sab / n - sa / n * sb / n) / sqrt((saa / n - sa * sa / n / n) * (sbb / n - sb * sb / n / n));
}

typedef struct visit_count { uint64_t n; } visit_count;
static void count_visit(void *u, uint32_t i, float d2) { (void)i; (void)d2; ((visit_count *)u)->n++; }

/* The proximity-ao breakdown: splatting, tree build, camera rays and the range searches
 * alone at the camera hits, in front of each hit's plane as the integrator searches (its
 * defaults: r = 1/10 of the bounding radius, d = r / 8). */
static void breakdown(const char *json_path, int w, int h, double *t_splat, double *t_build, double *t_search, uint32_t *npts, double *per_query) {
  valo_error err;
  scene *s = scene_new(json_path);
  if (load_json(s, json_path, NULL, &err) || scene_commit(s, &err)) { fprintf(stderr, "%s\n", err.message); scene_free(s); return; }
  float r = 0.1f * s->radius, d = r / 6;
  splat_points sp;
  double t0 = bench_now();
  splat_scene(s, d, 50000000, 2, &sp);
  *t_splat = bench_now() - t0;
  point_tree t;
  t0 = bench_now();
  point_tree_build(&t, sp.p, sp.n_pts);
  point_tree_build_boxes(&t);
  *t_build = bench_now() - t0;
  *npts = sp.n_pts;
  accel *acc;
  accel_create("kdtree", s->pos, s->cap_verts, s->idx, s->ntris, 2, NULL, &acc, &err);
  camera c = scene_camera_fit(s, (float)w / (float)h);
  vec3 fwd = v3_norm(v3_sub(c.look_at, c.pos)), right = v3_norm(v3_cross(fwd, c.up)), up = v3_cross(right, fwd);
  float th = tanf(0.5f * c.fov_deg * 3.14159265f / 180), asp = (float)w / (float)h;
  vec3 *hits = malloc((size_t)w * h * sizeof *hits), *nrm = malloc((size_t)w * h * sizeof *nrm);
  int nh = 0;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      float sx = (2 * (x + 0.5f) / w - 1) * th * asp, sy = (1 - 2 * (y + 0.5f) / h) * th;
      ray ry = {c.pos, v3_norm(v3_add(fwd, v3_add(v3_scale(right, sx), v3_scale(up, sy)))), INFINITY};
      hit hh;
      if (accel_intersect(acc, &ry, &hh)) {
        vec3 ng = v3_norm(scene_tri_ng(s, hh.tri));
        nrm[nh] = v3_dot(ng, ry.d) > 0 ? v3_neg(ng) : ng;
        hits[nh++] = v3_add(ry.o, v3_scale(ry.d, hh.t));
      }
    }
  visit_count vc = {0};
  t0 = bench_now();
  for (int i = 0; i < nh; i++) point_tree_radius_halfspace(&t, hits[i], r * r, nrm[i], 1e-3f * r, count_visit, &vc);
  *t_search = bench_now() - t0; /* one thread: the render uses two */
  *per_query = nh ? (double)vc.n / nh : 0;
  free(hits);
  free(nrm);
  accel_destroy(acc);
  point_tree_free(&t);
  splat_free(&sp);
  scene_free(s);
}

static int bench_ao(int quick) {
  char cb[4096], sp[4096], dr[4096];
  snprintf(cb, sizeof cb,
           "{ \"camera\": {\"position\": [0,1,3.4], \"look_at\": [0,1,0], \"up\": [0,1,0], \"fov\": 40},\n"
           "  \"shapes\": [ {\"file\": \"%s/scenes/cornell/CornellBox-Original.obj\"},\n"
           "    {\"file\": \"%s/scenes/models/stanford-bunny.obj\", \"transform\": {\"scale\": [4, 4, 4], \"translate\": [0.1, -0.13, 0.2]}} ] }",
           shared(), shared());
  snprintf(sp, sizeof sp,
           "{ \"camera\": {\"position\": [2.25067, 8.24132, -0.0492483], \"look_at\": [3.15037, 7.8048, -0.0501832], \"up\": [0.436514, 0.899693, -0.00291584], \"fov\": 70},\n"
           "  \"shapes\": [ {\"file\": \"%s/scenes/sponza/sponza.obj\"} ] }", shared());
  snprintf(dr, sizeof dr, "{ \"shapes\": [ {\"file\": \"%s/scenes/dragon/dragon_vrip.ply\"}, {\"file\": \"%s/floor.obj\"} ] }", shared(), ".");
  FILE *f = fopen("floor.obj", "w");
  if (!f) return 1;
  /* the dragon's ground: a quad under it (the PLY's y runs 0.05 .. 0.2) */
  fprintf(f, "v -0.3 0.0526 -0.2\nv 0.3 0.0526 -0.2\nv 0.3 0.0526 0.2\nv -0.3 0.0526 0.2\nf 1 4 3 2\n");
  fclose(f);
  const char *names[3] = {"CornellBox-Original + bunny", "Sponza", "dragon on a floor"};
  const char *jsons[3] = {cb, sp, dr};
  const int res[3][2] = {{256, 256}, {256, 144}, {256, 192}};
  int conv = quick ? 1024 : 4096;
  printf("## proximity-ao against ao (256 rays), 2 threads\n\n");
  printf("| scene | points | splat s | build s | search s (1 thread) | points per search | proximity-ao s (1 spp, all) | ao 256 s | ao/proximity time | proximity RMSE | fitted M: RMSE | ao-256 RMSE | proximity correlation |\n");
  printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int i = 0; i < 3; i++) {
    char path[64];
    snprintf(path, sizeof path, "bench-ao-%d-%ld.json", i, (long)getpid());
    f = fopen(path, "w");
    if (!f) return 1;
    fputs(jsons[i], f);
    fclose(f);
    int w = res[i][0], h = res[i][1];
    double ts = 0, tb = 0, tq = 0, ppq = 0, t_prox = 0, t_ao = 0, t_ref = 0;
    uint32_t np = 0;
    breakdown(path, w, h, &ts, &tb, &tq, &np, &ppq);
    float *px = render(path, "proximity-ao", 1, NULL, w, h, &t_prox);
    /* and with the strength a user would pick for this scene: the one whose mean matches
     * the converged ao (bisection on M) */
    float *ref0 = render(path, "ao", conv, "shading_normals=0", w, h, &t_ref);
    double lo = 0.05, hi = 4, mfit = 1, tdummy;
    float *fit = NULL;
    double mref = 0;
    for (int k = 0; ref0 && k < w * h; k++) mref += ref0[3 * k + 1];
    for (int it = 0; ref0 && it < 12; it++) {
      mfit = sqrt(lo * hi);
      char pm[64];
      snprintf(pm, sizeof pm, "strength=%.4f", mfit);
      free(fit);
      fit = render(path, "proximity-ao", 1, pm, w, h, &tdummy);
      if (!fit) break;
      double mp = 0;
      for (int k = 0; k < w * h; k++) mp += fit[3 * k + 1];
      if (mp > mref) lo = mfit; else hi = mfit;
    }
    /* ao about the geometric normal, as proximity-ao sees surfaces (Sponza's bump maps
     * would otherwise show in ao only) */
    float *ao = render(path, "ao", 256, "shading_normals=0", w, h, &t_ao);
    float *ref = ref0;
    remove(path);
    if (!px || !ao || !ref || !fit) return 1;
    printf("| %s | %u | %.3f | %.3f | %.3f | %.0f | %.3f | %.2f | %.1f | %.4f | %.2f: %.4f | %.4f | %.3f |\n", names[i], np, ts, tb, tq, ppq, t_prox,
           t_ao, t_ao / t_prox, rmse(px, ref, w * h), mfit, rmse(fit, ref, w * h), rmse(ao, ref, w * h), corr(px, ref, w * h));
    fflush(stdout);
    free(px); free(ao); free(ref); free(fit);
  }
  remove("floor.obj");
  printf("\n(RMSE and correlation against ao about the geometric normal at %d rays per pixel; times are create + render less the kd-tree build both\n"
         "need, so proximity-ao's include splatting and its point tree; fitted M: the strength whose image mean matches the reference.)\n\n", conv);
  return 0;
}


/* A scene file for CornellBox-Original with the reference's camera (in the working
 * folder; remove it after) and the path of that reference. */
static int write_cornell(char *path, size_t pn, char *refp, size_t rn) {
  snprintf(path, pn, "bench-cornell-%ld.json", (long)getpid());
  char obj[2048];
  snprintf(obj, sizeof obj, "%s/scenes/cornell/CornellBox-Original.obj", shared());
  if (bench_cornell_scene(path, obj, 256, 256)) return 1;
  snprintf(refp, rn, "%s/references/cornell-original.exr", shared());
  return 0;
}

/* Renders `integ` at each of spp[0..n) (w x w pixels) and prints a row per render with
 * its time and relMSE against ref; fills t[] and e[]. */
static int curve(const char *scene_path, const char *integ, const int *spp, int n, const image *ref, int w, double *t, double *e) {
  for (int i = 0; i < n; i++) {
    float *px = render(scene_path, integ, spp[i], NULL, w, w, &t[i]);
    if (!px) return 1;
    e[i] = bench_relmse(px, ref->rgb, w * w, NULL);
    printf("| %s | %d | %.2f | %.5f |\n", integ, spp[i], t[i], e[i]);
    fflush(stdout);
    free(px);
  }
  return 0;
}

static int bench_photon(int quick) {
  char path[64], refp[2048];
  if (write_cornell(path, sizeof path, refp, sizeof refp)) return 1;
  const char *scenes[2] = {path, VALO_SOURCE_DIR "/scenes/caustic.json"};
  const char *refs[2] = {refp, VALO_SOURCE_DIR "/tests/data/caustic-path.exr"};
  const char *names[2] = {"CornellBox-Original 256x256", "caustic.json 128x128"};
  const int wh[2] = {256, 128};
  printf("## photon against path: relMSE against time, 2 threads\n\n");
  for (int k = 0; k < 2; k++) {
    image ref;
    valo_error err;
    if (image_read(refs[k], &ref, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }
    printf("### %s\n\n| integrator | spp | seconds | relMSE |\n|---|---|---|---|\n", names[k]);
    const int pspp[4] = {4, 16, 64, 256}, fspp[4] = {1, 2, 4, 8};
    double pt[4], pe[4], ft[4], fe[4];
    int n = quick ? 3 : 4;
    if (curve(scenes[k], "path", pspp, n, &ref, wh[k], pt, pe) || curve(scenes[k], "photon", fspp, n, &ref, wh[k], ft, fe)) return 1;
    /* path is unbiased: relMSE ~ c / t; its error at photon's last time */
    double c = pe[n - 1] * pt[n - 1], at = c / ft[n - 1];
    printf("\nAt photon's %.1f s: path's relMSE (extrapolated as c/t) %.5f, photon %.5f: photon/path error %.2f.\n\n", ft[n - 1], at, fe[n - 1],
           fe[n - 1] / at);
    image_free(&ref);
  }
  remove(path);
  return 0;
}

static int bench_manylight(int quick) {
  char path[64], refp[2048];
  if (write_cornell(path, sizeof path, refp, sizeof refp)) return 1;
  const char *scenes[3] = {path, VALO_SOURCE_DIR "/scenes/cornell-glossy.json", VALO_SOURCE_DIR "/bench/sponza-sun.json"};
  const char *refs[3] = {refp, VALO_SOURCE_DIR "/tests/data/cornell-glossy-path.exr", VALO_SOURCE_DIR "/bench/references/sponza-sun-path.exr"};
  const char *names[3] = {"CornellBox-Original 256x256", "cornell-glossy.json 64x64", "Sponza under a sun (bench/sponza-sun.json) 128x72"};
  const int ws[3] = {256, 64, 128}, hs[3] = {256, 64, 72};
  const struct { const char *integ, *params, *label; } m[7] = {
      {"path", "", "path"},
      {"vpl", "count=64 direct=8", "vpl (clamp 0.1)"},
      {"vpl", "count=64 direct=8 clamp=0.3", "vpl (clamp 0.3)"},
      {"vpl", "count=64 direct=8 clamp=0.3 compensate=1", "vpl (clamp 0.3, compensated)"},
      {"vpl", "count=256 direct=8 clamp=0.2", "vpl (clamp 0.2, 256 lights)"},
      {"vpl", "count=512 direct=8 clamp=0.2 shadow_rays=32", "vpl (clamp 0.2, 512 lights, 32 sampled shadow rays)"},
      {"vsl", "count=64 direct=8", "vsl"}};
  const double budgets[3] = {2.5, 10, 40};
  int nb = quick ? 2 : 3;
  printf("## Many-light methods against path at equal time (2 threads; relMSE against the reference)\n\n");
  for (int k = 0; k < 3; k++) {
    image ref;
    valo_error err;
    if (image_read(refs[k], &ref, &err)) {
      /* made by: valo render bench/sponza-sun.json --spp 2048 --seed 21 -o bench/references/sponza-sun-path.exr */
      fprintf(stderr, "%s (skipped)\n", err.message);
      continue;
    }
    printf("### %s\n\n| method |", names[k]);
    for (int b = 0; b < nb; b++) printf(" %.1f s |", budgets[b]);
    printf("\n|---|");
    for (int b = 0; b < nb; b++) printf("---|");
    printf("\n");
    for (int i = 0; i < 7; i++) {
      printf("| %s |", m[i].label);
      for (int b = 0; b < nb; b++) {
        double t;
        float *px = render_budget(scenes[k], m[i].integ, 1000000, budgets[b], m[i].params, ws[k], hs[k], &t);
        if (!px) return 1;
        printf(" %.5f |", bench_relmse(px, ref.rgb, ws[k] * hs[k], NULL));
        fflush(stdout);
        free(px);
      }
      printf("\n");
    }
    printf("\n");
    image_free(&ref);
  }
  remove(path);
  return 0;
}

/* The "when to use each method" table (docs/integrators.md): every method at its
 * defaults against path, equal time, on scenes with independent references: where a
 * method should win and where it should not. restir-di is measured against path with
 * one bounce (direct light) on the many-light scene here and in bench_restir. */
static int bench_table(int quick, double seconds) {
  char cpath[64], mpath[64], refp[2048], mref[2048], obj[2048];
  snprintf(cpath, sizeof cpath, "bench-cornell-%ld.json", (long)getpid());
  snprintf(mpath, sizeof mpath, "bench-mirror-%ld.json", (long)getpid());
  snprintf(obj, sizeof obj, "%s/scenes/cornell/CornellBox-Original.obj", shared());
  if (bench_cornell_scene(cpath, obj, 256, 256)) return 1;
  snprintf(obj, sizeof obj, "%s/scenes/cornell/CornellBox-Mirror.obj", shared());
  if (bench_cornell_scene(mpath, obj, 256, 256)) return 1;
  snprintf(refp, sizeof refp, "%s/references/cornell-original.exr", shared());
  snprintf(mref, sizeof mref, "%s/references/cornell-mirror.exr", shared());
  const struct { const char *name, *scene, *ref; } sc[5] = {
      {"CornellBox-Original (diffuse; Cycles)", cpath, refp},
      {"CornellBox-Mirror (the tall box a mirror; Cycles)", mpath, mref},
      {"caustic-far (a small lamp's caustic through a glass ball; Mitsuba 3)", VALO_SOURCE_DIR "/tests/data/caustic-far/caustic-far.json",
       VALO_SOURCE_DIR "/tests/data/caustic-far/caustic-far-mitsuba.exr"},
      {"scenes/manylight.json (many small lamps; Mitsuba 3)", VALO_SOURCE_DIR "/scenes/manylight.json",
       VALO_SOURCE_DIR "/tests/data/manylight-path-mitsuba.exr"},
      {"scenes/manylight.json, direct light only (Mitsuba 3)", VALO_SOURCE_DIR "/scenes/manylight.json",
       VALO_SOURCE_DIR "/tests/data/manylight-direct-mitsuba.exr"}};
  const char *methods[4] = {"photon", "vpl", "vsl", "restir-gi"};
  double t = seconds > 0 ? seconds : quick ? 3 : 10;
  printf("## Each method at its defaults against path, %.0f s each (2 threads; relMSE against the reference)\n\n", t);
  printf("| scene | method | spp | relMSE | path relMSE | method / path | mean vs reference |\n|---|---|---|---|---|---|---|\n");
  for (int k = 0; k < 5; k++) {
    image ref;
    valo_error err;
    if (image_read(sc[k].ref, &ref, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }
    int n = ref.w * ref.h, direct = k == 4;
    double ref_mean = 0;
    for (int i = 0; i < 3 * n; i++) ref_mean += ref.rgb[i];
    double secs;
    float *pp = render_depth(sc[k].scene, "path", 1000000, t, NULL, direct ? 1 : -1, ref.w, ref.h, &secs);
    if (!pp) return 1;
    double pe = bench_relmse(pp, ref.rgb, n, NULL);
    free(pp);
    for (int m = 0; m < (direct ? 1 : 4); m++) {
      const char *integ = direct ? "restir-di" : methods[m];
      g_last_spp = 0;
      float *px = render_depth(sc[k].scene, integ, 1000000, t, NULL, -1, ref.w, ref.h, &secs);
      if (!px) return 1;
      double e = bench_relmse(px, ref.rgb, n, NULL), mean = 0;
      for (int i = 0; i < 3 * n; i++) mean += px[i];
      printf("| %s | %s | %d | %.5f | %.5f | %.2f | %+.1f %% |\n", sc[k].name, integ, g_last_spp, e, pe, e / pe,
             100 * (mean / ref_mean - 1));
      fflush(stdout);
      free(px);
    }
    image_free(&ref);
  }
  remove(cpath);
  remove(mpath);
  return 0;
}

int main(int argc, char **argv) {
  int quick = 0;
  double seconds = 0;
  const char *only = NULL;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick")) quick = 1;
    else if (!strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
    else if (!strcmp(argv[i], "--seconds") && i + 1 < argc) seconds = atof(argv[++i]);
    else { fprintf(stderr, "usage: bench_methods [--quick] [--only ao|photon|manylight|table] [--seconds S]\n"); return 2; }
  }
  if ((!only || !strcmp(only, "ao")) && bench_ao(quick)) return 1;
  if ((!only || !strcmp(only, "photon")) && bench_photon(quick)) return 1;
  if ((!only || !strcmp(only, "manylight")) && bench_manylight(quick)) return 1;
  if ((!only || !strcmp(only, "table")) && bench_table(quick, seconds)) return 1;
  return 0;
}
