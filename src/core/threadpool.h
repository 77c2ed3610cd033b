/* threadpool.h — owns the one thread pool: workers started once (on first use, more
 * when a loop asks for more threads) and kept for the process; parallel_for hands out
 * [0, n) work items through an atomic counter, the calling thread working too. */
#ifndef VALO_THREADPOOL_H
#define VALO_THREADPOOL_H
#include <stdint.h>

typedef void (*parallel_fn)(void *user, int64_t item, int thread_index);
/* Runs fn(user, i, t) for every i in [0, n), on up to `threads` threads (t in [0, threads);
 * the caller is t = 0), and returns when all have run. It cannot fail: where workers
 * cannot be started, fewer threads (at worst the caller alone) run every item. Loops
 * from different threads take turns; a loop started inside a loop runs on its caller. */
void parallel_for(int threads, int64_t n, parallel_fn fn, void *user);
int threads_available(void);
#endif
