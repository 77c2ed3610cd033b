/* compare.c — owns `valo compare`: one scene rendered by several integrators at equal time
 * (--time) or equal samples (--spp), each image kept at several moments of its run so
 * its error can be plotted against time; relMSE and mean bias against a reference EXR
 * (or the longest of the renders); the outputs in one folder: NAME.exr and NAME.png per
 * integrator, NAME_error.png (the per-pixel error as a heat map), NAME_crop.png (the crop),
 * summary.json and index.html (report.c). A progress line per render on a terminal;
 * Ctrl-C stops with exit 130 and no report. Uses only the public API. */
#include "cli/compare.h"
#include "cli/args.h"
#include "cli/report.h"
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <unistd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>

static void usage_compare(FILE *f) {
  fprintf(f,
          "Usage: valo compare SCENE --integrators A,B,... (--time SECONDS | --spp N) -o DIR [options]\n\n"
          "Renders SCENE with each integrator at equal time (or equal samples per pixel) and\n"
          "writes DIR/NAME.exr and .png per integrator, DIR/summary.json and DIR/index.html:\n"
          "the images side by side, a zoomed crop, per-pixel error heat maps, relMSE against\n"
          "time (log-log, SVG) and a table of time, spp, rays/s, relMSE and mean bias.\n\n"
          "  --integrators LIST     comma-separated integrator names (valo render --help-integrators)\n"
          "  --reference FILE       the reference image (EXR, PFM or HDR) at the render's size;\n"
          "                         without it, the longest render is the reference\n"
          "  --crop X,Y,W,H         the zoomed crop (default: the window where the images differ most)\n"
          "  -o DIR                 the report's folder (made when missing)\n"
          "  any `valo render` option: --time, --spp, --res, --threads, --seed, --param, ...\n\n"
          "relMSE: the mean over pixels and channels of (x - r)^2 / (r^2 + 0.01).\n");
}

/* relMSE of img against ref (n pixels), and the mean bias (mean(img) - mean(ref)) /
 * mean(ref) over all channels. */
static double relmse(const float *img, const float *ref, size_t n, double *bias) {
  double e = 0, si = 0, sr = 0;
  for (size_t i = 0; i < 3 * n; i++) {
    double d = (double)img[i] - (double)ref[i];
    e += d * d / ((double)ref[i] * ref[i] + 0.01);
    si += img[i];
    sr += ref[i];
  }
  if (bias) *bias = sr > 0 ? (si - sr) / sr : 0;
  return e / (3.0 * (double)n);
}

typedef struct snap_state { valo_render *r; cmp_run *run; size_t np; const float *ref; double next; int tty, index, count; } snap_state;

static volatile sig_atomic_t g_stop;
static void on_sigint(int sig) {
  (void)sig;
  if (g_stop) _exit(130);
  g_stop = 1;
}

/* The progress callback: at moments growing by 1.5x from 0.05 s, the error against the
 * reference file, or (none given) the image, until the reference is known. */
static int on_progress(void *user, double frac, int spp, double seconds) {
  snap_state *s = user;
  cmp_run *run = s->run;
  if (s->tty) {
    fprintf(stderr, "\rvalo: [%d/%d] %-12s %3d%%  %d spp  %.1f s ", s->index + 1, s->count, run->name, (int)(frac * 100 + 0.5), spp, seconds);
    fflush(stderr);
  }
  if (g_stop) return 1;
  if (seconds < s->next || run->nsnap >= CMP_MAX_SNAPS) return 0;
  float *px = malloc(s->np * 3 * sizeof *px);
  if (!px) return 0;
  valo_render_pixels(s->r, px);
  if (s->ref) {
    run->snap_err[run->nsnap] = relmse(px, s->ref, s->np, NULL);
    free(px);
    px = NULL;
  }
  run->snap[run->nsnap] = px;
  run->snap_t[run->nsnap] = seconds;
  run->snap_spp[run->nsnap] = spp;
  run->nsnap++;
  while (s->next <= seconds) s->next *= 1.5;
  return 0;
}

