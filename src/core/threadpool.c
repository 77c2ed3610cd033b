/* threadpool.c — see threadpool.h. One job at a time: the poster publishes it under the
 * pool's mutex with a new generation number and wakes the workers; each worker whose
 * index is below the job's thread count claims items until none are left, then reports
 * done; the poster works as thread 0 and waits for them. */
#include "core/threadpool.h"
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <unistd.h>

#define POOL_MAX_WORKERS 1023

typedef struct pool {
  pthread_mutex_t post;       /* one job at a time */
  pthread_mutex_t m;          /* guards the fields below */
  pthread_cond_t work, done;
  int nworkers;               /* started, with indices 1..nworkers */
  uint64_t generation;        /* of the current job */
  int participants;           /* workers 1..participants-1 take part in it */
  int active;                 /* of those, still working */
  parallel_fn fn;
  void *user;
  int64_t n;
  atomic_llong next;
} pool;

static pool g_pool = {.post = PTHREAD_MUTEX_INITIALIZER, .m = PTHREAD_MUTEX_INITIALIZER, .work = PTHREAD_COND_INITIALIZER, .done = PTHREAD_COND_INITIALIZER};
static _Thread_local int t_in_loop; /* this thread is running a loop's items */

static void run_items(pool *p, int index) {
  for (;;) {
    int64_t i = atomic_fetch_add(&p->next, 1);
    if (i >= p->n) break;
    p->fn(p->user, i, index);
  }
}

/* A worker's start: its index and the generation before the first job it may take (a
 * job posted while it was starting is still its to take). */
typedef struct worker_start { int index; uint64_t seen; } worker_start;

static void *worker(void *arg) {
  pool *p = &g_pool;
  worker_start ws = *(worker_start *)arg;
  free(arg);
  int index = ws.index;
  uint64_t seen = ws.seen;
  t_in_loop = 1;
  pthread_mutex_lock(&p->m);
  for (;;) {
    while (p->generation == seen) pthread_cond_wait(&p->work, &p->m);
    seen = p->generation;
    if (index >= p->participants) continue;
    pthread_mutex_unlock(&p->m);
    run_items(p, index);
    pthread_mutex_lock(&p->m);
    if (--p->active == 0) pthread_cond_signal(&p->done);
  }
  return NULL;
}

/* Starts workers up to `want` (called with post held); keeps what it could start. */
static void ensure_workers(pool *p, int want) {
  if (want > POOL_MAX_WORKERS) want = POOL_MAX_WORKERS;
  while (p->nworkers < want) {
    pthread_t t;
    pthread_attr_t attr;
    worker_start *ws = malloc(sizeof *ws);
    if (!ws) return;
    pthread_mutex_lock(&p->m);
    ws->index = p->nworkers + 1;
    ws->seen = p->generation;
    pthread_mutex_unlock(&p->m);
    if (pthread_attr_init(&attr)) { free(ws); return; }
    pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
    int rc = pthread_create(&t, &attr, worker, ws);
    pthread_attr_destroy(&attr);
    if (rc) { free(ws); return; }
    pthread_mutex_lock(&p->m);
    p->nworkers++;
    pthread_mutex_unlock(&p->m);
  }
}

void parallel_for(int threads, int64_t n, parallel_fn fn, void *user) {
  pool *p = &g_pool;
  if (n <= 0) return;
  if (threads <= 1 || n == 1 || t_in_loop) {
    for (int64_t i = 0; i < n; i++) fn(user, i, 0);
    return;
  }
  pthread_mutex_lock(&p->post);
  ensure_workers(p, threads - 1);
  pthread_mutex_lock(&p->m);
  int k = threads - 1 < p->nworkers ? threads - 1 : p->nworkers;
  p->fn = fn;
  p->user = user;
  p->n = n;
  atomic_store(&p->next, 0);
  p->participants = k + 1;
  p->active = k;
  p->generation++;
  pthread_cond_broadcast(&p->work);
  pthread_mutex_unlock(&p->m);
  t_in_loop = 1;
  run_items(p, 0);
  t_in_loop = 0;
  pthread_mutex_lock(&p->m);
  while (p->active > 0) pthread_cond_wait(&p->done, &p->m);
  pthread_mutex_unlock(&p->m);
  pthread_mutex_unlock(&p->post);
}

int threads_available(void) {
  long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n > 0 ? (int)n : 1;
}
