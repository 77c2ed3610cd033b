/* test_mpi.c — rendering across processes, as a user runs it: `mpirun --oversubscribe -n 3
 * valo render ...` on one machine. The EXR is byte-identical to one process's (other
 * thread counts too) for path with AOVs (and an image of one tile, where ranks get no
 * work), photon, vpl, adaptive sampling under both rules, a sequence of frames and a
 * time budget (against one process at the spp it reached);
 * every rank renders tiles and --stats-json lists each; a run killed with SIGKILL resumes
 * from its checkpoint under MPI to the same bytes; Ctrl-C on mpirun writes what is
 * finished and leaves no process behind; restir-di and a missing scene are refused with
 * one message. Skips where mpirun or an MPI build is missing, fails so under CI=true. */
#include "harness.h"
#include "image/image_io.h"
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static char g_out[65536];
static char g_rank_env[1100] = "ASAN_OPTIONS=detect_leaks=0"; /* mpirun -x: the ranks' */

static int mpi_ready(void) {
  int ci = getenv("CI") && !strcmp(getenv("CI"), "true");
#ifndef VALO_HAVE_MPI
  fprintf(stderr, "valo was built without MPI (install libopenmpi-dev): %s\n", ci ? "failing under CI=true" : "skipped");
  return ci ? 1 : TEST_SKIP;
#else
  const char *args[] = {"--version", NULL};
  if (run_exe("mpirun", args, 0, 60, g_out, sizeof g_out) != 0) {
    fprintf(stderr, "mpirun is not there (openmpi-bin): %s\n", ci ? "failing under CI=true" : "skipped");
    return ci ? 1 : TEST_SKIP;
  }
  /* containers run tests as root, which OpenMPI refuses unless told */
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  /* Under ASan: no leak check in the ranks. OpenMPI keeps start-up allocations to the
   * end and unloads its plugins in MPI_Finalize, so LeakSanitizer sees them from
   * "<unknown module>" and no suppression can name them; ASan and UBSan still check
   * every access. (valo's one-process runs here keep the leak check.) */
  const char *asan = getenv("ASAN_OPTIONS");
  snprintf(g_rank_env, sizeof g_rank_env, "ASAN_OPTIONS=%s%sdetect_leaks=0", asan ? asan : "", asan && *asan ? ":" : "");
  return 0;
#endif
}
#define NEED_MPI()                 \
  do {                             \
    int r_ = mpi_ready();          \
    if (r_) return r_;             \
  } while (0)

static const char *scene(void) { return VALO_SOURCE_DIR "/scenes/default.json"; }


/* argv: `prefix` (NULL-ended), then `args` (NULL-ended), into out (at most 38). */
static void join(const char **out, const char *const *prefix, const char *const *args) {
  int n = 0;
  for (int i = 0; prefix[i] && n < 38; i++) out[n++] = prefix[i];
  for (int i = 0; args[i] && n < 38; i++) out[n++] = args[i];
  out[n] = NULL;
}

/* Runs valo under mpirun with 3 ranks of `threads` threads; args after "render". */
static int run_mpi(const char *threads, const char *const *args) {
  const char *pre[] = {"--oversubscribe", "-x", g_rank_env, "-n", "3", VALO_EXE, "render", "--threads", threads, NULL};
  const char *a[40];
  join(a, pre, args);
  return run_exe("mpirun", a, 0, 600, g_out, sizeof g_out);
}
static int run_one(const char *const *args) {
  const char *pre[] = {"render", "--threads", "2", NULL};
  const char *a[40];
  join(a, pre, args);
  return run_cli(a, 0, 600, g_out, sizeof g_out);
}

/* The same render in one process (2 threads) and on 3 ranks (1 thread each): every
 * output byte-identical. outs: output names, "albedo:alb.exr" for an AOV. */
