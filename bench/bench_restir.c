/* bench_restir.c — restir-di and restir-gi against the baselines of the ReSTIR papers, at
 * equal time, on the many-light scenes (docs/performance.md):
 *  - direct light: restir-di against path limited to direct light (--max-depth 1: one NEE
 *    sample, MIS with BSDF sampling), with power-proportional light selection (the
 *    papers' baseline, the baseline the papers name) and with valo's default light grid;
 *  - global illumination: restir-gi against path (both with the light grid).
 * restir draws its candidates from the default light grid as well.
 * For each: per-frame relMSE at 1 sample per pixel per frame (the baseline given as many
 * samples per pixel as fit in restir's frame time, at least 1), the relMSE of the image
 * accumulated over an equal total time, and temporal stability on a static camera (mean
 * over pixels of |f_k - f_(k-1)| / (f_k + f_(k-1) + 0.01), luminance, over a sequence).
 * relMSE: mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01), pixels that see
 * a lamp (and their neighbours) left out: lamps smaller than a pixel are equally noisy
 * for every method.
 * References (bench/references, commands in docs/performance.md): path at high spp.
 * Scenes: the room (scenes/manylight.json), Sponza with lamps, and the walls room
 * (bench/manylight-walls.json: 1 536 lamps 1/1000 of the room's width off its walls and
 * ceiling; references bench/references/manylight-walls-{direct,path}.exr: valo `path
 * [--max-depth 1]` at 8 192 spp with the light grid, see docs/performance.md for why not
 * Mitsuba 3 here).
 * Usage: bench_restir [--quick] [--only room|sponza|walls] [--seconds S] [--params "K=V ..."]
 * [--stills di|gi|both] [--frames di|gi|both]
 * [--scene FILE WxH REF_DIRECT.exr [REF_PATH.exr]] (another scene instead: the held-out
 * rooms of tools/gen_manylight.c `heldout`, references made as docs/performance.md says)
 * (--params: restir parameters for every restir run, before each run's own; --stills:
 * only the accumulated stills, of restir-di, restir-gi or both; --frames: only the
 * per-frame measures) */
#include "valo/valo.h"
#include "bench_util.h"
#include "image/image_io.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifndef VALO_SOURCE_DIR
#define VALO_SOURCE_DIR "."
#endif


typedef struct scene_def { const char *name, *file, *ref_direct, *ref_path; int w, h; } scene_def;

typedef struct job {
  const char *file, *integ, *params;
  int w, h, spp, frames, max_depth;
  double budget;
  uint64_t seed;
  /* out */
  double secs;
  float *px;            /* final film */
  float *seq[64];       /* a sequence's frames */
  int nseq;
  const char *lights;   /* light sampler ("power"), NULL: the default */
} job;

static valo_status grab(void *user, const valo_render *r, int f, valo_error *err) {
  (void)err; (void)f;
  job *j = user;
  if (j->nseq < 64) {
    j->seq[j->nseq] = malloc((size_t)j->w * j->h * 3 * sizeof(float));
    valo_render_pixels(r, j->seq[j->nseq]);
    j->nseq++;
  }
  return VALO_OK;
}

