/* test_core.c — the core module's tables and services: the random-stream table (no two
 * uses of one stream share a dimension, every stream key differs), and the thread pool
 * (every item runs exactly once, on a valid thread index, for any count and repeatedly). */
#include "harness.h"
#include "core/streams.h"
#include "core/threadpool.h"
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

static int streams_disjoint(void) {
  int rows = 0;
  for (const stream_use *a = stream_uses; a->stream; a++, rows++) {
    CHECK(a->lo < a->hi, "%s / %s: empty range [%u, %u)", a->stream, a->use, a->lo, a->hi);
    for (const stream_use *b = a + 1; b->stream; b++) {
      if (strcmp(a->stream, b->stream)) continue;
      CHECK(a->hi <= b->lo || b->hi <= a->lo, "stream %s: \"%s\" [%u, %u) and \"%s\" [%u, %u) overlap", a->stream, a->use, a->lo, a->hi,
            b->use, b->lo, b->hi);
    }
  }
  int keys = 0;
  for (const uint64_t *k = stream_keys; *k; k++, keys++)
    for (const uint64_t *l = k + 1; *l; l++) CHECK(*k != *l, "two streams share the key %llx", (unsigned long long)*k);
  fprintf(stderr, "%d uses of streams checked, %d keys\n", rows, keys);
  CHECK(rows >= 15 && keys >= 4, "the table is too short (%d rows, %d keys)", rows, keys);
  /* and the check itself catches an overlap */
  stream_use bad[3] = {{"s", "a", 0, 4}, {"s", "b", 3, 5}, {NULL, NULL, 0, 0}};
  CHECK(!(bad[0].hi <= bad[1].lo || bad[1].hi <= bad[0].lo), "the overlap test misses [0,4) and [3,5)");
  return 0;
}

typedef struct pool_job { atomic_int *hits; int threads; atomic_int bad; } pool_job;
static void pool_item(void *user, int64_t item, int thread) {
  pool_job *j = user;
  atomic_fetch_add(&j->hits[item], 1);
  if (thread < 0 || thread >= j->threads) atomic_fetch_add(&j->bad, 1);
}
static int thread_pool(void) {
  const int64_t n = 10000;
  atomic_int *hits = calloc((size_t)n, sizeof *hits);
  for (int round = 0; round < 50; round++) {
    int threads = 1 + round % 7;
    int64_t m = round % 5 == 4 ? 0 : n - round; /* empty and odd-sized loops too */
    memset(hits, 0, (size_t)n * sizeof *hits);
    pool_job j = {hits, threads, 0};
    parallel_for(threads, m, pool_item, &j);
    for (int64_t i = 0; i < n; i++) CHECK(atomic_load(&hits[i]) == (i < m), "round %d: item %lld ran %d times", round, (long long)i, atomic_load(&hits[i]));
    CHECK(atomic_load(&j.bad) == 0, "a thread index out of range");
  }
  free(hits);
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"streams_disjoint", streams_disjoint}, {"thread_pool", thread_pool}, {NULL, NULL}};
  return test_main(argc, argv, cases);
}
