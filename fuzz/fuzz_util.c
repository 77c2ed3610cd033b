/* fuzz_util.c — see fuzz_util.h. The scratch folder and its files are removed at exit
 * (libFuzzer's crash path leaves them, with the input it reports). */
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

static char g_dir[256];
static char g_names[8][64];
static int g_nnames;

/* At exit: the files written and the folder go. */
static void cleanup(void) {
  char p[512];
  for (int i = 0; i < g_nnames; i++) {
    snprintf(p, sizeof p, "%s/%s", g_dir, g_names[i]);
    remove(p);
  }
  rmdir(g_dir);
}

const char *fuzz_file(const char *name, const uint8_t *data, size_t size) {
  static char path[512];
  if (!g_dir[0]) {
    const char *t = getenv("TMPDIR");
    snprintf(g_dir, sizeof g_dir, "%s/valo-fuzz-XXXXXX", t && *t ? t : "/tmp");
    if (!mkdtemp(g_dir)) { g_dir[0] = 0; return NULL; }
    atexit(cleanup);
  }
  int known = 0;
  for (int i = 0; i < g_nnames; i++) known |= !strcmp(g_names[i], name);
  if (!known && g_nnames < 8) snprintf(g_names[g_nnames++], sizeof g_names[0], "%s", name);
  snprintf(path, sizeof path, "%s/%s", g_dir, name);
  FILE *f = fopen(path, "wb");
  if (!f) return NULL;
  size_t w = size ? fwrite(data, 1, size, f) : 0;
  if (fclose(f) || w != size) return NULL;
  return path;
}
