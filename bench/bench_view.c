/* bench_view.c — the viewer's real-time figure (docs/performance.md): frames rendered as
 * `valo view` renders them (valo_render_step, each frame alone, temporal reuse from the
 * last, in the viewer's fast configuration), on a still camera, 2 threads. Prints the
 * frame rate over every frame (rendering time: the error is taken between frames) and
 * the relMSE of each frame rendered after the first second of still camera, against a converged direct-light reference, pixels that see a
 * lamp (and their neighbours) left out; and the first frame's (no history yet: what a
 * moving camera sees).
 * Usage: bench_view SCENE REFERENCE.exr [--res WxH] [--integrator NAME] [--params "K=V ..."]
 *        [--seconds S] (frames are rendered for S seconds after the first; default 2) */
#include "valo/valo.h"
#include "bench_util.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The viewer's configuration for restir (src/cli/view.c). */
static const char realtime_params[] = "candidates=4 iterations=0 unbiased=0";

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: bench_view SCENE REFERENCE.exr [--res WxH] [--integrator NAME] [--params \"K=V ...\"] [--seconds S]\n");
    return 2;
  }
  int w = 320, h = 240;
  const char *integ = "restir-di", *params = realtime_params;
  double seconds = 2;
  for (int i = 3; i + 1 < argc; i += 2) {
    if (!strcmp(argv[i], "--res")) sscanf(argv[i + 1], "%dx%d", &w, &h);
    else if (!strcmp(argv[i], "--integrator")) integ = argv[i + 1];
    else if (!strcmp(argv[i], "--params")) params = argv[i + 1];
    else if (!strcmp(argv[i], "--seconds")) seconds = atof(argv[i + 1]);
  }
  valo_error err;
  valo_scene *sc;
  int rw, rh;
  float *ref;
  if (valo_scene_load(argv[1], &sc, &err) || valo_image_read(argv[2], &rw, &rh, &ref, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }
  if (rw != w || rh != h) { fprintf(stderr, "%s is %dx%d, not %dx%d\n", argv[2], rw, rh, w, h); return 1; }
  int n = w * h;
  float *px = malloc((size_t)n * 3 * sizeof *px);
  unsigned char *ok = malloc((size_t)n);
  valo_options o;
  valo_options_init(&o);
  o.width = w; o.height = h; o.threads = 2; o.spp = 64; o.max_depth = 0;
  /* the lamp mask: emission seen directly in any of 64 samples, and its neighbours */
  valo_render *r;
  if (valo_render_create(sc, &o, &r, &err) || valo_render_run(r, NULL, NULL, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }
  valo_render_pixels(r, px);
  valo_render_destroy(r);
  bench_lamp_mask(px, w, h, ok);
  valo_options_init(&o);
  o.width = w; o.height = h; o.threads = 2;
  snprintf(o.integrator, sizeof o.integrator, "%s", integ);
  snprintf(o.params, sizeof o.params, "%s", strncmp(integ, "restir", 6) ? "" : params);
  if (!strncmp(integ, "path", 4)) o.max_depth = 1;
  if (valo_render_create(sc, &o, &r, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }
  double warm = 0, emax = 0, esum = 0, busy = 0, efirst = 0;
  int frames = 0, measured = 0;
  for (;;) {
    double s0 = bench_now();
    if (valo_render_step(r, 1, 1, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }
    frames++;
    busy += bench_now() - s0;
    if (frames == 1) {
      valo_render_pixels(r, px);
      efirst = bench_relmse(px, ref, n, ok);
    }
    if (busy >= 1 + seconds) break;
    if (busy < 1) { warm = busy; continue; }
    valo_render_pixels(r, px);
    double e = bench_relmse(px, ref, n, ok);
    emax = e > emax ? e : emax;
    esum += e;
    measured++;
  }
  printf("%s, %s (%s), %dx%d, 2 threads: %.2f fps (%.1f ms a frame, %d frames in %.2f s of rendering); "
         "first frame (no history) relMSE %.4g; after %.2f s of still camera, per-frame relMSE mean %.4g, max %.4g over %d frames\n",
         argv[1], integ, o.params, w, h, frames / busy, 1e3 * busy / frames, frames, busy, efirst, warm, measured ? esum / measured : 0, emax, measured);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  valo_image_free(ref);
  free(px);
  free(ok);
  return 0;
}