/* Runs j; secs excludes scene loading and the acceleration-structure build. */
static const char *g_params = ""; /* --params */
static int g_stills;               /* --stills: 1 direct light, 2 GI, 3 both; only the accumulated stills */
static int g_frames;               /* --frames: the same bits; only the per-frame measures */
static int run(job *j) {
  valo_error err;
  valo_scene *sc;
  if (valo_scene_load(j->file, &sc, &err)) { fprintf(stderr, "%s\n", err.message); return -1; }
  valo_options o;
  valo_options_init(&o);
  snprintf(o.integrator, sizeof o.integrator, "%s", j->integ);
  if (!strncmp(j->integ, "restir", 6)) snprintf(o.params, sizeof o.params, "%s %s", g_params, j->params ? j->params : "");
  else if (j->params) snprintf(o.params, sizeof o.params, "%s", j->params);
  o.width = j->w; o.height = j->h; o.spp = j->spp; o.threads = 2; o.seed = (int64_t)(j->seed ? j->seed : 5);
  if (j->max_depth >= 0) o.max_depth = j->max_depth;
  if (j->budget > 0) o.time_budget = j->budget;
  if (j->frames > 0) o.frames = j->frames;
  if (j->lights) snprintf(o.light_sampler, sizeof o.light_sampler, "%s", j->lights);
  valo_render *r;
  double t0 = bench_now();
  if (valo_render_create(sc, &o, &r, &err)) { fprintf(stderr, "%s\n", err.message); return -1; }
  j->nseq = 0;
  if (j->frames > 0) valo_render_on_frame(r, grab, j);
  if (valo_render_run(r, NULL, NULL, &err)) { fprintf(stderr, "%s\n", err.message); return -1; }
  valo_stats st;
  valo_render_stats(r, &st);
  j->secs = bench_now() - t0 - st.build_seconds;
  j->px = malloc((size_t)j->w * j->h * 3 * sizeof(float));
  valo_render_pixels(r, j->px);
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  return 0;
}
static void job_free(job *j) {
  free(j->px);
  for (int i = 0; i < j->nseq; i++) free(j->seq[i]);
}

static unsigned char *g_ok;
static double mean_ratio(const float *a, const float *b, int n) {
  double sa = 0, sb = 0;
  for (int i = 0; i < n; i++)
    if (!g_ok || g_ok[i]) for (int c = 0; c < 3; c++) { sa += a[3 * i + c]; sb += b[3 * i + c]; }
  return sa / sb;
}
static double flicker(const job *j, int n) {
  double s = 0;
  long cnt = 0;
  for (int k = 1; k < j->nseq; k++)
    for (int i = 0; i < n; i++) {
      if (g_ok && !g_ok[i]) continue;
      const float *a = &j->seq[k][3 * i], *b = &j->seq[k - 1][3 * i];
      double la = 0.2126 * a[0] + 0.7152 * a[1] + 0.0722 * a[2], lb = 0.2126 * b[0] + 0.7152 * b[1] + 0.0722 * b[2];
      s += fabs(la - lb) / (la + lb + 0.01);
      cnt++;
    }
  return cnt ? s / (double)cnt : 0;
}

/* A copy of the scene file without its camera animation (static-camera sequences). */
static int static_copy(const char *src, char *out, size_t n) {
  FILE *f = fopen(src, "rb");
  if (!f) return -1;
  static char buf[1 << 16];
  size_t len = fread(buf, 1, sizeof buf - 1, f);
  fclose(f);
  buf[len] = 0;
  char *k = strstr(buf, "\"keyframes\"");
  if (k) {
    /* cut from the comma before "keyframes" to its closing bracket */
    char *start = k;
    while (start > buf && *start != ',') start--;
    char *end = strchr(k, '[');
    for (int depth = 0; end && *end; end++) {
      if (*end == '[') depth++;
      else if (*end == ']' && --depth == 0) break;
    }
    if (!end || !*end) return -1;
    memmove(start, end + 1, strlen(end + 1) + 1);
  }
  const char *slash = strrchr(src, '/');
  snprintf(out, n, "%.*s/.bench-static-%s", slash ? (int)(slash - src) : 1, slash ? src : ".", slash ? slash + 1 : src);
  f = fopen(out, "wb");
  if (!f) return -1;
  fputs(buf, f);
  fclose(f);
  return 0;
}

