/* stats.h — owns the per-thread counters every ray-tracing stage keeps (rays traced,
 * samples lost by cause, surface samples drawn) and the check that a sample is usable. */
#ifndef VALO_STATS_H
#define VALO_STATS_H
#include "core/vec.h"
#include "valo/valo.h"
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* 64 bytes each: rays traced, losses by cause (valo_loss) and surface samples drawn (the
 * base of the per-vertex loss fractions). */
typedef struct thread_stats {
  uint64_t rays;
  uint64_t lost[VALO_LOSS_COUNT];
  uint64_t surface_samples;
  char pad[64 - (2 + VALO_LOSS_COUNT) * sizeof(uint64_t)]; /* arrays of these: no false sharing */
} thread_stats;
/* n zeroed thread_stats on 64-byte boundaries (free with free()): the padding above keeps
 * the threads' counters apart only if the array starts on a cache line, which calloc does
 * not promise. NULL when out of memory. */
static inline thread_stats *thread_stats_alloc(int n) {
  thread_stats *ts = aligned_alloc(64, (size_t)(n > 0 ? n : 1) * sizeof *ts);
  if (ts) memset(ts, 0, (size_t)(n > 0 ? n : 1) * sizeof *ts);
  return ts;
}
static inline void thread_stats_add(thread_stats *into, const thread_stats *from) {
  into->rays += from->rays;
  into->surface_samples += from->surface_samples;
  for (int k = 0; k < VALO_LOSS_COUNT; k++) into->lost[k] += from->lost[k];
}
/* Counts L's loss cause and returns 0 when L is NaN, infinite or negative; 1 if usable. */
static inline int sample_usable(thread_stats *ts, rgb L) {
  if (c3_finite(L) && L.r >= 0 && L.g >= 0 && L.b >= 0) return 1;
  int nan = isnan(L.r) || isnan(L.g) || isnan(L.b);
  ts->lost[nan ? VALO_LOSS_NAN : !c3_finite(L) ? VALO_LOSS_INF : VALO_LOSS_NEGATIVE]++;
  return 0;
}
/* A short name for a loss cause ("NaN", "infinite", ...). */
static inline const char *stats_loss_name(int cause) {
  static const char *const names[VALO_LOSS_COUNT] = {"NaN", "infinite", "negative", "BSDF non-finite", "shading normal"};
  return cause >= 0 && cause < VALO_LOSS_COUNT ? names[cause] : "unknown";
}
#endif
