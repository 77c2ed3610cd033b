/* bench_adaptive.c — adaptive sampling (`--adaptive`, docs/integrators.md) against uniform
 * sampling on CornellBox-Original, CornellBox-Mirror (256x256, the shared references) and
 * scenes/caustic.json (`path`, tests/data/caustic-path.exr), and the most any per-pixel
 * allocation of the same samples could gain there. Usage: bench_adaptive [--quick]
 * [--only NAME] [--seeds S] [--no-bound].
 *
 * 1. Measured: for S seeds, uniform sampling at the budget, then adaptive sampling with a
 *    time budget equal to uniform's time (equal time) and with the same sample budget
 *    (equal samples). Gains are ratios of relMSE averaged over the seeds (a single render's
 *    relMSE moves with the fireflies it happened to catch).
 * 2. The bound: a pixel's expected relMSE is w_i / n_i for n_i samples, and w_i is measured
 *    from KE independent uniform renders against the reference. An allocation n_i ~ a_i
 *    with a first pass of share F (n_i >= F times the average, the rest water-filled)
 *    gains mean(w) / mean(w / n) at equal samples. a_i = sqrt(v_i) is the optimum when v is
 *    w itself; a renderer only has an estimate v from a first pass, so v comes from pilot
 *    renders independent of the KE (as many samples as the first pass has), from the pixel
 *    alone or averaged over its neighbourhood without itself, as the renderer does. The
 *    last row gives each rule a pilot of KE renders: more samples than the whole budget.
 *    relMSE = mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01). */
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

typedef struct bscene {
  const char *name, *obj, *ref; /* obj: a shared Cornell box OBJ, or NULL for caustic.json */
  int unit_spp, budget_spp, quick_budget_spp;
} bscene;

static const bscene SCENES[] = {
    {"CornellBox-Original", "CornellBox-Original.obj", "cornell-original.exr", 16, 256, 64},
    {"CornellBox-Mirror", "CornellBox-Mirror.obj", "cornell-mirror.exr", 16, 256, 64},
    {"caustic", NULL, NULL, 64, 1024, 256},
};

static int W, H;

/* One render into out (W*H*3); returns seconds, or -1 on failure. */
static double render(valo_scene *sc, int caustic, int spp, unsigned seed, int adaptive, double time_budget, float *out) {
  valo_options o;
  valo_options_init(&o);
  o.threads = 2;
  o.seed = (int)seed;
  o.spp = spp;
  o.width = W;
  o.height = H;
  if (caustic) snprintf(o.integrator, sizeof o.integrator, "path");
  if (adaptive) o.adaptive = VALO_ADAPTIVE_ERROR;
  if (time_budget > 0) { o.time_budget = time_budget; o.spp = 1 << 20; }
  valo_render *r;
  valo_error err;
  if (valo_render_create(sc, &o, &r, &err) || valo_render_run(r, NULL, NULL, &err)) {
    fprintf(stderr, "%s\n", err.message);
    return -1;
  }
  valo_render_pixels(r, out);
  valo_stats st;
  valo_render_stats(r, &st);
  valo_render_destroy(r);
  return st.render_seconds;
}

/* Mean of v over the (2R+1)^2 neighbourhood of each pixel without the pixel (R = 0: the
 * pixel alone). */
static void neighbours(const double *v, double *o, int R) {
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      double acc = 0;
      int c = 0;
      for (int dy = -R; dy <= R; dy++)
        for (int dx = -R; dx <= R; dx++) {
          int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= W || yy >= H || (R > 0 && !dx && !dy)) continue;
          acc += v[(size_t)yy * W + xx];
          c++;
        }
      o[(size_t)y * W + x] = c ? acc / c : 0;
    }
}

