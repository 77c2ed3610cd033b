/* fuzz_util.h — owns what the fuzz harnesses share: a private scratch folder (inputs that
 * valo reads by path are written there under a fixed name) and a warning handler that
 * keeps valo quiet, so that a run prints only what libFuzzer reports. */
#ifndef VALO_FUZZ_UTIL_H
#define VALO_FUZZ_UTIL_H
#include "valo/valo.h"
#include <stddef.h>
#include <stdint.h>

/* Writes the input to `name` in the scratch folder; returns its path (static), or NULL. */
const char *fuzz_file(const char *name, const uint8_t *data, size_t size);
/* Silences valo's warnings and notes (once per process). */
void fuzz_quiet(void);
#endif
