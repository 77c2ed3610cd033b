/* bench_view.c — the viewer's real-time figures (docs/performance.md): frames rendered as
 * `valo view` renders them (valo_render_step, each frame alone, temporal reuse from the
 * last, in the viewer's fast configuration), on a still camera, 2 threads, raw and through
 * the real-time denoiser (valo_render_denoise_live) in one run. Prints for each the frame
 * rate over every frame (rendering and filtering time: the error is taken between frames),
 * the relMSE of each frame after the first second of still camera against a converged
 * direct-light reference (pixels that see a lamp, and their neighbours, left out), and
 * the first frame's (no history: what a moving camera sees).
 * With --ghost DEG it then measures the denoiser's trail after a camera move: 1 s still,
 * eight frames orbiting DEG/8 degrees each about the look-at point, then still at the end
 * (B); the per-frame error at B after the stop, against B's own reference (256 spp made
 * here), beside a render that starts at B with no history. A frame whose error is more
 * than 1.1x the fresh one's shows the old view (a ghost); the trail is the last such frame.
 * Usage: bench_view SCENE REFERENCE.exr [--res WxH] [--integrator NAME] [--params "K=V ..."]
 *        [--seconds S] (frames are rendered for S seconds after the first; default 2)
 *        [--ghost DEG] [--raw-only | --denoise-only] */
#include "valo/valo.h"
#include "bench_util.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The viewer's configuration for restir (src/cli/view.c). */
static const char realtime_params[] = "candidates=4 iterations=0 unbiased=0";

typedef struct cfg {
  const valo_scene *sc;
  int w, h;
  const char *integ, *params;
} cfg;

static valo_render *make(const cfg *c, int denoise) {
  valo_options o;
  valo_options_init(&o);
  o.width = c->w; o.height = c->h; o.threads = 2;
  snprintf(o.integrator, sizeof o.integrator, "%s", c->integ);
  snprintf(o.params, sizeof o.params, "%s", strncmp(c->integ, "restir", 6) ? "" : c->params);
  if (!strncmp(c->integ, "path", 4)) o.max_depth = 1;
  if (denoise) o.aovs = strncmp(c->integ, "restir", 6) ? 1 | VALO_AOVS_VARIANCE : 1;
  valo_render *r;
  valo_error err;
  if (valo_render_create(c->sc, &o, &r, &err)) { fprintf(stderr, "%s\n", err.message); exit(1); }
  return r;
}

/* One frame as the viewer renders it, into px (denoised or raw); its seconds. */
static double frame(valo_render *r, int denoise, float *px) {
  valo_error err;
  double s0 = bench_now();
  if (valo_render_step(r, 1, 1, &err) || (denoise && valo_render_denoise_live(r, px, &err))) { fprintf(stderr, "%s\n", err.message); exit(1); }
  double dt = bench_now() - s0;
  if (!denoise) valo_render_pixels(r, px);
  return dt;
}

/* The lamp mask, and with spp > 0 a converged direct-light render (path --max-depth 1) in
 * ref, at camera cam (NULL: the scene's). */
static void reference(const cfg *c, const valo_camera *cam, int spp, float *ref, unsigned char *ok) {
  valo_error err;
  valo_render *r;
  for (int pass = 0; pass < (spp > 0 ? 2 : 1); pass++) {
    valo_options o;
    valo_options_init(&o);
    o.width = c->w; o.height = c->h; o.threads = 2; o.spp = pass ? spp : 64; o.max_depth = pass ? 1 : 0;
    if (valo_render_create(c->sc, &o, &r, &err) || (cam && valo_render_set_camera(r, cam, &err)) || valo_render_run(r, NULL, NULL, &err)) {
      fprintf(stderr, "%s\n", err.message);
      exit(1);
    }
    valo_render_pixels(r, ref);
    valo_render_destroy(r);
    if (!pass) bench_lamp_mask(ref, c->w, c->h, ok); /* emission seen directly, and its neighbours */
  }
}

