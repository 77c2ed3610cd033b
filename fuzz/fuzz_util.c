/* fuzz_util.c — see fuzz_util.h. */
#include "fuzz_util.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void drop(void *user, const char *message) { (void)user; (void)message; }

void fuzz_quiet(void) {
  static int done;
  if (!done) { valo_set_warning_handler(drop, NULL); done = 1; }
}

const char *fuzz_file(const char *name, const uint8_t *data, size_t size) {
  static char dir[256], path[512];
  if (!dir[0]) {
    const char *t = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/valo-fuzz-XXXXXX", t && *t ? t : "/tmp");
    if (!mkdtemp(dir)) { dir[0] = 0; return NULL; }
  }
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "wb");
  if (!f) return NULL;
  size_t w = size ? fwrite(data, 1, size, f) : 0;
  if (fclose(f) || w != size) return NULL;
  return path;
}
