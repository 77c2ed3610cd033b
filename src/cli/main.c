/* main.c — owns the `valo` command line's run: the output folders' check, the progress
 * bar (with samples/s and ETA on a terminal, periodic plain lines otherwise), the final
 * summary, checkpoints and resume, Ctrl-C handling and exit codes (0 success, 1 error,
 * 2 usage, 130 interrupted), and the ranks of an MPI run (rank 0 reports and writes).
 * Arguments are parsed by args.c. Uses only the public API in
 * valo/valo.h. */
#include "valo/valo.h"
#include "cli/run_stats.h"
#include "cli/args.h"
#include "cli/compare.h"
#include "cli/view.h"
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include <unistd.h>

#define EXIT_INTERRUPTED 130

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
          "  valo render SCENE [options]   render a scene (JSON scene file, Mitsuba .xml, or an OBJ/glTF/PLY mesh)\n"
          "  valo convert SCENE.xml -o OUT.json [-D NAME=VALUE ...]\n"
          "                                write the JSON scene a Mitsuba scene file means\n"
          "  valo --help                   this text\n"
          "  valo render --help            the render options\n"
          "  valo compare SCENE --integrators A,B (--time S | --spp N) -o DIR\n"
          "                                the integrators side by side at equal time: an HTML report\n"
          "  valo view SCENE [options]     a window showing the render as it refines; restir in real time\n"
          "  valo --version                print the version\n\n"
          "Exit codes: 0 success, 1 error (bad input, failed write), 2 usage error, 130 interrupted.\n",
          valo_version());
}

/* valo convert SCENE.xml -o OUT.json [-D NAME=VALUE ...] */
static int cmd_convert(int argc, char **argv) {
  const char *in = NULL, *out = NULL;
  valo_load_options lo;
  valo_load_options_init(&lo);
  for (int i = 0; i < argc; i++) {
    const char *a = argv[i];
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      printf("Usage: valo convert SCENE.xml -o OUT.json [-D NAME=VALUE ...]\n\n"
             "Writes the JSON scene (docs/scene-format.md) that a Mitsuba scene file means: the same\n"
             "translation valo render makes of it, with file names made absolute. -D (--define)\n"
             "sets the file's <default> values, as for valo render.\n");
      return 0;
    }
    if ((!strcmp(a, "-o") || !strcmp(a, "--output") || !strcmp(a, "-D") || !strcmp(a, "--define")) && i + 1 >= argc) {
      fprintf(stderr, "valo: %s needs a value\n", a);
      return EXIT_USAGE;
    }
    if (!strcmp(a, "-o") || !strcmp(a, "--output")) { out = argv[++i]; continue; }
    if (!strcmp(a, "-D") || !strcmp(a, "--define")) {
      valo_error e;
      if (valo_option_set("--define", argv[++i], NULL, &lo, NULL, &e)) { fprintf(stderr, "valo: %s: %s\n", a, e.message); return EXIT_USAGE; }
      continue;
    }
    if (a[0] == '-' || in) { fprintf(stderr, "valo: convert: unexpected \"%s\" (valo convert --help)\n", a); return EXIT_USAGE; }
    in = a;
  }
  if (!in || !out) { fprintf(stderr, "valo: convert needs SCENE.xml and -o OUT.json (valo convert --help)\n"); return EXIT_USAGE; }
  valo_error err;
  if (valo_scene_convert(in, &lo, out, &err)) { fprintf(stderr, "valo: error: %s\n", err.message); return 1; }
  fprintf(stderr, "valo: wrote %s\n", out);
  return 0;
}

typedef struct progress_state { int tty; int quiet; double last_print; int spp_total; double time_budget; int frames; } progress_state;

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


/* Warnings of ranks above 0 are dropped: rank 0 prints the same ones. */
static void quiet_warning(void *user, const char *message) { (void)user; (void)message; }

/* On a terminal, the phases before the progress bar (loading, building: seconds for a
 * large scene) show a status line, cleared when they end; warnings clear it (and the
 * progress bar's line) first, then it is shown again. */
static char g_status[256];
static void status_clear(void) {
  if (g_status[0]) fprintf(stderr, "\r\033[K");
}
static void status_show(const char *what, const char *name) {
  status_clear();
  snprintf(g_status, sizeof g_status, "valo: %s %.200s ...", what, name);
  fprintf(stderr, "%s", g_status);
  fflush(stderr);
}
static void status_end(void) {
  status_clear();
  g_status[0] = 0;
}
static void tty_warning(void *user, const char *message) {
  (void)user;
  fprintf(stderr, "\r\033[K");
  if (!strncmp(message, "note: ", 6)) fprintf(stderr, "valo: %s\n", message);
  else fprintf(stderr, "valo: warning: %s\n", message);
  if (g_status[0]) fprintf(stderr, "%s", g_status);
  fflush(stderr);
}

