/* atomicfile.c — see atomicfile.h. */
#include "core/atomicfile.h"
#include <errno.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* path with the symbolic links of its last part followed: the file a write through path
 * reaches, so that the rename replaces that file and keeps the links. The folders on the
 * way are the kernel's to follow, the same for the temporary file and the target.
 * *via_proc: a link on the way was under /proc (/dev/stdout -> /proc/self/fd/1), whose
 * links name open files, not paths to replace ("pipe:[...]"). */
static int follow_links(const char *path, char *out, size_t n, int *via_proc) {
  char cur[4096], link[4096];
  *via_proc = 0;
  if (snprintf(cur, sizeof cur, "%s", path) >= (int)sizeof cur) { errno = ENAMETOOLONG; return -1; }
  for (int hops = 0;; hops++) {
    struct stat st;
    if (lstat(cur, &st) != 0 || !S_ISLNK(st.st_mode)) break;
    if (hops == 40) { errno = ELOOP; return -1; }
    if (!strncmp(cur, "/proc/", 6)) *via_proc = 1;
    ssize_t k = readlink(cur, link, sizeof link - 1);
    if (k < 0) return -1;
    link[k] = 0;
    const char *slash = strrchr(cur, '/');
    char next[4096];
    int len = link[0] == '/' || !slash ? snprintf(next, sizeof next, "%s", link)
                                       : snprintf(next, sizeof next, "%.*s/%s", (int)(slash - cur), cur, link);
    if (len < 0 || len >= (int)sizeof next) { errno = ENAMETOOLONG; return -1; }
    memcpy(cur, next, (size_t)len + 1);
  }
  if (snprintf(out, n, "%s", cur) >= (int)n) { errno = ENAMETOOLONG; return -1; }
  return 0;
}

/* Where a write to path goes: 1 in place (a FIFO, a device such as /dev/null, or an open
 * file named through /proc, as /dev/stdout is), 0 by renaming a temporary file over
 * target (path with its links followed), -1 on error. */
static int destination(const char *path, char *target, size_t n) {
  int via_proc;
  if (follow_links(path, target, n, &via_proc)) return -1;
  struct stat st;
  return via_proc || (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) ? 1 : 0;
}

int atomic_temp_name(const char *path, char *out, size_t n) {
  static atomic_uint counter;
  unsigned k = atomic_fetch_add(&counter, 1);
  char target[4096];
  int len, where = destination(path, target, sizeof target);
  if (where < 0) return -1;
  if (where == 1) { /* beside nothing: a file in the temporary folder, copied in by atomic_commit */
    const char *t = getenv("TMPDIR");
    len = snprintf(out, n, "%s/.valo-out.tmp%ld.%u", t && *t ? t : "/tmp", (long)getpid(), k);
  } else {
    const char *slash = strrchr(target, '/');
    len = slash ? snprintf(out, n, "%.*s/.%s.tmp%ld.%u", (int)(slash - target), target, slash + 1, (long)getpid(), k)
                : snprintf(out, n, ".%s.tmp%ld.%u", target, (long)getpid(), k);
  }
  return len < 0 || (size_t)len >= n ? -1 : 0;
}

static int sync_path(const char *p) {
  int fd = open(p, O_RDONLY);
  if (fd < 0) return -1;
  int r = fsync(fd);
  close(fd);
  return r;
}

/* The bytes of tmp written into path as it is (a stream or a device). */
static int copy_into(const char *tmp, const char *path) {
  int in = open(tmp, O_RDONLY), out = in < 0 ? -1 : open(path, O_WRONLY | O_TRUNC);
  int r = in < 0 || out < 0 ? -1 : 0;
  char b[65536];
  while (r == 0) {
    ssize_t k = read(in, b, sizeof b);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) { r = k < 0 ? -1 : 0; break; }
    for (ssize_t o = 0; o < k && r == 0;) {
      ssize_t w = write(out, b + o, (size_t)(k - o));
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) r = -1;
      else o += w;
    }
  }
  int e = errno;
  if (in >= 0) close(in);
  if (out >= 0 && close(out) != 0 && r == 0) { r = -1; e = errno; }
  remove(tmp);
  errno = e;
  return r;
}

int atomic_commit(const char *tmp, const char *path) {
  char target[4096];
  int where = destination(path, target, sizeof target);
  if (where == 1) return copy_into(tmp, path);
  if (where < 0 || sync_path(tmp) != 0 || rename(tmp, target) != 0) {
    int e = errno;
    remove(tmp);
    errno = e;
    return -1;
  }
  char dir[4096];
  const char *slash = strrchr(target, '/');
  snprintf(dir, sizeof dir, "%.*s", slash ? (slash == target ? 1 : (int)(slash - target)) : 1, slash ? target : ".");
  sync_path(dir); /* a folder that cannot be opened to sync still holds the file */
  return 0;
}

int atomic_write(const char *path, const void *data, size_t n) {
  char tmp[4200];
  if (atomic_temp_name(path, tmp, sizeof tmp)) return -1;
  FILE *f = fopen(tmp, "wb");
  if (!f) return -1;
  int bad = n && fwrite(data, 1, n, f) != n;
  bad |= fclose(f) != 0;
  if (bad) {
    int e = errno;
    remove(tmp);
    errno = e;
    return -1;
  }
  return atomic_commit(tmp, path);
}
