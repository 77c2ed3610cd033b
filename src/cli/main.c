/* main.c — owns the `valo` command line: argument parsing, the progress bar (with
 * samples/s and ETA on a terminal, periodic plain lines otherwise), the final summary,
 * Ctrl-C handling and exit codes (0 success, 1 error, 2 usage, 130 interrupted).
 * Uses only the public API in valo/valo.h. */
#include "valo/valo.h"
#include "cli/run_stats.h"
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define EXIT_USAGE 2
#define EXIT_INTERRUPTED 130
#define MAX_OUTPUTS 16

static valo_render *volatile g_render;
static volatile sig_atomic_t g_interrupted;

/* First Ctrl-C: stop after the tiles in flight and write what is finished. Second:
 * leave at once without writing. */
static void on_sigint(int sig) {
  (void)sig;
  if (g_interrupted) _exit(EXIT_INTERRUPTED);
  g_interrupted = 1;
  if (g_render) valo_render_cancel(g_render);
}

static void usage_main(FILE *f) {
  fprintf(f,
          "valo %s — physically based global-illumination renderer\n\n"
          "Usage:\n"
          "  valo render SCENE [options]   render a scene (JSON scene file, or an OBJ/glTF/PLY mesh)\n"
          "  valo --help                   this text\n"
          "  valo render --help            the render options\n"
          "  valo --version                print the version\n\n"
          "Exit codes: 0 success, 1 error (bad input, failed write), 2 usage error, 130 interrupted.\n",
          valo_version());
}

static void usage_render(FILE *f) {
  fprintf(f,
          "Usage: valo render SCENE [options]\n\n"
          "SCENE is a .json scene file (docs/scene-format.md) or a mesh file read by Assimp\n"
          "(OBJ/MTL, glTF 2.0, PLY, ...; its camera is used, or the view is framed automatically).\n"
          "Options override the scene file:\n"
          "  -o, --output FILE      output image; .exr/.pfm linear float, .png 8-bit sRGB;\n"
          "                         repeat for several outputs (default: SCENE-NAME.png);\n"
          "                         albedo:FILE, normal:FILE, depth:FILE write those AOVs,\n"
          "                         ao:FILE ambient occlusion (ao.distance), bent:FILE the bent normal,\n"
          "                         spp:FILE the samples each pixel received\n");
  /* the declared options (one table: their flags, defaults, ranges and help) */
  for (int i = 0; valo_option_at(i); i++) {
    const valo_option_info *o = valo_option_at(i);
    if (!o->flag) continue;
    char head[64];
    snprintf(head, sizeof head, "%s%s%s", o->flag, o->metavar ? " " : "", o->metavar ? o->metavar : "");
    const char *h = o->help;
    int first = 1;
    while (*h) {
      size_t n = strcspn(h, "\n");
      fprintf(f, "  %-22s %.*s\n", first ? head : "", (int)n, h);
      first = 0;
      h += n;
      if (*h) h++;
    }
    if (!strcmp(o->flag, "--integrator")) {
      fprintf(f, "  %-22s one of:", "");
      for (const char *const *n = valo_integrator_names(); *n; n++) fprintf(f, " %s", *n);
      fprintf(f, "\n");
    }
  }
  fprintf(f,
          "  --checkpoint FILE      save the render's state to FILE at pass boundaries (atomically)\n"
          "  --checkpoint-every S   at most every S seconds (default 60; 0: every pass)\n"
          "  --resume FILE          go on from a checkpoint (and keep checkpointing to it);\n"
          "                         the same scene and options; --time is this run's budget\n"
          "  --stats-json FILE      write the run's figures as JSON: load, build and render\n"
          "                         seconds, spp, rays, rays/s, peak memory, lost samples\n"
          "  --help-integrators     the integrators' parameters, with defaults and ranges\n"
          "  -q, --quiet            no progress or summary\n"
          "  -h, --help             this text\n");
}

/* Length of an output's AOV prefix ("albedo:", "normal:", "depth:", "spp:"), or 0. */
static size_t aov_prefix(const char *out) {
  static const char *const prefixes[] = {"albedo:", "normal:", "depth:", "ao:", "bent:", "spp:"};
  for (size_t k = 0; k < sizeof prefixes / sizeof prefixes[0]; k++)
    if (!strncmp(out, prefixes[k], strlen(prefixes[k]))) return strlen(prefixes[k]);
  return 0;
}

typedef struct progress_state { int tty; int quiet; double last_print; int spp_total; double time_budget; int frames; } progress_state;