/* Everything before the render runs: the output folders, the scene, the render, the
 * resume. 0, or an exit code with the message in err (printed here on rank 0). */
static int setup(const cli_args *ca, valo_options *opt, const char *ckpt, valo_scene **sc, valo_render **r, double *load_s, valo_error *err) {
  double t0 = cli_now();
  int rank = valo_mpi_rank();
  /* Every output's folder must exist and be writable before hours of rendering (rank 0
   * alone writes). */
  const char *extra[2] = {ca->stats_json, ckpt};
  for (int i = 0; i < ca->nout + 2 && rank == 0; i++) {
    if (i >= ca->nout && !extra[i - ca->nout]) continue;
    const char *file = i >= ca->nout ? extra[i - ca->nout] : ca->outputs[i] + aov_prefix(ca->outputs[i]);
    char dir[4096];
    const char *slash = strrchr(file, '/');
    if (slash) snprintf(dir, sizeof dir, "%.*s", slash == file ? 1 : (int)(slash - file), file);
    else snprintf(dir, sizeof dir, ".");
    /* a FIFO, a device or /dev/stdout is written in place (valo_file_write): it must be
     * writable itself */
    struct stat st;
    int in_place = stat(file, &st) == 0 && (!S_ISREG(st.st_mode) || !strncmp(file, "/dev/", 5) || !strncmp(file, "/proc/", 6));
    if (in_place && access(file, W_OK) != 0) {
      snprintf(err->message, sizeof err->message, "%s: cannot write: %s", i >= ca->nout ? extra[i - ca->nout] : ca->outputs[i], strerror(errno));
      return 1;
    }
    if (!in_place && access(dir, W_OK) != 0) {
      snprintf(err->message, sizeof err->message, "%s: cannot write there: folder %s %s", i >= ca->nout ? extra[i - ca->nout] : ca->outputs[i], dir,
               errno == ENOENT ? "does not exist" : strerror(errno));
      return 1;
    }
  }
  int tty = rank == 0 && !ca->quiet && isatty(2);
  if (tty) {
    valo_set_warning_handler(tty_warning, NULL);
    status_show("loading", ca->scene_path);
  }
  int lrc = valo_scene_load_with(ca->scene_path, &ca->lo, sc, err);
  if (tty) status_end();
  if (lrc) return 1;
  *load_s = cli_now() - t0;
  valo_options file_opts;
  valo_scene_file_options(*sc, &file_opts);
  /* --time alone: the scene file's spp (if any) still bounds the render, whichever comes
   * first; otherwise only the time does. */
  if (opt->time_budget > 0 && opt->spp == VALO_UNSET) opt->spp = file_opts.spp != VALO_UNSET ? file_opts.spp : 1048576;
  if (opt->params[0]) {
    /* --param entries are checked here, so that a mistyped one is a usage error */
    const char *integ = opt->integrator[0] ? opt->integrator : file_opts.integrator[0] ? file_opts.integrator : "path";
    if (valo_integrator_check_params(integ, opt->params, err)) {
      char m[sizeof err->message];
      snprintf(m, sizeof m, "--param: %.900s (valo render --help-integrators lists them)", err->message);
      snprintf(err->message, sizeof err->message, "%s", m);
      return EXIT_USAGE;
    }
  }
  if (tty) status_show("building the acceleration structure of", ca->scene_path);
  int crc = valo_render_create(*sc, opt, r, err);
  if (tty) status_end();
  if (crc) return 1;
  if (rank > 0) valo_render_set_warning_handler(*r, quiet_warning, NULL);
  if ((ca->resume && valo_render_resume(*r, ca->resume, err)) || (ckpt && valo_render_checkpoint_to(*r, ckpt, ca->ckpt_every, err))) return 1;
  return 0;
}