/* Renders one integrator; fills run (pixels, figures, moments). 0 or an exit code. */
static int render_one(valo_scene *sc, valo_options opt, const char *name, const char *dir, const float *ref, int index, int count, cmp_run *run,
                      cmp_run *dn) {
  snprintf(opt.integrator, sizeof opt.integrator, "%s", name);
  snprintf(run->name, sizeof run->name, "%s", name);
  valo_error err;
  valo_render *r = NULL;
  if (valo_render_create(sc, &opt, &r, &err)) {
    fprintf(stderr, "valo: error: %s: %s\n", name, err.message);
    return 1;
  }
  valo_stats st;
  valo_render_stats(r, &st);
  if (ref && (st.width != run->w || st.height != run->h)) {
    fprintf(stderr, "valo: error: the reference is %dx%d, the renders %dx%d\n", run->w, run->h, st.width, st.height);
    valo_render_destroy(r);
    return 1;
  }
  run->w = st.width;
  run->h = st.height;
  size_t np = (size_t)st.width * st.height;
  snap_state ss = {r, run, np, ref, 0.05, isatty(2), index, count};
  valo_status rs = valo_render_run(r, on_progress, &ss, &err);
  if (ss.tty) fprintf(stderr, "\n");
  if (rs == VALO_ERR_CANCELLED || g_stop) {
    fprintf(stderr, "valo: interrupted during %s; no report written\n", name);
    valo_render_destroy(r);
    return 130;
  }
  if (rs) {
    fprintf(stderr, "valo: error: %s: %s\n", name, err.message);
    valo_render_destroy(r);
    return 1;
  }
  valo_render_stats(r, &st);
  run->seconds = st.render_seconds;
  run->spp = st.spp_done;
  run->rays = st.rays;
  run->px = malloc(np * 3 * sizeof *run->px);
  if (!run->px) { valo_render_destroy(r); fprintf(stderr, "valo: error: out of memory\n"); return 1; }
  valo_render_pixels(r, run->px);
  /* the final image is the last moment of the plot */
  if (run->nsnap < CMP_MAX_SNAPS && (run->nsnap == 0 || run->snap_spp[run->nsnap - 1] != st.spp_done)) {
    run->snap[run->nsnap] = NULL;
    if (ref) run->snap_err[run->nsnap] = relmse(run->px, ref, np, NULL);
    else if ((run->snap[run->nsnap] = malloc(np * 3 * sizeof(float)))) memcpy(run->snap[run->nsnap], run->px, np * 3 * sizeof(float));
    if (ref || run->snap[run->nsnap]) {
      run->snap_t[run->nsnap] = st.render_seconds;
      run->snap_spp[run->nsnap] = st.spp_done;
      run->nsnap++;
    }
  }
  valo_output_options oo;
  valo_output_options_init(&oo);
  const char *ext[2] = {"exr", "png"};
  for (int k = 0; k < 2; k++) {
    char path[4400];
    snprintf(path, sizeof path, "%s/%s.%s", dir, name, ext[k]);
    if (valo_render_write(r, path, &oo, &err)) { fprintf(stderr, "valo: error: %s\n", err.message); valo_render_destroy(r); return 1; }
  }
  fprintf(stderr, "valo: %s: %.2f s, %d spp, %.3g rays\n", name, run->seconds, run->spp, (double)run->rays);
  if (dn) { /* --denoise: the same render denoised, an entry of its own (its time includes the filter's) */
    *dn = *run;
    memset(dn->snap, 0, sizeof dn->snap);
    snprintf(dn->name, sizeof dn->name, "%.20s+denoised", name);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    dn->px = malloc(np * 3 * sizeof *dn->px);
    if (!dn->px || valo_render_layer(r, "denoised", dn->px, &err)) {
      fprintf(stderr, "valo: error: %s\n", dn->px ? err.message : "out of memory");
      valo_render_destroy(r);
      return 1;
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    dn->seconds += (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    dn->nsnap = 0;
    dn->snap_t[0] = dn->seconds;
    dn->snap_spp[0] = dn->spp;
    if (ref) { dn->snap_err[0] = relmse(dn->px, ref, np, NULL); dn->nsnap = 1; }
    else if ((dn->snap[0] = malloc(np * 3 * sizeof(float)))) { memcpy(dn->snap[0], dn->px, np * 3 * sizeof(float)); dn->nsnap = 1; }
    for (int k = 0; k < 2; k++) {
      char path[4400];
      snprintf(path, sizeof path, "denoised:%s/%s.%s", dir, dn->name, ext[k]);
      if (valo_render_write(r, path, &oo, &err)) { fprintf(stderr, "valo: error: %s\n", err.message); valo_render_destroy(r); return 1; }
    }
    fprintf(stderr, "valo: %s: %.2f s\n", dn->name, dn->seconds);
  }
  valo_render_destroy(r);
  return 0;
}

/* The crop window (1/6 of the width, the film's aspect) where the images differ most from
 * the reference, summed over integrators, on a grid of half-window steps. */
static void worst_crop(const cmp_report *rep, const float *ref, int crop[4]) {
  int w = rep->runs[0].w, h = rep->runs[0].h;
  int cw = w / 6 > 8 ? w / 6 : (w < 8 ? w : 8), ch = cw * h / w > 0 ? cw * h / w : 1;
  double best = -1;
  crop[0] = 0; crop[1] = 0; crop[2] = cw; crop[3] = ch;
  for (int y = 0; y + ch <= h; y += ch / 2 > 0 ? ch / 2 : 1)
    for (int x = 0; x + cw <= w; x += cw / 2 > 0 ? cw / 2 : 1) {
      double e = 0;
      for (int k = 0; k < rep->nruns; k++)
        for (int yy = y; yy < y + ch; yy++)
          for (int xx = x; xx < x + cw; xx++)
            for (int c = 0; c < 3; c++) {
              size_t i = 3 * ((size_t)yy * w + xx) + c;
              double d = (double)rep->runs[k].px[i] - ref[i];
              e += d * d / ((double)ref[i] * ref[i] + 0.01);
            }
      if (e > best) { best = e; crop[0] = x; crop[1] = y; }
    }
}

/* Writes NAME_error.png (log10 of the per-pixel relative squared error, 1e-4 .. 1, as a
 * dark-blue to yellow ramp) and NAME_crop.png (the crop, each pixel 4x4). */
static int write_maps(const cmp_report *rep, const cmp_run *run, const float *ref, const char *dir) {
  int w = run->w, h = run->h;
  float *m = malloc((size_t)w * h * 3 * sizeof *m);
  int cw = rep->crop[2], ch = rep->crop[3], z = 4;
  float *c = malloc((size_t)cw * ch * z * z * 3 * sizeof *c);
  if (!m || !c) { free(m); free(c); return 1; }
  for (size_t i = 0; i < (size_t)w * h; i++) {
    double e = 0;
    for (int k = 0; k < 3; k++) {
      double d = (double)run->px[3 * i + k] - ref[3 * i + k];
      e += d * d / ((double)ref[3 * i + k] * ref[3 * i + k] + 0.01) / 3;
    }
    double t = e > 0 ? (log10(e) + 4) / 4 : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    /* linear values whose sRGB encoding runs dark blue, magenta, orange, yellow */
    m[3 * i] = (float)pow(t, 1.2);
    m[3 * i + 1] = (float)(t * t * t);
    m[3 * i + 2] = (float)(0.3 * (1 - t) * (0.2 + t));
  }
  for (int y = 0; y < ch * z; y++)
    for (int x = 0; x < cw * z; x++)
      for (int k = 0; k < 3; k++)
        c[3 * ((size_t)y * cw * z + x) + k] = run->px[3 * ((size_t)(rep->crop[1] + y / z) * w + rep->crop[0] + x / z) + k];
  valo_output_options oo;
  valo_output_options_init(&oo);
  char path[4400];
  valo_error err;
  int bad = 0;
  snprintf(path, sizeof path, "%s/%s_error.png", dir, run->name);
  if (valo_image_write(path, w, h, m, &oo, &err)) { fprintf(stderr, "valo: error: %s\n", err.message); bad = 1; }
  snprintf(path, sizeof path, "%s/%s_crop.png", dir, run->name);
  if (!bad && valo_image_write(path, cw * z, ch * z, c, &oo, &err)) { fprintf(stderr, "valo: error: %s\n", err.message); bad = 1; }
  free(m);
  free(c);
  return bad;
}

int cmd_compare(int argc, char **argv) {
  static const char *const own[] = {"--integrators", "--reference", "-o", "--output", "--crop", NULL};
  const char *val[5] = {NULL, NULL, NULL, NULL, NULL};
  cli_args ca;
  int prc = cli_parse_with_own(argc, argv, own, val, &ca, stderr);
  if (prc == CLI_HELP) { usage_compare(stdout); return 0; }
  if (prc >= 0) return prc;
  const char *list = val[0], *refpath = val[1], *dir = val[2] ? val[2] : val[3], *crop_s = val[4];
  if (!list || !dir) { fprintf(stderr, "valo: compare needs --integrators and -o DIR\n"); usage_compare(stderr); return EXIT_USAGE; }
  if (ca.opt.time_budget == VALO_UNSET && ca.opt.spp == VALO_UNSET) {
    fprintf(stderr, "valo: compare needs a budget that is the same for every integrator: --time SECONDS or --spp N\n");
    return EXIT_USAGE;
  }
  int crop[4] = {0, 0, 0, 0}, have_crop = 0;
  if (crop_s) {
    if (sscanf(crop_s, "%d,%d,%d,%d", &crop[0], &crop[1], &crop[2], &crop[3]) != 4 || crop[0] < 0 || crop[1] < 0 || crop[2] < 1 || crop[3] < 1) {
      fprintf(stderr, "valo: --crop: \"%s\" is not X,Y,W,H (W and H at least 1)\n", crop_s);
      return EXIT_USAGE;
    }
    have_crop = 1;
  }
  cmp_report rep;
  memset(&rep, 0, sizeof rep);
  char names[CMP_MAX_RUNS][32];
  for (const char *p = list; *p;) {
    const char *e = strchr(p, ',');
    size_t len = e ? (size_t)(e - p) : strlen(p);
    if (rep.nruns == (ca.denoise ? CMP_MAX_RUNS / 2 : CMP_MAX_RUNS)) {
      fprintf(stderr, "valo: at most %d integrators%s\n", ca.denoise ? CMP_MAX_RUNS / 2 : CMP_MAX_RUNS, ca.denoise ? " with --denoise" : "");
      return EXIT_USAGE;
    }
    int known = 0;
    for (const char *const *n = valo_integrator_names(); *n; n++) known |= strlen(*n) == len && !strncmp(*n, p, len);
    if (!known || len >= sizeof names[0]) {
      fprintf(stderr, "valo: --integrators: unknown integrator \"%.*s\" (valo render --help-integrators lists them)\n", (int)len, p);
      return EXIT_USAGE;
    }
    snprintf(names[rep.nruns++], sizeof names[0], "%.*s", (int)len, p);
    p = e ? e + 1 : p + len;
  }
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_sigint;
  sigaction(SIGINT, &sa, NULL); /* Ctrl-C: the render stops, no report; twice: at once */
  if (mkdir(dir, 0755) != 0 && errno != EEXIST) { fprintf(stderr, "valo: error: %s: cannot make the folder: %s\n", dir, strerror(errno)); return 1; }
  valo_error err;
  valo_scene *sc = NULL;
  if (valo_scene_load_with(ca.scene_path, &ca.lo, &sc, &err)) { fprintf(stderr, "valo: error: %s\n", err.message); return 1; }
  valo_options opt = ca.opt;
  if (opt.time_budget > 0 && opt.spp == VALO_UNSET) opt.spp = 1048576;
  int rc = 0;
  float *ref = NULL;
  int rw = 0, rh = 0;
  if (refpath) {
    /* the reference first: a wrong size is said before the first render runs, and each
     * run's error is taken as it goes */
    if (valo_image_read(refpath, &rw, &rh, &ref, &err)) { fprintf(stderr, "valo: error: %s\n", err.message); rc = 1; }
    snprintf(rep.reference, sizeof rep.reference, "%s", refpath);
  }
  int nint = rep.nruns, per = ca.denoise ? 2 : 1;
  if (ca.denoise) opt.aovs = (opt.aovs > 0 ? opt.aovs : 1) | VALO_AOVS_VARIANCE;
  rep.nruns = 0;
  for (int k = 0; k < nint && !rc; k++) {
    cmp_run *run = &rep.runs[per * k];
    run->w = rw;
    run->h = rh;
    rc = render_one(sc, opt, names[k], dir, ref, k, nint, run, ca.denoise ? run + 1 : NULL);
    rep.nruns += per; /* counted even when it failed or was interrupted: the cleanup frees what it holds */
  }
  valo_scene_destroy(sc);
  if (!rc && !refpath) {
    int longest = 0;
    for (int k = per; k < rep.nruns; k += per) /* a denoised image is never the reference */
      if (rep.runs[k].seconds > rep.runs[longest].seconds) longest = k;
    rep.ref_run = longest + 1;
  }
  if (!rc) {
    const float *r = ref ? ref : rep.runs[rep.ref_run - 1].px;
    size_t np = (size_t)rep.runs[0].w * rep.runs[0].h;
    for (int k = 0; k < rep.nruns; k++) {
      cmp_run *run = &rep.runs[k];
      run->relmse = relmse(run->px, r, np, &run->bias);
      for (int s = 0; s < run->nsnap; s++)
        if (run->snap[s]) run->snap_err[s] = relmse(run->snap[s], r, np, NULL);
    }
    if (have_crop) {
      if (crop[0] + crop[2] > rep.runs[0].w || crop[1] + crop[3] > rep.runs[0].h) {
        fprintf(stderr, "valo: --crop %s falls outside the %dx%d image\n", crop_s, rep.runs[0].w, rep.runs[0].h);
        rc = EXIT_USAGE;
      }
      memcpy(rep.crop, crop, sizeof crop);
    } else worst_crop(&rep, r, rep.crop);
    for (int k = 0; k < rep.nruns && !rc; k++) rc = write_maps(&rep, &rep.runs[k], r, dir);
    snprintf(rep.scene, sizeof rep.scene, "%s", ca.scene_path);
    rep.time_budget = opt.time_budget > 0 ? opt.time_budget : 0;
    rep.spp_budget = opt.time_budget > 0 ? 0 : opt.spp;
    if (!rc && (report_write_summary(&rep, dir) || report_write_html(&rep, dir))) rc = 1;
    if (!rc) fprintf(stderr, "valo: wrote %s/index.html and %s/summary.json\n", dir, dir);
  }
  valo_image_free(ref);
  for (int k = 0; k < rep.nruns; k++) {
    free(rep.runs[k].px);
    for (int s = 0; s < rep.runs[k].nsnap; s++) free(rep.runs[k].snap[s]);
  }
  return rc;
}