static int identical(const char *what, const char *const *args, const char *const *outs) {
  static char arg[2][8][1200], file[2][8][1200];
  const char *o[2][20];
  int n = 0;
  for (; outs[n] && n < 8; n++)
    for (int s = 0; s < 2; s++) {
      const char *colon = strchr(outs[n], ':');
      int plen = colon ? (int)(colon - outs[n] + 1) : 0;
      snprintf(file[s][n], sizeof file[s][n], "%s/%s_%d_%s", scratch_dir(), s ? "three" : "one", n, outs[n] + plen);
      snprintf(arg[s][n], sizeof arg[s][n], "%.*s%s", plen, outs[n], file[s][n]);
      remove(file[s][n]);
      o[s][2 * n] = "-o";
      o[s][2 * n + 1] = arg[s][n];
    }
  for (int s = 0; s < 2; s++) { o[s][2 * n] = "-q"; o[s][2 * n + 1] = NULL; }
  const char *a1[40], *a3[40];
  join(a1, args, o[0]);
  join(a3, args, o[1]);
  int rc = run_one(a1);
  CHECK(rc == 0, "%s: one process failed (%d)", what, rc);
  rc = run_mpi("1", a3);
  CHECK(rc == 0, "%s: 3 ranks failed (%d)", what, rc);
  for (int i = 0; i < n; i++)
    if (!strchr(outs[i], '%')) /* a frame pattern: the caller compares the frames */
      CHECK(same_bytes(file[0][i], file[1][i]), "%s: %s differs between one process and 3 ranks", what, outs[i]);
  fprintf(stderr, "%s: %d outputs byte-identical on 1 process and 3 ranks\n", what, n);
  return 0;
}

/* Every rank of a --stats-json file rendered tiles; returns how many ranks it lists. */
static int ranks_that_worked(const char *json, int *listed) {
  char *text = read_text_file(json);
  int worked = 0;
  *listed = 0;
  for (const char *p = text ? strstr(text, "\"ranks\"") : NULL; p && (p = strstr(p, "\"tiles\": ")); p++) {
    (*listed)++;
    if (atoll(p + 9) > 0) worked++;
  }
  free(text);
  return worked;
}

static int identical_path(void) {
  NEED_MPI();
  const char *args[] = {scene(), "--res", "160x120", "--spp", "24", "--seed", "3", NULL};
  const char *outs[] = {"img.exr", "albedo:alb.exr", "ao:ao.exr", "depth:depth.pfm", NULL};
  if (identical("path with AOVs", args, outs)) return 1;
  /* one tile: some ranks get no work at all, and are only told to stop */
  const char *tiny[] = {scene(), "--res", "8x8", "--spp", "4", NULL};
  const char *one[] = {"img.exr", NULL};
  if (identical("one tile", tiny, one)) return 1;
  /* every rank took part, and the stats say so */
  const char *json = scratch_path("stats.json");
  const char *a[] = {scene(), "--res", "160x120", "--spp", "24", "--seed", "3", "-q", "-o", scratch_path("s.exr"), "--stats-json", json, NULL};
  CHECK(run_mpi("1", a) == 0, "3 ranks with --stats-json failed");
  int listed = 0, worked = ranks_that_worked(json, &listed);
  CHECK(listed == 3 && worked == 3, "--stats-json lists %d ranks, %d of them rendered tiles (expected 3 and 3)", listed, worked);
  return 0;
}

static int identical_prepare(void) {
  NEED_MPI();
  const char *outs[] = {"img.exr", NULL};
  const char *photon[] = {scene(), "--res", "64x48", "--spp", "3", "--integrator", "photon", NULL};
  const char *vpl[] = {scene(), "--res", "64x48", "--spp", "3", "--integrator", "vpl", NULL};
  return identical("photon", photon, outs) || identical("vpl", vpl, outs);
}

static int identical_adaptive(void) {
  NEED_MPI();
  const char *outs[] = {"img.exr", "spp:spp.pfm", NULL};
  const char *err[] = {scene(), "--res", "96x72", "--spp", "32", "--adaptive-rule", "error", NULL};
  const char *dig[] = {scene(), "--res", "96x72", "--spp", "32", "--adaptive-rule", "digest", NULL};
  return identical("adaptive, error rule", err, outs) || identical("adaptive, digest rule", dig, outs);
}

static int identical_frames(void) {
  NEED_MPI();
  const char *outs[] = {"f_%04d.exr", NULL};
  const char *args[] = {VALO_SOURCE_DIR "/scenes/manylight.json", "--integrator", "path", "--res", "64x48", "--spp", "4", "--frames", "3", NULL};
  if (identical("a sequence of 3 frames", args, outs)) return 1;
  /* the pattern wrote frames 0..2 */
  for (int f = 0; f < 3; f++) {
    char a[1200], b[1200];
    snprintf(a, sizeof a, "%s/one_0_f_%04d.exr", scratch_dir(), f);
    snprintf(b, sizeof b, "%s/three_0_f_%04d.exr", scratch_dir(), f);
    CHECK(access(a, R_OK) == 0, "frame %d was not written", f);
    CHECK(same_bytes(a, b), "frame %d differs between one process and 3 ranks", f);
  }
  return 0;
}

