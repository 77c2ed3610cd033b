/* bench_render.c — time-to-error of the `path` integrator on CornellBox-Original 256x256
 * against the Cycles reference (../shared/references): seconds and relMSE at 16, 64, 256
 * and 1024 spp, beside Cycles' own times on a 2-core machine (references/README.md), and
 * the time valo needs to reach the relMSE of Cycles' 1024-spp render (0.00014, reached by
 * Cycles in 106 s). relMSE = mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01).
 * Adaptive sampling is bench_adaptive's. Usage: bench_render [--quick] [--sampler S] */
#include "valo/valo.h"
#include "image/image_io.h"
#include "bench_util.h"
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
  char obj[2048], refp[2048];
  snprintf(obj, sizeof obj, "%s/scenes/cornell/CornellBox-Original.obj", root && *root ? root : VALO_SHARED_DIR);
  snprintf(refp, sizeof refp, "%s/references/cornell-original.exr", root && *root ? root : VALO_SHARED_DIR);
  char scene_path[64];
  snprintf(scene_path, sizeof scene_path, "bench-render-%ld.json", (long)getpid());
  if (bench_cornell_scene(scene_path, obj, 256, 256)) return 1;
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
  return 0;
}
