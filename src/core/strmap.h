/* strmap.h — owns a map from strings to integers (open addressing, FNV-1a), so that
 * loaders find a name among many in constant time instead of by a walk. Keys are
 * borrowed: each must outlive the map. The first value put under a key stays. */
#ifndef VALO_STRMAP_H
#define VALO_STRMAP_H
#include <stddef.h>

typedef struct strmap {
  const char **keys; /* NULL: an empty slot */
  long *vals;
  size_t cap, n;     /* cap a power of two, n < cap / 2 */
} strmap;

/* Puts key -> val unless key is there already; 0, or -1 when out of memory. */
int strmap_put(strmap *m, const char *key, long val);
/* The value under key (the first put), or -1. */
long strmap_get(const strmap *m, const char *key);
void strmap_free(strmap *m);
#endif
