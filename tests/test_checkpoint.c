/* test_checkpoint.c — checkpoint and resume through the command line, as a user runs
 * them: a render killed with SIGKILL part-way and resumed ends byte-identical to an
 * uninterrupted one (path uniform and adaptive under both rules, photon, vpl); a
 * checkpoint that is truncated, corrupted, not a checkpoint, made by another version,
 * for another scene or with other options is refused with a message saying which, and
 * no image is written. */
#include "harness.h"
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/inotify.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static char g_out[65536];
#define RUN(code, ...)                                                                       \
  do {                                                                                       \
    const char *const a_[] = {__VA_ARGS__, NULL};                                            \
    int rc_ = run_cli(a_, 0, 600, g_out, sizeof g_out);                                      \
    CHECK(rc_ == (code), "exit code %d, expected %d", rc_, (code));                          \
  } while (0)
#define SAID(text) CHECK(strstr(g_out, text) != NULL, "message lacks \"%s\"", text)

static const char *scene(void) { return VALO_SOURCE_DIR "/scenes/default.json"; }


/* Starts valo with args (NULL-ended) and SIGKILLs it once its checkpoint file has been
 * written `writes` times: each write renames a finished file over it, which inotify
 * reports (no write is missed, however fast they come). Returns 0 when it was killed
 * that way, 1 when it ended first. */
static int run_and_kill(const char *const *args, const char *ckpt, int writes) {
  remove(ckpt);
  char dir[1200];
  snprintf(dir, sizeof dir, "%s", ckpt);
  char *slash = strrchr(dir, '/');
  const char *base = slash ? slash + 1 : ckpt;
  if (slash) *slash = 0;
  else snprintf(dir, sizeof dir, ".");
  int in = inotify_init1(IN_NONBLOCK);
  if (in < 0 || inotify_add_watch(in, dir, IN_MOVED_TO) < 0) { fprintf(stderr, "inotify: %s\n", strerror(errno)); return 1; }
  pid_t pid = spawn_cli(args, "/dev/null");
  int seen = 0, status = 0;
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
    if (seen >= writes) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      close(in);
      return 0;
    }
    if (waitpid(pid, &status, WNOHANG) == pid) { close(in); return 1; }
  }
}

/* The spp a resumed run started from ("resuming from F at N spp"), or -1. */
static int resumed_at(void) {
  const char *p = strstr(g_out, "resuming from ");
  if (!p || !(p = strstr(p, " at "))) return -1;
  return atoi(p + 4);
}

typedef struct ckpt_case { const char *name; const char *args[12]; int spp, writes, min_at; } ckpt_case;

/* argv for one run: the common part, the case's arguments, then `more` (NULL-ended). */
static void build_args(const char **out, const ckpt_case *c, const char *spp, const char *threads, const char *const *more) {
  const char *common[] = {"render", scene(), "--res", "64x64", "--seed", "7", "--spp", spp, "--threads", threads, NULL};
  int n = 0;
  for (int i = 0; common[i]; i++) out[n++] = common[i];
  for (int i = 0; c->args[i]; i++) out[n++] = c->args[i];
  for (int i = 0; more[i]; i++) out[n++] = more[i];
  out[n] = NULL;
}

static int one_kill(const ckpt_case *c) {
  const char *full = scratch_path("full.exr"), *res = scratch_path("resumed.exr"), *ck = scratch_path("ck.valo");
  char spp[16];
  snprintf(spp, sizeof spp, "%d", c->spp);
  const char *args[40];
  /* uninterrupted */
  const char *m1[] = {"-q", "-o", full, NULL};
  build_args(args, c, spp, "2", m1);
  int rc = run_cli(args, 0, 600, g_out, sizeof g_out);
  CHECK(rc == 0, "%s: the uninterrupted render failed (%d)", c->name, rc);
  /* killed part-way, on another thread count (the image must not depend on it) */
  const char *m2[] = {"-q", "--checkpoint", ck, "--checkpoint-every", "0", "-o", res, NULL};
  build_args(args, c, spp, "3", m2);
  CHECK(run_and_kill(args, ck, c->writes) == 0, "%s: the render ended before %d checkpoints", c->name, c->writes);
  remove(res);
  /* resumed */
  const char *m3[] = {"--resume", ck, "-o", res, NULL};
  build_args(args, c, spp, "2", m3);
  rc = run_cli(args, 0, 600, g_out, sizeof g_out);
  CHECK(rc == 0, "%s: the resumed render failed (%d)", c->name, rc);
  int at = resumed_at();
  CHECK(at >= c->min_at && at < c->spp, "%s: resumed at %d spp, expected %d..%d", c->name, at, c->min_at, c->spp - 1);
  CHECK(same_bytes(full, res), "%s: the resumed image differs from the uninterrupted one", c->name);
  fprintf(stderr, "%s: killed, resumed at %d of %d spp: byte-identical\n", c->name, at, c->spp);
  return 0;
}

/* A real SIGKILL mid-way, then --resume: the EXR is byte-identical to an uninterrupted
 * render's (splatted ones too: the filters' weight sums are in it). Each is killed well before its last checkpoint (path: 8 of them; adaptive:
 * about 22, killed past the uniform half of the budget; photon 6; vpl 12). */
