/* bench_util.h — owns what the benchmark programs share: a monotonic clock, the relMSE
 * they report (docs/performance.md), the many-light scenes' lamp mask and the Cornell scene file with the references'
 * camera. */
#ifndef VALO_BENCH_UTIL_H
#define VALO_BENCH_UTIL_H
#include <stdio.h>
#include <time.h>

/* Writes a scene file at path holding the mesh file obj seen by the shared references'
 * Cornell-box camera, on a w x h film; the caller removes it. 0 on success. */
static inline int bench_cornell_scene(const char *path, const char *obj, int w, int h) {
  FILE *f = fopen(path, "w");
  if (!f) return 1;
  fprintf(f, "{ \"camera\": {\"position\": [0,1,3.4], \"look_at\": [0,1,0], \"up\": [0,1,0], \"fov\": 40},\n"
             "  \"film\": {\"width\": %d, \"height\": %d}, \"shapes\": [ {\"file\": \"%s\"} ] }\n", w, h, obj);
  return fclose(f) != 0;
}

/* Seconds on a monotonic clock. */
static inline double bench_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The pixels to leave out of a many-light relMSE: ok[i] = 0 where em (w*h RGB: emission
 * seen directly, a render at depth 0) is non-zero at pixel i or one of its 8 neighbours,
 * 1 elsewhere. Lamps smaller than a pixel are equally noisy for every method. */
static inline void bench_lamp_mask(const float *em, int w, int h, unsigned char *ok) {
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      int bad = 0;
      for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
          int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
          const float *p = &em[3 * (yy * w + xx)];
          if (p[0] + p[1] + p[2] > 0) bad = 1;
        }
      ok[y * w + x] = !bad;
    }
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