/* Where the frame number goes in an output name: a "%d" or "%0Nd" (N < 10). Returns the
 * offset of the '%' and the conversion's length in *len, -1 when there is none, -2 when
 * the name has another '%' (not allowed). */
static int frame_pattern(const char *name, int *len) {
  const char *p = strchr(name, '%');
  if (!p) return -1;
  const char *q = p + 1;
  if (*q == '0') { q++; if (*q >= '1' && *q <= '9') q++; else return -2; }
  if (*q != 'd' || strchr(q + 1, '%')) return -2;
  *len = (int)(q + 1 - p);
  return (int)(p - name);
}
/* name with its frame pattern replaced by frame f. */
static void frame_name(const char *name, int f, char *out, size_t n) {
  int len, at = frame_pattern(name, &len);
  if (at < 0) { snprintf(out, n, "%s", name); return; }
  int width = len > 2 ? name[at + 2] - '0' : 0;
  snprintf(out, n, "%.*s%0*d%s", at, name, width, f, name + at + len);
}

typedef struct frame_out { const char *const *outputs; int nout; int frames; int quiet; const valo_output_options *oo; } frame_out;
/* The frame callback: writes the outputs with a frame pattern, and at the last frame the
 * plain ones. */
static valo_status write_frame(void *user, const valo_render *r, int f, valo_error *err) {
  const frame_out *fo = user;
  for (int i = 0; i < fo->nout; i++) {
    int len, pat = frame_pattern(fo->outputs[i], &len) >= 0;
    if (!pat && f != fo->frames - 1) continue;
    char name[4096];
    frame_name(fo->outputs[i], f, name, sizeof name);
    valo_status st = valo_render_write(r, name, fo->oo, err);
    if (st) return st;
    if (!fo->quiet && !isatty(2)) fprintf(stderr, "valo: wrote %s (frame %d)\n", name, f);
  }
  return VALO_OK;
}