/* --time on 3 ranks: the spp it reached, rendered by one process, gives the same bytes. */
static int time_budget(void) {
  NEED_MPI();
  const char *json = scratch_path("t.json"), *t3 = scratch_path("t3.exr"), *t1 = scratch_path("t1.exr");
  const char *a[] = {scene(), "--res", "128x96", "--time", "1.5", "-q", "-o", t3, "--stats-json", json, NULL};
  CHECK(run_mpi("1", a) == 0, "3 ranks with --time failed");
  char *text = read_text_file(json);
  CHECK(text != NULL, "no stats file");
  const char *p = strstr(text, "\"spp\": ");
  int spp = p ? atoi(p + 7) : -1;
  free(text);
  CHECK(spp != -1, "no spp in the stats");
  CHECK(spp >= 2, "only %d spp in 1.5 s", spp);
  char s[16];
  snprintf(s, sizeof s, "%d", spp);
  const char *b[] = {scene(), "--res", "128x96", "--spp", s, "-q", "-o", t1, NULL};
  CHECK(run_one(b) == 0, "one process failed");
  CHECK(same_bytes(t1, t3), "3 ranks for 1.5 s (%d spp) differ from one process at %d spp", spp, spp);
  fprintf(stderr, "--time 1.5 on 3 ranks reached %d spp: byte-identical to one process at %d spp\n", spp, spp);
  return 0;
}

/* Starts mpirun (3 ranks, 1 thread each) with args after "render" and, once its checkpoint
 * has been replaced `writes` times (inotify), sends it sig (SIGKILL: to every process of the job at once); returns its exit status
 * (128 + signal when a signal ended it), or -1 when it ended first, 999 when it hung. */
static int run_mpi_until(const char *const *args, const char *ckpt, int writes, int sig) {
  const char *pre[] = {"--oversubscribe", "-x", g_rank_env, "-n", "3", VALO_EXE, "render", "--threads", "1", NULL};
  const char *a[40];
  join(a, pre, args);
  remove(ckpt);
  char dir[1200];
  snprintf(dir, sizeof dir, "%s", ckpt);
  char *slash = strrchr(dir, '/');
  const char *base = slash + 1;
  *slash = 0;
  int in = inotify_init1(IN_NONBLOCK);
  if (in < 0 || inotify_add_watch(in, dir, IN_MOVED_TO) < 0) { fprintf(stderr, "inotify: %s\n", strerror(errno)); return -2; }
  char log[1200];
  snprintf(log, sizeof log, "%s/mpi_log.txt", scratch_dir());
  pid_t pid = spawn_exe("mpirun", a, log);
  int seen = 0, status = 0, sent = 0;
  struct timespec t0;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  for (;;) {
    struct pollfd pf = {in, POLLIN, 0};
    if (poll(&pf, 1, 5) > 0) {
      char buf[4096] __attribute__((aligned(__alignof__(struct inotify_event))));
      ssize_t len = read(in, buf, sizeof buf);
      for (char *p = buf; len > 0 && p < buf + len;) {
        struct inotify_event *ev = (struct inotify_event *)p;
        if (ev->len && !strcmp(ev->name, base)) seen++;
        p += sizeof *ev + ev->len;
      }
    }
    if (seen >= writes && !sent) {
      if (sig == SIGKILL) {
        /* the job dies at once, as when its machines fail: every process of the session */
        char cmd[64];
        snprintf(cmd, sizeof cmd, "pkill -KILL -s %d", (int)pid);
        if (system(cmd) != 0) kill(pid, SIGKILL);
      } else kill(pid, sig);
      sent = 1;
    }
    if (waitpid(pid, &status, WNOHANG) == pid) break;
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    if (t.tv_sec - t0.tv_sec > 600) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      close(in);
      return 999;
    }
  }
  close(in);
  FILE *f = fopen(log, "rb");
  size_t len = f ? fread(g_out, 1, sizeof g_out - 1, f) : 0;
  if (f) fclose(f);
  g_out[len] = 0;
  fprintf(stderr, "mpirun said: %s", g_out);
  if (!sent) return -1;
  return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : WEXITSTATUS(status);
}

/* No valo process of this test's left running (by its scratch folder in the argv). */
static int leftovers(void) {
  struct timespec d = {0, 200000000};
  for (int tries = 0; tries < 25; tries++) {
    char cmd[1400];
    snprintf(cmd, sizeof cmd, "pgrep -f '[v]alo render.*%s' > /dev/null", scratch_dir()); /* [v]: not this shell */
    if (system(cmd) != 0) return 0;
    nanosleep(&d, NULL);
  }
  return 1;
}

/* SIGKILL to mpirun and every rank part-way, then --resume under MPI: the same bytes as
 * an uninterrupted render. */