static int cmd_render(int argc, char **argv) {
  int rank = valo_mpi_rank();
  cli_args ca;
  /* every rank parses the same arguments; rank 0 alone says what is wrong */
  FILE *devnull = rank > 0 ? fopen("/dev/null", "w") : NULL;
  int prc = cli_parse_render(argc, argv, &ca, devnull ? devnull : stdout, devnull ? devnull : stderr);
  if (devnull) fclose(devnull);
  if (prc >= 0) return prc;
  valo_options opt = ca.opt;
  valo_output_options oo = ca.oo;
  const char *scene_path = ca.scene_path, *const *outputs = ca.outputs, *stats_json = ca.stats_json, *ckpt = ca.ckpt, *resume = ca.resume;
  int nout = ca.nout, quiet = ca.quiet || rank > 0;
  if (resume && !ckpt) ckpt = resume; /* a resumed render keeps checkpointing to its file */
  if (rank > 0) valo_set_warning_handler(quiet_warning, NULL);

  valo_error err;
  err.message[0] = 0;
  double load_s = 0;
  valo_scene *sc = NULL;
  valo_render *r = NULL;
  int src = setup(&ca, &opt, ckpt, &sc, &r, &load_s, &err);
  /* under MPI every rank learns whether any failed, and rank 0 says which and why */
  src = valo_mpi_agree(src, &err);
  if (src) {
    if (rank == 0) fprintf(stderr, "valo: error: %s\n", err.message);
    valo_render_destroy(r);
    valo_scene_destroy(sc);
    return src;
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
    char ranks[48] = "";
    if (valo_mpi_size() > 1) snprintf(ranks, sizeof ranks, " on each of %d MPI ranks", valo_mpi_size());
    fprintf(stderr, "valo: %s: %llu triangles, %dx%d, %s, %s integrator, %s, %d threads%s\n", scene_path,
            (unsigned long long)st.triangles, st.width, st.height, budget, st.integrator, st.accel, st.threads, ranks);
    if (resume) fprintf(stderr, "valo: resuming from %s at %d spp\n", resume, st.spp_done);
    if (!valo_scene_has_light(sc))
      fprintf(stderr, "valo: warning: the scene has no light: the image will be black\n");
    unsigned ov = valo_scene_overlapping_lights(sc);
    if (ov)
      fprintf(stderr, "valo: note: %u area lights overlap another in their plane; where they overlap, the first in the scene's "
                      "order is the one seen\n", ov);
  }
  g_render = r;
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = rank > 0 ? SIG_IGN : on_sigint;
  sigaction(SIGINT, &sa, NULL);
  /* mpirun passes Ctrl-C on as SIGTERM to every rank (and SIGKILL a second later): rank
   * 0 stops and writes what is finished, the others go on until it tells them to stop */
  if (valo_mpi_size() > 1) sigaction(SIGTERM, &sa, NULL);
  valo_status rs = valo_render_run(r, rank == 0 ? on_progress : NULL, &ps, &err);
  g_render = NULL;
  if (rank > 0) {
    valo_render_destroy(r);
    valo_scene_destroy(sc);
    return rs && rs != VALO_ERR_CANCELLED ? 1 : 0;
  }
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
    valo_rank_stats rks[256];
    int nr = 0;
    while (nr < 256 && valo_render_rank_stats(r, nr, &rks[nr]) == 0) nr++;
    run_report rep = {scene_path, rc == 0 ? "ok" : rc == EXIT_INTERRUPTED ? "interrupted" : "error", rc, load_s, &st, peak, rks, nr};
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
            "valo: summary: %llu triangles; load %.2f s, build %.2f s (%s), render %.2f s; %d spp; %.3g rays, %.2f Mrays/s; "
            "peak memory %.0f MB; lost: %s\n",
            (unsigned long long)st.triangles, load_s, st.build_seconds, st.accel, st.render_seconds, st.spp_done, (double)st.rays,
            st.render_seconds > 0 ? st.rays / st.render_seconds * 1e-6 : 0.0, (double)peak / 1048576.0, lost);
    valo_rank_stats k;
    for (int i = 0; valo_render_rank_stats(r, i, &k) == 0; i++)
      fprintf(stderr, "valo: rank %d (%s, %d threads): %llu tiles, %llu samples, %.3g rays, %.2f Mrays/s over %.2f s busy, peak memory %.0f MB\n", i,
              k.host, k.threads, (unsigned long long)k.tiles, (unsigned long long)k.samples, (double)k.rays,
              k.busy_seconds > 0 ? (double)k.rays / k.busy_seconds * 1e-6 : 0.0, k.busy_seconds, (double)k.peak_memory_bytes / 1048576.0);
  }
  valo_render_destroy(r);
  valo_scene_destroy(sc);
  return rc;
}

int main(int argc, char **argv) {
  if (argc < 2) { usage_main(stderr); return EXIT_USAGE; }
  if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) { usage_main(stdout); return 0; }
  if (!strcmp(argv[1], "--version")) { printf("valo %s\n", valo_version()); return 0; }
  if (!strcmp(argv[1], "render")) {
    int launched = valo_mpi_init(&argc, &argv);
    if (launched > valo_mpi_size()) {
      fprintf(stderr, "valo: error: started as %d MPI processes, but this valo was built without MPI (install libopenmpi-dev and rebuild)\n", launched);
      return 1;
    }
    int rc = cmd_render(argc - 2, argv + 2);
    valo_mpi_finalize();
    return rc;
  }
  if (!strcmp(argv[1], "compare")) return cmd_compare(argc - 2, argv + 2);
  if (!strcmp(argv[1], "view")) return cmd_view(argc - 2, argv + 2);
  if (!strcmp(argv[1], "convert")) return cmd_convert(argc - 2, argv + 2);
  fprintf(stderr, "valo: unknown command \"%s\" (see valo --help)\n", argv[1]);
  return EXIT_USAGE;
}
