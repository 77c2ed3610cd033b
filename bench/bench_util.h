/* bench_util.h — owns what the benchmark programs share: a monotonic clock and the
 * relMSE they report (docs/performance.md). */
#ifndef VALO_BENCH_UTIL_H
#define VALO_BENCH_UTIL_H
#include <time.h>

/* Seconds on a monotonic clock. */
static inline double bench_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* relMSE of RGB image a against reference b (n pixels): the mean over pixels and channels
 * of (a - b)^2 / (b^2 + 0.01); only pixels i with mask[i] != 0 when mask is not NULL. */
static inline double bench_relmse(const float *a, const float *b, int n, const unsigned char *mask) {
  double e = 0;
  long cnt = 0;
  for (int i = 0; i < n; i++) {
    if (mask && !mask[i]) continue;
    for (int c = 0; c < 3; c++) {
      double d = a[3 * i + c] - b[3 * i + c];
      e += d * d / (b[3 * i + c] * b[3 * i + c] + 0.01);
    }
    cnt += 3;
  }
  return cnt ? e / (double)cnt : 0;
}
#endif
