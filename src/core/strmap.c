/* strmap.c — see strmap.h. */
#include "core/strmap.h"
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static uint64_t fnv1a(const char *s) {
  uint64_t h = 1469598103934665603ull;
  for (; *s; s++) h = (h ^ (unsigned char)*s) * 1099511628211ull;
  return h;
}

/* The slot holding key, or the empty one where it would go. */
static size_t slot(const strmap *m, const char *key) {
  size_t i = (size_t)fnv1a(key) & (m->cap - 1);
  while (m->keys[i] && strcmp(m->keys[i], key)) i = (i + 1) & (m->cap - 1);
  return i;
}

static int grow(strmap *m) {
  strmap g = {calloc(m->cap ? 2 * m->cap : 16, sizeof *g.keys), malloc((m->cap ? 2 * m->cap : 16) * sizeof *g.vals), m->cap ? 2 * m->cap : 16, m->n};
  if (!g.keys || !g.vals) { free(g.keys); free(g.vals); return -1; }
  for (size_t i = 0; i < m->cap; i++)
    if (m->keys[i]) {
      size_t j = slot(&g, m->keys[i]);
      g.keys[j] = m->keys[i];
      g.vals[j] = m->vals[i];
    }
  strmap_free(m);
  *m = g;
  return 0;
}

int strmap_put(strmap *m, const char *key, long val) {
  if (2 * (m->n + 1) > m->cap && grow(m)) return -1;
  size_t i = slot(m, key);
  if (m->keys[i]) return 0;
  m->keys[i] = key;
  m->vals[i] = val;
  m->n++;
  return 0;
}

long strmap_get(const strmap *m, const char *key) {
  if (!m->cap) return -1;
  size_t i = slot(m, key);
  return m->keys[i] ? m->vals[i] : -1;
}

void strmap_free(strmap *m) {
  free(m->keys);
  free(m->vals);
  memset(m, 0, sizeof *m);
}