static int bench_scene(const scene_def *sd, int quick, double seconds) {
  int n = sd->w * sd->h;
  char stat[1024];
  if (static_copy(sd->file, stat, sizeof stat)) { fprintf(stderr, "cannot copy %s\n", sd->file); return 1; }
  /* lamp mask: emission seen directly */
  job em = {stat, "path", NULL, sd->w, sd->h, 1024, 0, 0, 0, 1, 0, NULL, {NULL}, 0, NULL}; /* every pixel a lamp touches */
  if (run(&em)) return 1;
  g_ok = malloc((size_t)n);
  bench_lamp_mask(em.px, sd->w, sd->h, g_ok);
  job_free(&em);
  for (int gi = 0; gi < 2; gi++) {
    const char *refp = gi ? sd->ref_path : sd->ref_direct;
    if (!refp || (g_stills && !(g_stills & (1 << gi))) || (g_frames && !(g_frames & (1 << gi)))) continue;
    image ref;
    valo_error err;
    if (image_read(refp, &ref, &err) || ref.w != sd->w || ref.h != sd->h) { fprintf(stderr, "%s: %s\n", refp, err.message); return 1; }
    const char *integ = gi ? "restir-gi" : "restir-di";
    int depth = gi ? -1 : 1;
    printf("\n%s, %s against path%s (%dx%d, 2 threads)\n", sd->name, integ, gi ? "" : " --max-depth 1", sd->w, sd->h);
    if (!g_stills) {
      /* time per frame (a static-camera sequence) and per baseline sample */
      int nf = quick ? 4 : 16;
      job rt = {stat, integ, NULL, sd->w, sd->h, 1, nf, -1, 0, 3, 0, NULL, {NULL}, 0, NULL};
      job rt0 = {stat, integ, "temporal=0", sd->w, sd->h, 1, nf, -1, 0, 3, 0, NULL, {NULL}, 0, NULL};
      job pt = {stat, "path", NULL, sd->w, sd->h, nf, 0, depth, 0, 3, 0, NULL, {NULL}, 0, "power"};
      job gt = {stat, "path", NULL, sd->w, sd->h, nf, 0, depth, 0, 3, 0, NULL, {NULL}, 0, NULL};
      /* best of three, alternating (the machine's load varies between runs) */
      double best[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
      job *tj[4] = {&rt, &rt0, &pt, &gt};
      for (int rep = 0; rep < 3; rep++)
        for (int k = 0; k < 4; k++) {
          if (rep) job_free(tj[k]);
          if (run(tj[k])) return 1;
          if (tj[k]->secs < best[k]) best[k] = tj[k]->secs;
        }
      double t_frame = best[0] / nf, t_frame0 = best[1] / nf, t_spp = best[2] / nf, t_gspp = best[3] / nf;
      int base_spp = (int)lround(t_frame / t_spp), gbase_spp = (int)lround(t_frame / t_gspp);
      if (base_spp < 1) base_spp = 1;
      if (gbase_spp < 1) gbase_spp = 1;
      job_free(&rt); job_free(&rt0); job_free(&pt); job_free(&gt);
      /* per frame: a static-camera sequence; the last frame (history built) */
      int seqn = quick ? 8 : 24;
      job rs = {stat, integ, NULL, sd->w, sd->h, 1, seqn, -1, 0, 7, 0, NULL, {NULL}, 0, NULL};
      job rs0 = {stat, integ, "temporal=0", sd->w, sd->h, 1, seqn, -1, 0, 7, 0, NULL, {NULL}, 0, NULL};
      job ris = {stat, integ, "temporal=0 iterations=0", sd->w, sd->h, 1, 1, -1, 0, 7, 0, NULL, {NULL}, 0, NULL};
      job rsp = {stat, integ, NULL, sd->w, sd->h, 1, seqn, -1, 0, 7, 0, NULL, {NULL}, 0, "power"};
      job ps = {stat, "path", NULL, sd->w, sd->h, base_spp, seqn, depth, 0, 7, 0, NULL, {NULL}, 0, "power"};
      job gs = {stat, "path", NULL, sd->w, sd->h, gbase_spp, seqn, depth, 0, 7, 0, NULL, {NULL}, 0, NULL};
      if (run(&rs) || run(&rs0) || run(&ris) || run(&rsp) || run(&ps) || run(&gs)) return 1;
      double e_rs = 0, e_rs0 = 0, e_rsp = 0, e_ps = 0, e_gs = 0;
      int last = 4 < rs.nseq ? 4 : rs.nseq;
      for (int k = rs.nseq - last; k < rs.nseq; k++) {
        e_rs += bench_relmse(rs.seq[k], ref.rgb, n, g_ok) / last;
        e_rs0 += bench_relmse(rs0.seq[k], ref.rgb, n, g_ok) / last;
        e_rsp += bench_relmse(rsp.seq[k], ref.rgb, n, g_ok) / last;
        e_ps += bench_relmse(ps.seq[k], ref.rgb, n, g_ok) / last;
        e_gs += bench_relmse(gs.seq[k], ref.rgb, n, g_ok) / last;
      }
      double e_ris = bench_relmse(ris.seq[0], ref.rgb, n, g_ok);
      printf("  time per frame: %s %.3f s; path %.3f s per spp with power selection, %.3f s with the light grid -> baselines %d and %d spp per frame\n",
             integ, t_frame, t_spp, t_gspp, base_spp, gbase_spp);
      printf("  per-frame relMSE (last %d of %d static frames): %s %.4g, without temporal %.4g, no reuse (RIS only) %.4g, candidates by power %.4g;"
             " path (power) %d spp %.4g; path (grid) %d spp %.4g\n",
             last, seqn, integ, e_rs, e_rs0, e_ris, e_rsp, base_spp, e_ps, gbase_spp, e_gs);
      printf("  per-frame ratio path (power) / %s: %.2f (spatial only: %.2f); path (grid) / %s: %.2f\n", integ, e_ps / e_rs, e_ps / e_rs0, integ,
             e_gs / e_rs);
      /* one frame without history at its own cost: path (grid) at the samples that fit in
       * that time, its relMSE scaled from them to the time */
      int spp0 = (int)lround(t_frame0 / t_gspp);
      if (spp0 < 1) spp0 = 1;
      double e_g0 = e_gs;
      if (spp0 != gbase_spp) {
        job g0 = {stat, "path", NULL, sd->w, sd->h, spp0, seqn, depth, 0, 7, 0, NULL, {NULL}, 0, NULL};
        if (run(&g0)) return 1;
        e_g0 = 0;
        for (int k = g0.nseq - last; k < g0.nseq; k++) e_g0 += bench_relmse(g0.seq[k], ref.rgb, n, g_ok) / last;
        job_free(&g0);
      }
      e_g0 *= spp0 * t_gspp / t_frame0;
      printf("  one frame without history: %s %.3f s, relMSE %.4g; path (grid) in that time (scaled from %d spp) %.4g; ratio %.2f\n", integ,
             t_frame0, e_rs0, spp0, e_g0, e_g0 / e_rs0);
      printf("  temporal stability (mean relative frame-to-frame change): %s %.4f, without temporal %.4f, path (power) %.4f, path (grid) %.4f\n", integ,
             flicker(&rs, n), flicker(&rs0, n), flicker(&ps, n), flicker(&gs, n));
      job_free(&rs); job_free(&rs0); job_free(&ris); job_free(&rsp); job_free(&ps); job_free(&gs);
    }
    /* accumulated at equal time: a still (frames averaged) against path with the same budget */
    if (g_frames) { image_free(&ref); continue; }
    double T = seconds > 0 ? seconds : (quick ? 2.0 : 10.0);
    job ra = {stat, integ, NULL, sd->w, sd->h, 1048576, 0, -1, T, 11, 0, NULL, {NULL}, 0, NULL};
    job pa = {stat, "path", NULL, sd->w, sd->h, 1048576, 0, depth, T, 11, 0, NULL, {NULL}, 0, "power"};
    job ga = {stat, "path", NULL, sd->w, sd->h, 1048576, 0, depth, T, 11, 0, NULL, {NULL}, 0, NULL};
    if (run(&ra) || run(&pa) || run(&ga)) return 1;
    double ea = bench_relmse(ra.px, ref.rgb, n, g_ok), epa = bench_relmse(pa.px, ref.rgb, n, g_ok), ega = bench_relmse(ga.px, ref.rgb, n, g_ok);
    printf("  accumulated over %.0f s: %s relMSE %.4g (mean ratio %.4f), path (power) %.4g (mean ratio %.4f), path (grid) %.4g (mean ratio %.4f);"
           " ratios path / %s: %.2f (power), %.2f (grid)\n",
           T, integ, ea, mean_ratio(ra.px, ref.rgb, n), epa, mean_ratio(pa.px, ref.rgb, n), ega, mean_ratio(ga.px, ref.rgb, n), integ, epa / ea,
           ega / ea);
    job_free(&ga);
    job_free(&ra); job_free(&pa);
    image_free(&ref);
  }
  remove(stat);
  free(g_ok);
  g_ok = NULL;
  return 0;
}

int main(int argc, char **argv) {
  int quick = 0;
  const char *only = NULL;
  scene_def own = {NULL, NULL, NULL, NULL, 0, 0};
  double seconds = 0;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick")) quick = 1;
    else if (!strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
    else if (!strcmp(argv[i], "--seconds") && i + 1 < argc) seconds = atof(argv[++i]);
    else if (!strcmp(argv[i], "--params") && i + 1 < argc) g_params = argv[++i];
    else if (!strcmp(argv[i], "--scene") && i + 3 < argc) {
      own.name = own.file = argv[++i];
      if (sscanf(argv[++i], "%dx%d", &own.w, &own.h) != 2) { fprintf(stderr, "--scene: %s is not WxH\n", argv[i]); return 2; }
      own.ref_direct = argv[++i];
      if (i + 1 < argc && strncmp(argv[i + 1], "--", 2)) own.ref_path = argv[++i];
    }
    else if ((!strcmp(argv[i], "--stills") || !strcmp(argv[i], "--frames")) && i + 1 < argc) {
      const char *w = argv[++i];
      int bits = !strcmp(w, "di") ? 1 : !strcmp(w, "gi") ? 2 : !strcmp(w, "both") ? 3 : 0;
      if (!bits) { fprintf(stderr, "%s: di, gi or both\n", argv[i - 1]); return 2; }
      *(!strcmp(argv[i - 1], "--stills") ? &g_stills : &g_frames) = bits;
    }
    else { fprintf(stderr, "usage: bench_restir [--quick] [--only room|sponza|walls] [--seconds S] [--params \"K=V ...\"] [--stills di|gi|both] [--frames di|gi|both] [--scene FILE WxH REF_DIRECT.exr [REF_PATH.exr]]\n"); return 2; }
  }
  if (own.file) return bench_scene(&own, quick, seconds) != 0;
  static const char *names[3] = {"room", "sponza", "walls"};
  const scene_def scenes[3] = {
      {"room (scenes/manylight.json, 1 024 lamps)", VALO_SOURCE_DIR "/scenes/manylight.json", VALO_SOURCE_DIR "/bench/references/manylight-room-direct.exr",
       VALO_SOURCE_DIR "/bench/references/manylight-room-path.exr", 160, 120},
      {"Sponza with 1 200 lamps (bench/sponza-lamps.json)", VALO_SOURCE_DIR "/bench/sponza-lamps.json",
       VALO_SOURCE_DIR "/bench/references/sponza-lamps-direct.exr", VALO_SOURCE_DIR "/bench/references/sponza-lamps-path.exr", 320, 180},
      {"walls room (bench/manylight-walls.json, 1 536 lamps 1/1000 of its width off the walls)", VALO_SOURCE_DIR "/bench/manylight-walls.json",
       VALO_SOURCE_DIR "/bench/references/manylight-walls-direct.exr", VALO_SOURCE_DIR "/bench/references/manylight-walls-path.exr", 256, 192}};
  for (int s = 0; s < 3; s++) {
    if (only && strcmp(only, names[s])) continue;
    if (bench_scene(&scenes[s], quick, seconds)) return 1;
  }
  return 0;
}
