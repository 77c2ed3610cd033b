/* replay.c — owns the fuzz harnesses' plain driver, for builds without libFuzzer: it runs
 * the harness once on every file named (or every file in a folder named), so that the
 * seed corpus and the crashes fuzzing found (fuzz/regressions/) are tests of every build,
 * the sanitizer build included. */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int run_file(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) { fprintf(stderr, "replay: cannot open %s\n", path); return 1; }
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  uint8_t *b = malloc(n > 0 ? (size_t)n : 1);
  size_t got = b ? fread(b, 1, (size_t)(n > 0 ? n : 0), f) : 0;
  fclose(f);
  if (!b || got != (size_t)(n > 0 ? n : 0)) { free(b); fprintf(stderr, "replay: cannot read %s\n", path); return 1; }
  LLVMFuzzerTestOneInput(b, got);
  free(b);
  return 0;
}

int main(int argc, char **argv) {
  int files = 0, bad = 0;
  for (int i = 1; i < argc; i++) {
    struct stat sb;
    if (stat(argv[i], &sb)) { fprintf(stderr, "replay: %s does not exist\n", argv[i]); bad++; continue; }
    if (!S_ISDIR(sb.st_mode)) { bad += run_file(argv[i]); files++; continue; }
    DIR *d = opendir(argv[i]);
    struct dirent *e;
    while (d && (e = readdir(d))) {
      if (e->d_name[0] == '.') continue;
      char p[4096];
      snprintf(p, sizeof p, "%s/%s", argv[i], e->d_name);
      if (!stat(p, &sb) && S_ISREG(sb.st_mode)) { bad += run_file(p); files++; }
    }
    if (d) closedir(d);
  }
  fprintf(stderr, "replay: %d inputs, %d unreadable\n", files, bad);
  return bad || files == 0;
}
