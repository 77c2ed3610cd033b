/* memlimit.c — owns the memory limit (sysconf's physical pages, lowered by
 * VALO_MEMORY_LIMIT) and the check that names what would not fit. */
#include "core/memlimit.h"
#include "core/error.h"
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

static uint64_t parse_size(const char *s) {
  char *end;
  double v = strtod(s, &end);
  if (end == s || !(v > 0)) return 0;
  switch (*end) {
  case 'k': case 'K': v *= 1024.0; break;
  case 'm': case 'M': v *= 1048576.0; break;
  case 'g': case 'G': v *= 1073741824.0; break;
  default: break;
  }
  return v >= 1.8e19 ? UINT64_MAX : (uint64_t)v;
}

uint64_t mem_limit(void) {
  long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  uint64_t phys = pages > 0 && page > 0 ? (uint64_t)pages * (uint64_t)page : UINT64_MAX;
  const char *e = getenv("VALO_MEMORY_LIMIT");
  uint64_t lim = e && *e ? parse_size(e) : 0;
  return lim && lim < phys ? lim : phys;
}

static void human(uint64_t b, char *out, size_t n) {
  if (b >= (1ull << 30)) snprintf(out, n, "%.1f GiB", (double)b / 1073741824.0);
  else if (b >= (1ull << 20)) snprintf(out, n, "%.1f MiB", (double)b / 1048576.0);
  else snprintf(out, n, "%.1f KiB", (double)b / 1024.0);
}

valo_status mem_check_pixels(uint64_t w, uint64_t h, uint64_t bytes_per_pixel, const char *name, valo_error *err) {
  char what[64];
  snprintf(what, sizeof what, "%llu x %llu pixels", (unsigned long long)w, (unsigned long long)h);
  return mem_check(w * h * bytes_per_pixel, name, what, err);
}

valo_status mem_check(uint64_t bytes, const char *name, const char *what, valo_error *err) {
  uint64_t lim = mem_limit();
  if (bytes <= lim) return VALO_OK;
  char need[32], have[32];
  human(bytes, need, sizeof need);
  human(lim, have, sizeof have);
  const char *e = getenv("VALO_MEMORY_LIMIT");
  return err_set(err, VALO_ERR_NOMEM, "%s: %s: %s needed, more than the %s of %s", name, what, need, have,
                 e && *e ? "VALO_MEMORY_LIMIT" : "this machine's memory");
}