static void fmt_time(double s, char *buf, size_t n) {
  if (!(s >= 0) || s > 1e7) { snprintf(buf, n, "--:--"); return; }
  long t = (long)(s + 0.5);
  if (t >= 3600) snprintf(buf, n, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  else snprintf(buf, n, "%02ld:%02ld", t / 60, t % 60);
}

static int on_progress(void *user, double frac, int spp_done, double seconds) {
  progress_state *p = user;
  if (p->quiet) return 0;
  double rate = seconds > 0 ? spp_done / seconds : 0;
  double eta = frac > 0 ? seconds * (1 - frac) / frac : -1;
  char e[32], el[32];
  fmt_time(eta, e, sizeof e);
  fmt_time(seconds, el, sizeof el);
  char sp[48];
  if (p->frames > 0) { snprintf(sp, sizeof sp, "frame %d/%d", (int)(frac * p->frames + 0.5), p->frames); rate = seconds > 0 ? frac * p->frames / seconds : 0; }
  else if (p->spp_total >= 1048576) snprintf(sp, sizeof sp, "%d spp", spp_done);
  else snprintf(sp, sizeof sp, "%d/%d spp", spp_done, p->spp_total);
  const char *unit = p->frames > 0 ? "frames/s" : "spp/s";
  if (p->tty) {
    int width = 30, fill = (int)(frac * width + 0.5);
    char bar[64];
    for (int i = 0; i < width; i++) bar[i] = i < fill ? '#' : '.';
    bar[width] = 0;
    fprintf(stderr, "\r[%s] %3d%%  %s  %.2f %s  elapsed %s  ETA %s ", bar, (int)(frac * 100 + 0.5), sp, rate, unit, el, e);
    fflush(stderr);
  } else if (seconds - p->last_print >= 5.0 || frac >= 1.0) {
    fprintf(stderr, "valo: %3d%% %s, %.2f %s, elapsed %s, ETA %s\n", (int)(frac * 100 + 0.5), sp, rate, unit, el, e);
    p->last_print = seconds;
  }
  return g_interrupted;
}

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmd_render(int argc, char **argv) {
  valo_options opt;
  valo_options_init(&opt);
  valo_output_options oo;
  valo_output_options_init(&oo);
  valo_load_options lo;
  valo_load_options_init(&lo);
  const char *scene_path = NULL, *outputs[MAX_OUTPUTS], *stats_json = NULL, *ckpt = NULL, *resume = NULL;
  double ckpt_every = 60;
  int nout = 0, quiet = 0;
  for (int i = 0; i < argc; i++) {
    const char *a = argv[i];
    const char *val = i + 1 < argc ? argv[i + 1] : NULL;
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) { usage_render(stdout); return 0; }
    if (!strcmp(a, "--help-integrators")) {
      char buf[8192];
      for (const char *const *n = valo_integrator_names(); *n; n++)
        if (!valo_integrator_describe(*n, buf, sizeof buf)) fputs(buf, stdout);
      return 0;
    }
    if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) { quiet = 1; continue; }
    if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
      if (!val) { fprintf(stderr, "valo: %s needs a value\n", a); return EXIT_USAGE; }
      i++;
      if (nout == MAX_OUTPUTS) { fprintf(stderr, "valo: at most %d outputs\n", MAX_OUTPUTS); return EXIT_USAGE; }
      outputs[nout++] = val;
      continue;
    }
    if (!strcmp(a, "--stats-json") || !strcmp(a, "--checkpoint") || !strcmp(a, "--resume") || !strcmp(a, "--checkpoint-every")) {
      if (!val) { fprintf(stderr, "valo: %s needs a value\n", a); return EXIT_USAGE; }
      i++;
      if (a[2] == 's') stats_json = val;
      else if (a[2] == 'r') resume = val;
      else if (!strcmp(a, "--checkpoint")) ckpt = val;
      else {
        char *end;
        ckpt_every = strtod(val, &end);
        if (end == val || *end || !(ckpt_every >= 0 && ckpt_every <= 1e9)) {
          fprintf(stderr, "valo: --checkpoint-every: \"%s\" is not a number of seconds from 0 to 1e9\n", val);
          return EXIT_USAGE;
        }
      }
      continue;
    }
    if (a[0] == '-' && a[1]) {
      /* a declared option (valo_option_at): a flag alone, or a flag and its value */
      const valo_option_info *info = NULL;
      for (int k = 0; valo_option_at(k); k++)
        if (valo_option_at(k)->flag && !strcmp(valo_option_at(k)->flag, a)) info = valo_option_at(k);
      if (!info) { fprintf(stderr, "valo: unknown option \"%s\" (see valo render --help)\n", a); return EXIT_USAGE; }
      if (info->metavar && !val) { fprintf(stderr, "valo: %s needs a value\n", a); return EXIT_USAGE; }
      valo_error perr;
      if (valo_option_set(a, info->metavar ? val : NULL, &opt, &lo, &oo, &perr)) {
        fprintf(stderr, "valo: %s: %s\n", a, perr.message);
        return EXIT_USAGE;
      }
      if (info->metavar) i++;
      continue;
    }
    if (!scene_path) scene_path = a;
    else { fprintf(stderr, "valo: more than one scene given (\"%s\" and \"%s\")\n", scene_path, a); return EXIT_USAGE; }
  }
  if (!scene_path) { fprintf(stderr, "valo: no scene given\n"); usage_render(stderr); return EXIT_USAGE; }
  if (opt.noise_threshold != VALO_UNSET && !(opt.adaptive > 0)) {
    opt.adaptive = VALO_ADAPTIVE_ERROR;
    if (!quiet) fprintf(stderr, "valo: note: --noise-threshold turns on adaptive sampling (--adaptive)\n");
  }
  char default_out[1024];
  if (nout == 0) {
    const char *base = strrchr(scene_path, '/');
    base = base ? base + 1 : scene_path;
    const char *dot = strrchr(base, '.');
    int len = dot ? (int)(dot - base) : (int)strlen(base);
    snprintf(default_out, sizeof default_out, "%.*s.png", len, base);
    outputs[nout++] = default_out;
  }
  int aovs = 0; /* the AOVs the outputs ask for */
  for (int i = 0; i < nout; i++) {
    if (aov_prefix(outputs[i]) && strncmp(outputs[i], "spp:", 4)) aovs |= 1;
    if (!strncmp(outputs[i], "ao:", 3) || !strncmp(outputs[i], "bent:", 5)) aovs |= VALO_AOVS_AO;
    int plen, pat = frame_pattern(outputs[i], &plen);
    if (pat == -2) { fprintf(stderr, "valo: %s: a '%%' in an output name must be a frame pattern, %%d or %%04d\n", outputs[i]); return EXIT_USAGE; }
    if (pat >= 0 && opt.frames == VALO_UNSET) { fprintf(stderr, "valo: %s: a frame pattern needs --frames\n", outputs[i]); return EXIT_USAGE; }
    const char *dot = strrchr(outputs[i], '.');
    if (!dot || (strcasecmp(dot, ".exr") && strcasecmp(dot, ".pfm") && strcasecmp(dot, ".png"))) {
      fprintf(stderr, "valo: %s: unknown output format (use .exr, .pfm or .png)\n", outputs[i]);
      return EXIT_USAGE;
    }
  }
  if (aovs) opt.aovs = aovs;

  if (resume && !ckpt) ckpt = resume; /* a resumed render keeps checkpointing to its file */
  /* Every output's folder must exist and be writable before hours of rendering. */
  const char *extra[2] = {stats_json, ckpt};
  for (int i = 0; i < nout + 2; i++) {
    if (i >= nout && !extra[i - nout]) continue;
    const char *file = i >= nout ? extra[i - nout] : outputs[i] + aov_prefix(outputs[i]);
    char dir[4096];
    const char *slash = strrchr(file, '/');
    if (slash) snprintf(dir, sizeof dir, "%.*s", slash == file ? 1 : (int)(slash - file), file);
    else snprintf(dir, sizeof dir, ".");
    if (access(dir, W_OK) != 0) {
      fprintf(stderr, "valo: error: %s: cannot write there: folder %s %s\n", i >= nout ? extra[i - nout] : outputs[i], dir,
              errno == ENOENT ? "does not exist" : strerror(errno));
      return 1;
    }
  }

  valo_error err;
  double t0 = now_seconds();
  valo_scene *sc = NULL;
  if (valo_scene_load_with(scene_path, &lo, &sc, &err)) { fprintf(stderr, "valo: error: %s\n", err.message); return 1; }
  valo_options file_opts;
  valo_scene_file_options(sc, &file_opts);
  /* --time alone: the scene file's spp (if any) still bounds the render, whichever comes
   * first; otherwise only the time does. */
  if (opt.time_budget > 0 && opt.spp == VALO_UNSET) opt.spp = file_opts.spp != VALO_UNSET ? file_opts.spp : 1048576;
  double load_s = now_seconds() - t0;
  valo_render *r = NULL;
  if (opt.params[0]) {
    /* --param entries are checked here, so that a mistyped one is a usage error */
    valo_options fo;
    valo_scene_file_options(sc, &fo);
    const char *integ = opt.integrator[0] ? opt.integrator : fo.integrator[0] ? fo.integrator : "path";
    if (valo_integrator_check_params(integ, opt.params, &err)) {
      fprintf(stderr, "valo: --param: %s (valo render --help-integrators lists them)\n", err.message);
      valo_scene_destroy(sc);
      return EXIT_USAGE;
    }
  }
  if (valo_render_create(sc, &opt, &r, &err)) {
    fprintf(stderr, "valo: error: %s\n", err.message);
    valo_scene_destroy(sc);
    return 1;
  }
  if ((resume && valo_render_resume(r, resume, &err)) || (ckpt && valo_render_checkpoint_to(r, ckpt, ckpt_every, &err))) {
    fprintf(stderr, "valo: error: %s\n", err.message);
    valo_render_destroy(r);
    valo_scene_destroy(sc);
    return 1;
  }
  valo_stats st;
  valo_render_stats(r, &st);
  valo_options eff;
  valo_scene_file_options(sc, &eff);
  int spp_total = opt.spp != VALO_UNSET ? opt.spp : (eff.spp != VALO_UNSET ? eff.spp : 16);
  double time_total = opt.time_budget != VALO_UNSET ? opt.time_budget : eff.time_budget;
  int frames = opt.frames != VALO_UNSET ? opt.frames : 0;
  progress_state ps = {isatty(2), quiet, -1e9, spp_total, time_total, frames};
  frame_out fo = {outputs, nout, frames, quiet, &oo};
  if (frames > 0) valo_render_on_frame(r, write_frame, &fo);
  if (!quiet) {
    char budget[96];
    if (frames > 0) snprintf(budget, sizeof budget, "%d frames at %d spp%s", frames, spp_total, time_total > 0 ? " (time-limited)" : "");
    else if (time_total > 0 && spp_total >= 1048576) snprintf(budget, sizeof budget, "time budget %g s", time_total);
    else if (time_total > 0) snprintf(budget, sizeof budget, "%d spp or %g s, whichever comes first", spp_total, time_total);
    else snprintf(budget, sizeof budget, "%d spp", spp_total);
    fprintf(stderr, "valo: %s: %llu triangles, %dx%d, %s, %s integrator, %s, %d threads\n", scene_path,
            (unsigned long long)st.triangles, st.width, st.height, budget, st.integrator, st.accel, st.threads);
    if (resume) fprintf(stderr, "valo: resuming from %s at %d spp\n", resume, st.spp_done);
    if (!valo_scene_has_light(sc))
      fprintf(stderr, "valo: warning: the scene has no light: the image will be black\n");
  }
  g_render = r;
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_sigint;
  sigaction(SIGINT, &sa, NULL);
  valo_status rs = valo_render_run(r, on_progress, &ps, &err);
  g_render = NULL;
  if (ps.tty && !quiet) fprintf(stderr, "\n");
  int rc = 0;
  valo_render_stats(r, &st);
  if (frames > 0) {
    /* the frame callback wrote every frame as it finished */
    if (rs == VALO_ERR_CANCELLED || g_interrupted) {
      rc = EXIT_INTERRUPTED;
      fprintf(stderr, "valo: interrupted after %d of %d frames (each written as it finished)\n", st.frames_done, frames);
    } else if (rs) {
      fprintf(stderr, "valo: error: %s\n", err.message);
      rc = 1;
    } else {
      if (st.frames_done < frames && st.frames_done > 0) {
        /* the time budget ended the sequence early: plain names get its last frame */
        for (int i = 0; i < nout; i++) {
          int plen;
          if (frame_pattern(outputs[i], &plen) >= 0) continue;
          if (valo_render_write(r, outputs[i], &oo, &err)) { fprintf(stderr, "valo: error: %s\n", err.message); rc = 1; }
        }
      }
      if (!quiet) fprintf(stderr, "valo: wrote %d frames%s\n", st.frames_done, st.frames_done < frames ? " (the time budget ended the sequence)" : "");
    }
  } else if (rs == VALO_ERR_CANCELLED || g_interrupted) {
    rc = EXIT_INTERRUPTED;
    if (st.spp_done > 0 || st.samples > 0)
      fprintf(stderr, "valo: interrupted after %d spp%s; writing what is finished\n", st.spp_done,
              st.samples > (uint64_t)st.spp_done * st.width * st.height ? " (some tiles one pass more)" : "");
    else fprintf(stderr, "valo: interrupted before any sample finished; no image written\n");
  } else if (rs) {
    fprintf(stderr, "valo: error: %s\n", err.message);
    rc = 1;
  }
  if (frames == 0 && (rc == 0 || (rc == EXIT_INTERRUPTED && (st.spp_done > 0 || st.samples > 0)))) {
    for (int i = 0; i < nout; i++) {
      if (valo_render_write(r, outputs[i], &oo, &err)) { fprintf(stderr, "valo: error: %s\n", err.message); rc = 1; }
      else if (!quiet) fprintf(stderr, "valo: wrote %s (%d spp)\n", outputs[i], st.spp_done);
    }
  }
  uint64_t peak = run_peak_memory();
  if (stats_json) {
    run_report rep = {scene_path, rc == 0 ? "ok" : rc == EXIT_INTERRUPTED ? "interrupted" : "error", rc, load_s, &st, peak};
    if (run_stats_write_json(stats_json, &rep) && rc == 0) rc = 1;
  }
  if (!quiet) {
    char lost[256] = "none";
    size_t n = 0;
    for (int k = 0; k < VALO_LOSS_COUNT; k++) {
      if (!st.lost[k] || n >= sizeof lost) continue;
      n += (size_t)snprintf(lost + n, sizeof lost - n, "%s%llu %s", n ? ", " : "", (unsigned long long)st.lost[k], valo_loss_name(k));
      if (k == VALO_LOSS_SHADING_NORMAL && n < sizeof lost && st.surface_samples)
        n += (size_t)snprintf(lost + n, sizeof lost - n, " (%.3g%% of surface samples)", 100.0 * (double)st.lost[k] / (double)st.surface_samples);
    }
    fprintf(stderr,
            "valo: summary: %llu triangles; load %.2f s, build %.2f s, render %.2f s; %d spp; %.3g rays, %.2f Mrays/s; "
            "peak memory %.0f MB; lost: %s\n",
            (unsigned long long)st.triangles, load_s, st.build_seconds, st.render_seconds, st.spp_done, (double)st.rays,
            st.render_seconds > 0 ? st.rays / st.render_seconds * 1e-6 : 0.0, (double)peak / 1048576.0, lost);
  }
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  return rc;
}

int main(int argc, char **argv) {
  if (argc < 2) { usage_main(stderr); return EXIT_USAGE; }
  if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) { usage_main(stdout); return 0; }
  if (!strcmp(argv[1], "--version")) { printf("valo %s\n", valo_version()); return 0; }
  if (!strcmp(argv[1], "render")) return cmd_render(argc - 2, argv + 2);
  fprintf(stderr, "valo: unknown command \"%s\" (see valo --help)\n", argv[1]);
  return EXIT_USAGE;
}