static int kill_and_resume(void) {
  static const ckpt_case cases[] = {
      {"path", {NULL}, 128, 4, 1},
      {"path splatted (gaussian)", {"--filter", "gaussian", "--splat", NULL}, 128, 4, 1},
      {"path splatted, adaptive", {"--filter", "gaussian", "--splat", "--adaptive", NULL}, 64, 12, 33},
      {"path adaptive (error rule)", {"--adaptive", NULL}, 64, 12, 33},
      {"path adaptive (digest rule)", {"--adaptive", "--adaptive-rule", "digest", NULL}, 64, 12, 33},
      {"photon", {"--integrator", "photon", "--param", "photon.global=5000", "--param", "photon.caustic=2000", "--param", "photon.gather=4", NULL},
       6, 3, 1},
      {"vpl", {"--integrator", "vpl", "--param", "vpl.count=128", NULL}, 12, 3, 1}};
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    if (one_kill(&cases[i])) return 1;
  return 0;
}

/* FNV-1a over n bytes: the checkpoint's checksum, to forge a file of another version. */
static uint64_t fnv(const unsigned char *p, size_t n) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (size_t i = 0; i < n; i++) { h ^= p[i]; h *= 0x100000001b3ULL; }
  return h;
}

static unsigned char *read_all(const char *path, size_t *n) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long len = ftell(f);
  fseek(f, 0, SEEK_SET);
  unsigned char *b = malloc(len > 0 ? (size_t)len : 1);
  *n = b ? fread(b, 1, (size_t)len, f) : 0;
  fclose(f);
  return b;
}
static int write_all(const char *path, const unsigned char *b, size_t n) {
  FILE *f = fopen(path, "wb");
  if (!f) return -1;
  size_t w = fwrite(b, 1, n, f);
  return fclose(f) || w != n ? -1 : 0;
}

/* Refusals: each exit 1, naming why, and no image written. */
static int refusals(void) {
  const char *ck = scratch_path("good.valo"), *bad = scratch_path("bad.valo"), *out = scratch_path("never.exr");
  RUN(0, "render", scene(), "--res", "32x32", "--spp", "4", "--seed", "7", "-q", "--checkpoint", ck, "--checkpoint-every", "0", "-o",
      scratch_path("x.exr"));
  size_t n;
  unsigned char *b = read_all(ck, &n);
  CHECK(b && n > 64, "no checkpoint written");
  remove(out);
#define REFUSED(...)                                              \
  do {                                                            \
    RUN(1, "render", scene(), "--res", "32x32", "--spp", "4", "-o", out, __VA_ARGS__); \
    CHECK(access(out, F_OK) != 0, "an image was written");        \
  } while (0)
  /* other options: the message names the option and both values */
  REFUSED("--seed", "8", "--resume", ck);
  SAID("other options"); SAID("--seed 7"); SAID("--seed 8");
  REFUSED("--seed", "7", "--max-depth", "3", "--resume", ck);
  SAID("--max-depth -1"); SAID("--max-depth 3");
  /* another scene */
  RUN(1, "render", VALO_SOURCE_DIR "/scenes/caustic.json", "--res", "32x32", "--spp", "4", "--seed", "7", "-o", out, "--resume", ck);
  SAID("another scene"); SAID("default.json");
  CHECK(access(out, F_OK) != 0, "an image was written");
  /* truncated */
  CHECK(write_all(bad, b, n / 2) == 0, "write");
  REFUSED("--seed", "7", "--resume", bad);
  SAID("truncated");
  /* corrupted: one byte of the film */
  b[n / 2] ^= 0x40;
  CHECK(write_all(bad, b, n) == 0, "write");
  b[n / 2] ^= 0x40;
  REFUSED("--seed", "7", "--resume", bad);
  SAID("corrupted");
  /* another version: the version string changed and the checksum made to match */
  unsigned char *v = malloc(n);
  CHECK(v != NULL, "memory");
  memcpy(v, b, n);
  CHECK(v[12] >= '0' && v[12] <= '9', "the version is not where expected");
  v[12] = v[12] == '9' ? '8' : (unsigned char)(v[12] + 1);
  uint64_t h = fnv(v, n - 16);
  memcpy(v + n - 8, &h, 8);
  CHECK(write_all(bad, v, n) == 0, "write");
  free(v);
  REFUSED("--seed", "7", "--resume", bad);
  SAID("made by valo"); SAID("this is valo");
  /* not a checkpoint */
  const char *txt = scratch_file("text.valo", "just some text, long enough to have a tail of sixteen bytes\n");
  REFUSED("--seed", "7", "--resume", txt);
  SAID("not a valo checkpoint");
  /* the unchanged file still resumes */
  CHECK(write_all(bad, b, n) == 0, "write");
  RUN(0, "render", scene(), "--res", "32x32", "--spp", "4", "--seed", "7", "-o", out, "--resume", bad);
  SAID("resuming from");
  free(b);
  /* what cannot be checkpointed says so */
  RUN(1, "render", scene(), "--res", "32x32", "--spp", "2", "--frames", "2", "-o", scratch_path("f%d.png"), "--checkpoint", ck);
  SAID("still images");
  RUN(1, "render", scene(), "--res", "32x32", "--spp", "2", "--integrator", "restir-di", "-o", out, "--checkpoint", ck);
  SAID("image-wide");
  RUN(2, "render", scene(), "--checkpoint-every", "soon");
  SAID("--checkpoint-every");
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"kill_and_resume", kill_and_resume}, {"refusals", refusals}, {NULL, NULL}};
  return test_main(argc, argv, cases);
}
