/* bench_render.c — time-to-error of the `path` integrator on CornellBox-Original 256x256
 * against the Cycles reference (../shared/references): seconds and relMSE at 16, 64, 256
 * and 1024 spp, beside Cycles' own times on a 2-core machine (references/README.md), and
 * the time valo needs to reach the relMSE of Cycles' 1024-spp render (0.00014, reached by
 * Cycles in 106 s). relMSE = mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01).
 * Then adaptive sampling against uniform sampling at equal time on CornellBox-Original,
 * CornellBox-Mirror and scenes/caustic.json (a glass sphere's caustic on a floor, with
 * `path`, against tests/data/caustic-path.exr, 32 768 spp). Usage: bench_render [--quick] */
#include "valo/valo.h"
#include "image/image_io.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef VALO_SHARED_DIR
#define VALO_SHARED_DIR "../shared"
#endif

int main(int argc, char **argv) {
  int quick = 0;
  const char *sampler_name = "sobol";
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick")) quick = 1;
    else if (!strcmp(argv[i], "--sampler") && i + 1 < argc) sampler_name = argv[++i];
  }
  const char *root = getenv("VALO_SHARED");
  char obj[2048], refp[2048], json[4096];
  snprintf(obj, sizeof obj, "%s/scenes/cornell/CornellBox-Original.obj", root && *root ? root : VALO_SHARED_DIR);
  snprintf(refp, sizeof refp, "%s/references/cornell-original.exr", root && *root ? root : VALO_SHARED_DIR);
  char scene_path[64];
  snprintf(scene_path, sizeof scene_path, "bench-render-%ld.json", (long)getpid());
  FILE *f = fopen(scene_path, "w");
  if (!f) return 1;
  fprintf(f, "{ \"camera\": {\"position\": [0,1,3.4], \"look_at\": [0,1,0], \"up\": [0,1,0], \"fov\": 40},\n"
             "  \"film\": {\"width\": 256, \"height\": 256}, \"shapes\": [ {\"file\": \"%s\"} ] }\n", obj);
  fclose(f);
  (void)json;
  valo_error err;
  image ref;
  if (image_read(refp, &ref, &err)) { fprintf(stderr, "%s\n", err.message); remove(scene_path); return 1; }
  valo_scene *sc;
  if (valo_scene_load(scene_path, &sc, &err)) { fprintf(stderr, "%s\n", err.message); remove(scene_path); return 1; }
  remove(scene_path);
  const int spps[4] = {16, 64, 256, 1024};
  const double cycles_s[4] = {1.3, 6.3, 29, 106};
  printf("## Render: CornellBox-Original 256x256, path integrator vs Cycles reference (2 threads)\n\n");
  printf("| spp | valo s | Cycles s | valo/Cycles time | valo relMSE | Mrays/s |\n|---|---|---|---|---|---|\n");
  double last_t = 0, last_e = 0;
  for (int i = 0; i < (quick ? 3 : 4); i++) {
    valo_options o;
    valo_options_init(&o);
    o.spp = spps[i];
    o.threads = 2;
    snprintf(o.sampler, sizeof o.sampler, "%s", sampler_name);
    o.seed = 3;
    valo_render *r;
    if (valo_render_create(sc, &o, &r, &err) || valo_render_run(r, NULL, NULL, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }
    float *px = malloc(256 * 256 * 3 * sizeof(float));
    valo_render_pixels(r, px);
    double e = 0;
    for (int k = 0; k < 256 * 256 * 3; k++) e += (px[k] - ref.rgb[k]) * (px[k] - ref.rgb[k]) / (ref.rgb[k] * ref.rgb[k] + 0.01);
    e /= 256 * 256 * 3;
    valo_stats st;
    valo_render_stats(r, &st);
    printf("| %d | %.2f | %.1f | %.2f | %.6f | %.2f |\n", spps[i], st.render_seconds, cycles_s[i], st.render_seconds / cycles_s[i], e,
           st.rays / st.render_seconds * 1e-6);
    fflush(stdout);
    last_t = st.render_seconds; last_e = e;
    free(px);
    valo_render_destroy(r);
  }
  /* relMSE ~ c / t for an unbiased estimator: time to reach Cycles' 1024-spp error. */
  double target = 0.00014, t_needed = last_t * last_e / target;
  printf("\nTime for valo to reach relMSE %.5f (Cycles 1024 spp, 106 s): about %.1f s, %.2fx Cycles' time.\n", target, t_needed, t_needed / 106);
  valo_scene_destroy(sc);
  image_free(&ref);
  /* Adaptive against uniform sampling at equal time, on both scenes with a reference. */
  printf("\n## Adaptive sampling: equal-time relMSE against uniform sampling (2 threads)\n\n");
  printf("| scene | uniform spp | seconds | uniform relMSE | adaptive relMSE (same time) | adaptive/uniform |\n|---|---|---|---|---|---|\n");
  const char *names[3] = {"CornellBox-Original", "CornellBox-Mirror", "scenes/caustic.json (path)"},
             *refs[2] = {"cornell-original.exr", "cornell-mirror.exr"};
  for (int k = 0; k < 3; k++) {
    int caustic = k == 2;
    const char *load_path = caustic ? VALO_SOURCE_DIR "/scenes/caustic.json" : scene_path;
    if (caustic) {
      snprintf(refp, sizeof refp, "%s", VALO_SOURCE_DIR "/tests/data/caustic-path.exr");
    } else {
      snprintf(obj, sizeof obj, "%s/scenes/cornell/%s.obj", root && *root ? root : VALO_SHARED_DIR, names[k]);
      snprintf(refp, sizeof refp, "%s/references/%s", root && *root ? root : VALO_SHARED_DIR, refs[k]);
      f = fopen(scene_path, "w");
      if (!f) return 1;
      fprintf(f, "{ \"camera\": {\"position\": [0,1,3.4], \"look_at\": [0,1,0], \"up\": [0,1,0], \"fov\": 40},\n"
                 "  \"film\": {\"width\": 256, \"height\": 256}, \"shapes\": [ {\"file\": \"%s\"} ] }\n", obj);
      fclose(f);
    }
    int loaded = !image_read(refp, &ref, &err) && !valo_scene_load(load_path, &sc, &err);
    if (!caustic) remove(scene_path);
    if (!loaded) { fprintf(stderr, "%s\n", err.message); return 1; }
    int np = ref.w * ref.h, spp = caustic ? (quick ? 256 : 1024) : (quick ? 64 : 256);
    double secs = 0, e[2];
    for (int mode = 0; mode < 2; mode++) {
      valo_options o;
      valo_options_init(&o);
      o.threads = 2;
      o.seed = 5;
      snprintf(o.sampler, sizeof o.sampler, "%s", sampler_name);
      o.spp = spp;
      o.width = ref.w;
      o.height = ref.h;
      if (caustic) snprintf(o.integrator, sizeof o.integrator, "path");
      if (mode == 1) { o.adaptive = 1; o.spp = 1 << 20; o.time_budget = secs; }
      valo_render *r;
      if (valo_render_create(sc, &o, &r, &err) || valo_render_run(r, NULL, NULL, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }
      float *px = malloc((size_t)np * 3 * sizeof(float));
      valo_render_pixels(r, px);
      double acc = 0;
      for (int i = 0; i < np * 3; i++) acc += (px[i] - ref.rgb[i]) * (px[i] - ref.rgb[i]) / (ref.rgb[i] * ref.rgb[i] + 0.01);
      e[mode] = acc / (np * 3);
      valo_stats st;
      valo_render_stats(r, &st);
      if (mode == 0) secs = st.render_seconds;
      free(px);
      valo_render_destroy(r);
    }
    printf("| %s | %d | %.1f | %.6f | %.6f | %.2f |\n", names[k], spp, secs, e[0], e[1], e[1] / e[0]);
    fflush(stdout);
    valo_scene_destroy(sc);
    image_free(&ref);
  }
  return 0;
}
