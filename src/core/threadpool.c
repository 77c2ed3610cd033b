/* threadpool.c — see threadpool.h. */
#include "core/threadpool.h"
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

typedef struct pf_shared { parallel_fn fn; void *user; int64_t n; atomic_llong next; } pf_shared;
typedef struct pf_arg { pf_shared *sh; int index; } pf_arg;

static void *pf_worker(void *p) {
  pf_arg *a = p;
  for (;;) {
    int64_t i = atomic_fetch_add(&a->sh->next, 1);
    if (i >= a->sh->n) break;
    a->sh->fn(a->sh->user, i, a->index);
  }
  return NULL;
}

int parallel_for(int threads, int64_t n, parallel_fn fn, void *user) {
  if (threads < 1) threads = 1;
  pf_shared sh = {fn, user, n, 0};
  atomic_init(&sh.next, 0);
  pthread_t *tid = calloc((size_t)threads, sizeof *tid);
  pf_arg *args = calloc((size_t)threads, sizeof *args);
  int started = 0, rc = 0;
  if (!tid || !args) { rc = -1; threads = 1; }
  for (int t = 1; t < threads; t++) {
    args[t].sh = &sh; args[t].index = t;
    if (pthread_create(&tid[t], NULL, pf_worker, &args[t]) != 0) { rc = -1; break; }
    started = t;
  }
  pf_arg self = {&sh, 0};
  pf_worker(&self);
  for (int t = 1; t <= started; t++) pthread_join(tid[t], NULL);
  free(tid); free(args);
  return rc;
}

int threads_available(void) {
  long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n > 0 ? (int)n : 1;
}