static int checkpoint_kill_resume(void) {
  NEED_MPI();
  const char *full = scratch_path("full.exr"), *res = scratch_path("res.exr"), *ck = scratch_path("ck.valo");
  const char *a1[] = {scene(), "--res", "96x72", "--spp", "96", "-q", "-o", full, NULL};
  CHECK(run_one(a1) == 0, "the uninterrupted render failed");
  /* passes grow to about a second each; the fifth checkpoint is a few spp in */
  const char *a2[] = {scene(), "--res", "96x72", "--spp", "96", "-q", "--checkpoint", ck, "--checkpoint-every", "0", "-o", res, NULL};
  int rc = run_mpi_until(a2, ck, 4, SIGKILL);
  CHECK(rc == 128 + SIGKILL, "mpirun was not killed part-way (%d)", rc);
  CHECK(!leftovers(), "valo processes outlived the killed mpirun");
  remove(res);
  const char *a3[] = {scene(), "--res", "96x72", "--spp", "96", "--resume", ck, "-o", res, NULL};
  CHECK(run_mpi("1", a3) == 0, "the resumed render on 3 ranks failed");
  const char *p = strstr(g_out, "resuming from ");
  CHECK(p && strstr(p, " at "), "no resume line");
  int at = atoi(strstr(p, " at ") + 4);
  CHECK(at > 0 && at < 96, "resumed at %d spp", at);
  CHECK(same_bytes(full, res), "killed on 3 ranks and resumed on 3: differs from the uninterrupted render");
  fprintf(stderr, "killed at %d of 96 spp on 3 ranks, resumed on 3: byte-identical\n", at);
  return 0;
}

/* Ctrl-C on mpirun (it passes SIGTERM to every rank): rank 0 writes what is finished, the
 * stats say "interrupted", and no process is left. */
static int ctrl_c(void) {
  NEED_MPI();
  const char *img = scratch_path("int.exr"), *ck = scratch_path("int.valo"), *json = scratch_path("int.json");
  remove(img);
  const char *a[] = {scene(), "--res", "160x120", "--spp", "100000", "--checkpoint", ck, "--checkpoint-every", "0", "-o", img, "--stats-json", json, NULL};
  int rc = run_mpi_until(a, ck, 3, SIGINT);
  CHECK(rc != 999 && rc != -1, "mpirun %s", rc == 999 ? "hung after Ctrl-C" : "ended before Ctrl-C");
  CHECK(strstr(g_out, "interrupted after") != NULL, "rank 0 did not report the interruption");
  CHECK(strstr(g_out, "wrote ") != NULL, "rank 0 wrote no image");
  image im;
  CHECK(image_read(img, &im, NULL) == 0, "%s is not a readable image", img);
  CHECK(im.w == 160 && im.h == 120, "image %dx%d", im.w, im.h);
  image_free(&im);
  char *text = read_text_file(json);
  CHECK(text != NULL, "no stats file");
  int interrupted = strstr(text, "\"status\": \"interrupted\"") != NULL;
  free(text);
  CHECK(interrupted, "the stats do not say interrupted");
  CHECK(!leftovers(), "valo processes outlived Ctrl-C");
  return 0;
}

static int count(const char *hay, const char *needle) {
  int n = 0;
  for (const char *p = hay; (p = strstr(p, needle)); p++) n++;
  return n;
}

static int refusals(void) {
  NEED_MPI();
  const char *a[] = {scene(), "--res", "32x32", "--integrator", "restir-di", "-o", scratch_path("r.exr"), NULL};
  CHECK(run_mpi("1", a) != 0, "restir-di ran on 3 ranks");
  CHECK(strstr(g_out, "restir-di is image-wide") && strstr(g_out, "one process"), "the refusal does not say why");
  CHECK(count(g_out, "valo: error") == 1, "%d error lines, expected one (rank 0's)", count(g_out, "valo: error"));
  const char *b[] = {"/nonexistent/scene.json", "-o", scratch_path("r.exr"), NULL};
  CHECK(run_mpi("1", b) != 0, "a missing scene ran");
  CHECK(strstr(g_out, "/nonexistent/scene.json") != NULL, "the message does not name the file");
  CHECK(count(g_out, "valo: error") == 1, "%d error lines, expected one", count(g_out, "valo: error"));
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"identical_path", identical_path},
                                    {"identical_prepare", identical_prepare},
                                    {"identical_adaptive", identical_adaptive},
                                    {"identical_frames", identical_frames},
                                    {"time_budget", time_budget},
                                    {"checkpoint_kill_resume", checkpoint_kill_resume},
                                    {"ctrl_c", ctrl_c},
                                    {"refusals", refusals},
                                    {NULL, NULL}};
  return test_main(argc, argv, cases);
}
