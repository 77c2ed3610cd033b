/* grow.h — owns appending to arrays one element at a time: capacities run 1, 2, 4, 8, ...,
 * so n appends copy O(n) elements in all. Growing by one element per realloc is quadratic
 * wherever realloc cannot extend in place (always under ASan: 30 000 Mitsuba shapes took
 * minutes there). */
#ifndef VALO_GROW_H
#define VALO_GROW_H
#include <stdlib.h>

/* The array p, holding n elements of elem bytes and only ever grown by grow_for, with
 * room for element n: p itself, or its reallocation (NULL when out of memory, p still
 * valid). */
static inline void *grow_for(void *p, size_t n, size_t elem) {
  if (n & (n - 1)) return p; /* n is no power of two: its capacity, the next one, has room */
  return realloc(p, (n ? 2 * n : 1) * elem);
}
#endif