/* Equal-sample gain over uniform of n_i = max(F, lam sqrt(a_i)) (mean 1), on true w. */
static double alloc_gain(const double *w, const double *a, size_t n, double F) {
  double lo = 0, hi = 1e30;
  for (int it = 0; it < 400; it++) {
    double lam = 0.5 * (lo + hi), m = 0;
    for (size_t i = 0; i < n; i++) {
      double x = lam * sqrt(a[i]);
      m += x > F ? x : F;
    }
    if (m / (double)n > 1) hi = lam;
    else lo = lam;
  }
  double mw = 0, r = 0;
  for (size_t i = 0; i < n; i++) {
    double x = lo * sqrt(a[i]), ni = x > F ? x : F;
    r += w[i] / ni;
    mw += w[i];
  }
  return r > 0 ? mw / r : 1;
}

int main(int argc, char **argv) {
  int quick = 0, seeds = 0, bound = 1;
  const char *only = NULL;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick")) quick = 1;
    else if (!strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
    else if (!strcmp(argv[i], "--seeds") && i + 1 < argc) seeds = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--no-bound")) bound = 0;
    else { fprintf(stderr, "usage: bench_adaptive [--quick] [--only NAME] [--seeds S] [--no-bound]\n"); return 2; }
  }
  if (seeds <= 0) seeds = quick ? 2 : 4;
  const int KE = quick ? 12 : 32;
  const char *root = getenv("VALO_SHARED");
  if (!root || !*root) root = VALO_SHARED_DIR;
  printf("# Adaptive sampling against uniform sampling (2 threads, %d seeds%s)\n\n", seeds, quick ? ", quick" : "");
  printf("| scene | spp | uniform s | uniform relMSE | adaptive relMSE, equal time | **gain, equal time** | adaptive s, relMSE at equal samples | gain, equal samples |\n|---|---|---|---|---|---|---|---|\n");
  char bound_rows[3][1024];
  int nb = 0;
  for (size_t k = 0; k < sizeof SCENES / sizeof *SCENES; k++) {
    const bscene *b = &SCENES[k];
    if (only && strcmp(only, b->name)) continue;
    int caustic = b->obj == NULL;
    char refp[2048], obj[2048], scene_path[64] = "";
    if (caustic) snprintf(refp, sizeof refp, "%s", VALO_SOURCE_DIR "/tests/data/caustic-path.exr");
    else snprintf(refp, sizeof refp, "%s/references/%s", root, b->ref);
    image ref;
    valo_error err;
    if (image_read(refp, &ref, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }
    valo_scene *sc;
    if (caustic) {
      if (valo_scene_load(VALO_SOURCE_DIR "/scenes/caustic.json", &sc, &err)) { fprintf(stderr, "%s\n", err.message); return 1; }
    } else {
      snprintf(obj, sizeof obj, "%s/scenes/cornell/%s", root, b->obj);
      snprintf(scene_path, sizeof scene_path, "bench-adaptive-%ld.json", (long)getpid());
      if (bench_cornell_scene(scene_path, obj, 256, 256)) return 1;
      int bad = valo_scene_load(scene_path, &sc, &err) != VALO_OK;
      remove(scene_path);
      if (bad) { fprintf(stderr, "%s\n", err.message); return 1; }
    }
    W = ref.w;
    H = ref.h;
    size_t np = (size_t)W * H;
    int budget = quick ? b->quick_budget_spp : b->budget_spp;
    float *px = malloc(np * 3 * sizeof *px);
    double *w = calloc(np, sizeof *w), *s1 = calloc(np * 3, sizeof *s1), *s2 = calloc(np * 3, sizeof *s2);
    double *v = calloc(np, sizeof *v), *a = calloc(np, sizeof *a);
    if (!px || !w || !s1 || !s2 || !v || !a) return 1;

    /* 1. measured */
    double eu = 0, tu = 0, et = 0, es = 0, ts = 0;
    for (int s = 0; s < seeds; s++) {
      double t = render(sc, caustic, budget, 5 + s, 0, 0, px);
      if (t < 0) return 1;
      tu += t;
      eu += bench_relmse(px, ref.rgb, (int)np, NULL);
      if (render(sc, caustic, budget, 5 + s, 1, t, px) < 0) return 1;
      et += bench_relmse(px, ref.rgb, (int)np, NULL);
      double ta = render(sc, caustic, budget, 5 + s, 1, 0, px);
      if (ta < 0) return 1;
      ts += ta;
      es += bench_relmse(px, ref.rgb, (int)np, NULL);
    }
    eu /= seeds; tu /= seeds; et /= seeds; es /= seeds; ts /= seeds;
    printf("| %s | %d | %.1f | %.6f | %.6f | **%.2f** | %.1f s, %.6f | %.2f |\n", b->name, budget, tu, eu, et, eu / et, ts, es, eu / es);
    fflush(stdout);

    /* 2. the bound: w from KE renders of unit_spp, pilots from up to KE more */
    for (int e = 0; e < KE * bound; e++) {
      if (render(sc, caustic, b->unit_spp, 1000 + e, 0, 0, px) < 0) return 1;
      for (size_t i = 0; i < np; i++)
        for (int c = 0; c < 3; c++) {
          double d = px[3 * i + c] - ref.rgb[3 * i + c];
          w[i] += d * d / (ref.rgb[3 * i + c] * ref.rgb[3 * i + c] + 0.01) / 3 / KE;
        }
    }
    const double shares[3] = {0.75, 0.5, 0.25};
    const int radii[4] = {0, 2, 4, 8};
    int len = 0;
    bound_rows[nb][0] = 0;
    for (int p = 0; p < KE * bound; p++) {
      if (render(sc, caustic, b->unit_spp, 2000 + p, 0, 0, px) < 0) return 1;
      for (size_t i = 0; i < np * 3; i++) {
        s1[i] += px[i];
        s2[i] += (double)px[i] * px[i];
      }
      int kp = p + 1;
      for (int fi = 0; fi < 4; fi++) {
        double F = fi < 3 ? shares[fi] : 0.5;
        int want = fi < 3 ? (int)(F * budget / b->unit_spp + 0.5) : KE;
        if (want < 2) want = 2;
        if (kp != want) continue;
        for (size_t i = 0; i < np; i++) {
          double acc = 0;
          for (int c = 0; c < 3; c++) {
            double m = s1[3 * i + c] / kp, var = (s2[3 * i + c] - s1[3 * i + c] * m) / (kp - 1);
            acc += (var > 0 ? var : 0) / (m * m + 0.01) / 3;
          }
          v[i] = acc;
        }
        len += snprintf(bound_rows[nb] + len, sizeof bound_rows[nb] - (size_t)len, "| %s | %.2f | %d spp%s |", b->name, F, kp * b->unit_spp,
                        fi == 3 ? " (all)" : "");
        for (int ri = 0; ri < 4; ri++) {
          neighbours(v, a, radii[ri]);
          len += snprintf(bound_rows[nb] + len, sizeof bound_rows[nb] - (size_t)len, " %.2f |", alloc_gain(w, a, np, F));
        }
        len += snprintf(bound_rows[nb] + len, sizeof bound_rows[nb] - (size_t)len, "\n");
      }
    }
    nb += bound;
    free(px); free(w); free(s1); free(s2); free(v); free(a);
    valo_scene_destroy(sc);
    image_free(&ref);
  }
  if (!bound) return 0;
  printf("\n# The bound: equal-sample gain of the best allocation from a first pass (valo: share 0.5, 17x17)\n\n"
         "First pass share F; the pilot's samples per pixel; allocation n ~ sqrt(v) from the pixel's own first-pass\n"
         "variance (biased if used, here only a bound) or its neighbours' (5x5, 9x9, 17x17 without itself).\n\n"
         "| scene | F | pilot | own pixel | 5x5 | 9x9 | 17x17 |\n|---|---|---|---|---|---|---|\n");
  for (int i = 0; i < nb; i++) printf("%s", bound_rows[i]);
  return 0;
}
