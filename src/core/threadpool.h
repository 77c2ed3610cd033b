/* threadpool.h — owns the one pthreads pool: parallel_for over [0, n) work items claimed
 * with an atomic counter, the calling thread working too. Workers are started once per
 * call (render passes are long, so start-up cost is negligible). */
#ifndef VALO_THREADPOOL_H
#define VALO_THREADPOOL_H
#include <stdint.h>

typedef void (*parallel_fn)(void *user, int64_t item, int thread_index);
/* Runs fn(user, i, t) for every i in [0, n) on `threads` threads (t in [0, threads)).
 * Returns 0, or -1 if threads could not be started (then all work ran on the caller). */
int parallel_for(int threads, int64_t n, parallel_fn fn, void *user);
int threads_available(void);
#endif
