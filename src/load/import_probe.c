/* import_probe.c — owns the trial import of unchecked mesh formats in a child process
 * (import_probe.h): the child's memory limit, the parent's time limit, and the errors
 * that name what happened. */
#include "load/import_probe.h"
#include "core/clock.h"
#include "core/error.h"
#include "core/memlimit.h"
#include <assimp/cimport.h>
#include <assimp/scene.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

/* What the child reports through the pipe: one of these bytes, then Assimp's message. */
enum { PROBE_OK = 'O', PROBE_REFUSED = 'E', PROBE_MEMORY = 'M' };

/* What the child may add to its address space: 64 times the file's size, at least 1 GiB
 * and at most valo's memory limit. A header that claims billions of elements then fails
 * its allocation at once instead of filling the machine. */
static uint64_t memory_budget(uint64_t size) {
  uint64_t lim = size < (1ull << 40) ? 64 * size : UINT64_MAX;
  if (lim < (1ull << 30)) lim = 1ull << 30;
  return lim < mem_limit() ? lim : mem_limit();
}

static void limit_memory(uint64_t budget) {
  FILE *f = fopen("/proc/self/statm", "r");
  unsigned long long pages = 0;
  int ok = f && fscanf(f, "%llu", &pages) == 1;
  if (f) fclose(f);
  long page = sysconf(_SC_PAGE_SIZE);
  if (!ok || page <= 0) return;
  uint64_t now = (uint64_t)pages * (uint64_t)page;
  if (budget > UINT64_MAX - now) return;
  struct rlimit rl = {(rlim_t)(now + budget), (rlim_t)(now + budget)};
  setrlimit(RLIMIT_AS, &rl);
}

static void write_all(int fd, const char *p, size_t n) {
  while (n > 0) {
    ssize_t w = write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return;
    p += w;
    n -= (size_t)w;
  }
}

static void child(int fd, const char *path, unsigned flags, uint64_t budget) {
  /* What a crashing Assimp prints (a sanitizer's report of Assimp's fault, under valo's
   * sanitizer builds) is not for the user: the parent names the file and what happened. */
  int null = open("/dev/null", O_WRONLY);
  if (null >= 0) {
    dup2(null, 1);
    dup2(null, 2);
    close(null);
  }
  limit_memory(budget);
  const struct aiScene *ai = aiImportFile(path, flags);
  char msg[512];
  if (ai) {
    msg[0] = PROBE_OK;
    msg[1] = 0;
  } else {
    const char *e = aiGetErrorString();
    int memory = e && strstr(e, "bad_alloc");
    snprintf(msg, sizeof msg, "%c%s", memory ? PROBE_MEMORY : PROBE_REFUSED, e && *e ? e : "unknown format");
  }
  write_all(fd, msg, strlen(msg));
  _exit(0); /* no atexit handlers, no stdio flush of the parent's buffers */
}

/* 30 s plus 2 s per MiB of the file, or VALO_IMPORT_TIMEOUT seconds. */
static double time_limit(uint64_t size) {
  const char *e = getenv("VALO_IMPORT_TIMEOUT");
  if (e && *e) {
    double v = strtod(e, NULL);
    if (v > 0) return v;
  }
  return 30.0 + 2.0 * (double)size / 1048576.0;
}

valo_status import_probe(const char *path, unsigned flags, valo_error *err) {
  int fds[2];
  if (pipe(fds)) return err_set(err, VALO_ERR_IO, "%s: cannot start the trial import: %s", path, strerror(errno));
  struct stat sb;
  uint64_t size = stat(path, &sb) == 0 && sb.st_size > 0 ? (uint64_t)sb.st_size : 0;
  uint64_t budget = memory_budget(size);
  fflush(NULL); /* nothing buffered is written twice */
  pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    return err_set(err, VALO_ERR_IO, "%s: cannot start the trial import: %s", path, strerror(errno));
  }
  if (pid == 0) {
    close(fds[0]);
    child(fds[1], path, flags, budget);
  }
  close(fds[1]);
  double limit = time_limit(size), end = now_seconds() + limit;
  char msg[512];
  size_t len = 0;
  int timed_out = 0;
  for (;;) {
    double left = end - now_seconds();
    if (left <= 0) { timed_out = 1; break; }
    struct pollfd p = {fds[0], POLLIN, 0};
    int r = poll(&p, 1, left > 1000.0 ? 1000000 : (int)(left * 1000.0) + 1);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) continue;
    ssize_t n = read(fds[0], msg + len, sizeof msg - 1 - len);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break; /* the child closed the pipe: it finished or died */
    len += (size_t)n;
    if (len == sizeof msg - 1) break;
  }
  close(fds[0]);
  msg[len] = 0;
  if (timed_out) kill(pid, SIGKILL);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
  if (timed_out)
    return err_set(err, VALO_ERR_PARSE,
                   "%s: Assimp did not finish reading the file within %g s, so valo stopped it "
                   "(VALO_IMPORT_TIMEOUT=SECONDS sets the limit)",
                   path, limit);
  if (len > 0 && msg[0] == PROBE_OK) return VALO_OK;
  if (len > 0 && msg[0] == PROBE_MEMORY) {
    return err_set(err, VALO_ERR_NOMEM, "%s: Assimp ran out of memory reading the file (%s): it may use %.1f GiB, "
                   "64 times the file's size, at least 1 GiB, at most valo's memory limit",
                   path, msg + 1, (double)budget / 1073741824.0);
  }
  if (len > 0 && msg[0] == PROBE_REFUSED) { /* as load_mesh says it of checked formats */
    const char *ext = strrchr(path, '.');
    return err_set(err, VALO_ERR_PARSE, "%s: not a mesh file valo can read (%s) (the importer said: %s)", path,
                   ext ? ext + 1 : "no extension", msg + 1);
  }
  /* The child writes its result before it exits, so without one it crashed: a signal, or
   * (under valo's sanitizer builds) a sanitizer's report of Assimp's fault and exit 1. */
  char how[64];
  if (WIFSIGNALED(status)) snprintf(how, sizeof how, "%s", strsignal(WTERMSIG(status)));
  else snprintf(how, sizeof how, "it exited with status %d", WIFEXITED(status) ? WEXITSTATUS(status) : -1);
  return err_set(err, VALO_ERR_PARSE,
                 "%s: Assimp crashed reading the file (%s); valo checks OBJ, PLY and glTF files itself, other "
                 "formats only as far as Assimp does",
                 path, how);
}
