/* atomicfile.c — see atomicfile.h. */
#include "core/atomicfile.h"
#include <errno.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

int atomic_temp_name(const char *path, char *out, size_t n) {
  static atomic_uint counter;
  unsigned k = atomic_fetch_add(&counter, 1);
  const char *slash = strrchr(path, '/');
  int len = slash ? snprintf(out, n, "%.*s/.%s.tmp%ld.%u", (int)(slash - path), path, slash + 1, (long)getpid(), k)
                  : snprintf(out, n, ".%s.tmp%ld.%u", path, (long)getpid(), k);
  return len < 0 || (size_t)len >= n ? -1 : 0;
}

static int sync_path(const char *p) {
  int fd = open(p, O_RDONLY);
  if (fd < 0) return -1;
  int r = fsync(fd);
  close(fd);
  return r;
}

int atomic_commit(const char *tmp, const char *path) {
  if (sync_path(tmp) != 0 || rename(tmp, path) != 0) {
    int e = errno;
    remove(tmp);
    errno = e;
    return -1;
  }
  char dir[4096];
  const char *slash = strrchr(path, '/');
  snprintf(dir, sizeof dir, "%.*s", slash ? (slash == path ? 1 : (int)(slash - path)) : 1, slash ? path : ".");
  sync_path(dir); /* a folder that cannot be opened to sync still holds the file */
  return 0;
}
