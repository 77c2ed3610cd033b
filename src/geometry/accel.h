/* accel.h — owns the one ray-query interface (ARCHITECTURE "Acceleration"): a small ops
 * table {intersect, occluded, destroy} implemented by the SAH kd-tree (kdtree_top.c,
 * kdtree_build.c, kdtree_traverse.c) and by Embree 3 (embree.c), chosen by name when a
 * render is created. Rays have no tmin: origins
 * are offset robustly instead (offset.h), and hits need t > 0. */
#ifndef VALO_ACCEL_H
#define VALO_ACCEL_H
#include "core/vec.h"
#include "core/rng.h"
#include "valo/valo.h"
#include <string.h>

typedef struct ray { vec3 o, d; float tmax; } ray;
/* b1, b2: barycentric weights of the triangle's second and third vertex. */
typedef struct hit { float t, b1, b2; uint32_t tri; } hit;

/* A 64-bit hash of a ray's origin and direction bits (core/rng.h's mixer per word). */
static inline uint64_t accel_ray_key(vec3 o, vec3 d) {
  const float f[6] = {o.x, o.y, o.z, d.x, d.y, d.z};
  uint64_t h = 0x9E3779B97F4A7C15ull;
  for (int i = 0; i < 6; i++) {
    uint32_t b;
    memcpy(&b, &f[i], 4);
    h = rng_mix64(h ^ b ^ ((uint64_t)i << 32));
  }
  return h;
}

typedef struct accel accel;
typedef struct accel_ops {
  const char *name;
  /* Closest hit with 0 < t < r->tmax; returns 1 and fills h on a hit. */
  int (*intersect)(const accel *a, const ray *r, hit *h);
  /* Any hit with 0 < t < r->tmax. */
  int (*occluded)(const accel *a, const ray *r);
  void (*destroy)(accel *a);
  /* n any-hit queries at once (blocked[i] = occluded(r[i])), or NULL: one at a time.
   * Embree's stream query (rtcOccluded1M) groups the rays into packets. */
  void (*occluded_n)(const accel *a, const ray *r, uint8_t *blocked, int n);
} accel_ops;
struct accel { const accel_ops *ops; };

/* An optional hit filter (alpha cutouts, stochastic opacity): for triangles whose
 * tri_flags[t] has flag_bit set, a hit counts only if pass(user, t, b1, b2, key) returns
 * non-zero — for closest-hit and any-hit queries alike. key is accel_ray_key of the
 * query's ray, the same for both backends, so a random choice made from it and the
 * triangle is the same each time the ray meets that triangle, on any thread. */
typedef struct accel_filter {
  int (*pass)(const void *user, uint32_t tri, float b1, float b2, uint64_t key);
  const void *user;
  const uint8_t *tri_flags;
  uint8_t flag_bit;
} accel_filter;

/* kind: "kdtree" or "embree". Triangles are given as indexed vertices, npos of them
 * readable at pos. The kd-tree keeps its own copy; Embree shares pos and idx (they must
 * outlive the structure) when at least one vertex past the highest one the triangles use
 * is readable (Embree reads each vertex with a 16-byte load; scene_commit keeps a spare),
 * else it copies them. Sharing means a hit's corners are in cache when it is shaded. threads: used by builders that can use them (the kd-tree's build
 * gives the same tree for any count; <= 0: all). filter: NULL or one that outlives the
 * structure. */
valo_status accel_create(const char *kind, const vec3 *pos, uint32_t npos, const uint32_t *idx, uint32_t ntris, int threads,
                         const accel_filter *filter, accel **out, valo_error *err);
static inline int accel_intersect(const accel *a, const ray *r, hit *h) { return a->ops->intersect(a, r, h); }
static inline int accel_occluded(const accel *a, const ray *r) { return a->ops->occluded(a, r); }
static inline void accel_occluded_n(const accel *a, const ray *r, uint8_t *blocked, int n) {
  if (a->ops->occluded_n) { a->ops->occluded_n(a, r, blocked, n); return; }
  for (int i = 0; i < n; i++) blocked[i] = (uint8_t)a->ops->occluded(a, &r[i]);
}
static inline void accel_destroy(accel *a) { if (a) a->ops->destroy(a); }

valo_status kdtree_create(const vec3 *pos, const uint32_t *idx, uint32_t ntris, int threads, const accel_filter *filter, accel **out,
                          valo_error *err);
valo_status embree_create(const vec3 *pos, uint32_t npos, const uint32_t *idx, uint32_t ntris, const accel_filter *filter, accel **out,
                          valo_error *err);
int embree_available(void);

/* Statistics of a built kd-tree (for benchmarks and tests). */
typedef struct kd_stats { uint32_t nodes, leaves, empty_leaves, max_depth; uint64_t refs; size_t bytes; } kd_stats;
void kdtree_stats(const accel *a, kd_stats *st);
/* For bench_raykernel's bound on what faster leaves could give. kdtree_trace runs a
 * query (any: any hit), counting into tr what it visits, and records the leaf node where
 * it ended (its hit or its blocker found there) with that t. kdtree_walk repeats the
 * walk with no triangle tested, taking the hit from tr when it reaches that leaf; with
 * count > 0 it recounts nodes, boxes and leaves into tr, with count < 0 it walks only
 * the descent to the first leaf (what a traversal starting at the origin's leaf skips).
 * descent: nodes up to the first leaf, it included (all when none); dup_groups: groups
 * whose every triangle the query had tested in an earlier leaf (mailboxing's most). */
typedef struct kd_trace { uint32_t nodes, boxes, leaves, groups, dup_groups, descent, end_leaf; float t; } kd_trace;
int kdtree_trace(const accel *a, const ray *r, int any, kd_trace *tr);
int kdtree_walk(const accel *a, const ray *r, int any, kd_trace *tr, int count);
#endif