static void orbit(valo_camera *c, double deg) {
  double t = deg * M_PI / 180, ox = c->pos[0] - c->look_at[0], oz = c->pos[2] - c->look_at[2];
  c->pos[0] = c->look_at[0] + ox * cos(t) - oz * sin(t);
  c->pos[2] = c->look_at[2] + ox * sin(t) + oz * cos(t);
}

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: bench_view SCENE REFERENCE.exr [--res WxH] [--integrator NAME] [--params \"K=V ...\"] [--seconds S] [--ghost DEG] [--raw-only | --denoise-only]\n");
    return 2;
  }
  cfg c = {NULL, 320, 240, "restir-di", realtime_params};
  double seconds = 2, ghost = 0;
  int modes[2] = {1, 1}; /* raw, denoised */
  for (int i = 3; i < argc; i++) {
    if (!strcmp(argv[i], "--raw-only")) modes[1] = 0;
    else if (!strcmp(argv[i], "--denoise-only")) modes[0] = 0;
    else if (i + 1 >= argc) { fprintf(stderr, "%s needs a value\n", argv[i]); return 2; }
    else if (!strcmp(argv[i], "--res")) sscanf(argv[++i], "%dx%d", &c.w, &c.h);
    else if (!strcmp(argv[i], "--integrator")) c.integ = argv[++i];
    else if (!strcmp(argv[i], "--params")) c.params = argv[++i];
    else if (!strcmp(argv[i], "--seconds")) seconds = atof(argv[++i]);
    else if (!strcmp(argv[i], "--ghost")) ghost = atof(argv[++i]);
    else { fprintf(stderr, "unknown option %s\n", argv[i]); return 2; }
  }
  valo_error err;
  valo_scene *sc;
  int rw, rh;
  float *ref;
  if (valo_scene_load(argv[1], &sc, &err) || valo_image_read(argv[2], &rw, &rh, &ref, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }
  c.sc = sc;
  if (rw != c.w || rh != c.h) { fprintf(stderr, "%s is %dx%d, not %dx%d\n", argv[2], rw, rh, c.w, c.h); return 1; }
  int n = c.w * c.h;
  float *px = malloc((size_t)n * 3 * sizeof *px), *refb = malloc((size_t)n * 3 * sizeof *refb);
  unsigned char *ok = malloc((size_t)n), *okb = malloc((size_t)n);
  float *em = malloc((size_t)n * 3 * sizeof *em);
  reference(&c, NULL, 0, em, ok); /* the mask only */
  for (int dn = 0; dn < 2; dn++) {
    if (!modes[dn]) continue;
    valo_render *r = make(&c, dn);
    double warm = 0, emax = 0, esum = 0, busy = 0, efirst = 0;
    int frames = 0, measured = 0;
    for (;;) {
      busy += frame(r, dn, px);
      frames++;
      if (frames == 1) efirst = bench_relmse(px, ref, n, ok);
      if (busy >= 1 + seconds) break;
      if (busy < 1) { warm = busy; continue; }
      double e = bench_relmse(px, ref, n, ok);
      emax = e > emax ? e : emax;
      esum += e;
      measured++;
    }
    printf("%s, %s (%s), %s, %dx%d, 2 threads: %.2f fps (%.1f ms a frame, %d frames in %.2f s); first frame (no history) relMSE %.4g; "
           "after %.2f s of still camera, per-frame relMSE mean %.4g, max %.4g over %d frames\n",
           argv[1], c.integ, c.params, dn ? "denoised" : "raw", c.w, c.h, frames / busy, 1e3 * busy / frames, frames, busy, efirst, warm,
           measured ? esum / measured : 0, emax, measured);
    fflush(stdout);
    valo_render_destroy(r);
  }
  if (ghost != 0) {
    valo_render *r = make(&c, 1);
    valo_camera cam;
    valo_render_camera(r, &cam);
    valo_camera b = cam;
    orbit(&b, ghost);
    reference(&c, &b, 256, refb, okb);
    double busy = 0;
    while (busy < 1) busy += frame(r, 1, px); /* 1 s still at A */
    for (int k = 1; k <= 8; k++) { /* moving: eight frames */
      orbit(&cam, ghost / 8);
      if (valo_render_set_camera(r, &cam, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }
      frame(r, 1, px);
    }
    enum { AFTER = 12 };
    double with[AFTER], fresh[AFTER];
    for (int k = 0; k < AFTER; k++) { frame(r, 1, px); with[k] = bench_relmse(px, refb, n, okb); }
    valo_render_destroy(r);
    r = make(&c, 1);
    if (valo_render_set_camera(r, &b, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }
    for (int k = 0; k < AFTER; k++) { frame(r, 1, px); fresh[k] = bench_relmse(px, refb, n, okb); }
    valo_render_destroy(r);
    int trail = 0;
    printf("ghosting: %.3g degrees in 8 frames, then still; per-frame relMSE after the stop (with history / started there):", ghost);
    for (int k = 0; k < AFTER; k++) {
      printf(" %.4g/%.4g", with[k], fresh[k]);
      if (with[k] > 1.1 * fresh[k]) trail = k + 1;
    }
    printf("\ntrail: %d frames worse than a start without history\n", trail);
  }
  valo_scene_destroy(sc);
  valo_image_free(ref);
  free(px); free(refb); free(ok); free(okb); free(em);
  return 0;
}
