/* pointtree.h — owns the point kd-tree shared by the photon maps and proximity-AO's
 * splatted points (ARCHITECTURE.md: "one point kd-tree"): a balanced, implicit kd-tree
 * (Jensen's photon-map tree: the median of each range is its node, split on the range's
 * widest axis; no child pointers), with k-nearest and fixed-radius queries. The k-nearest
 * query can measure distance squeezed along a normal (d^2 + f (d.n)^2), the disc variant
 * against leaks through corners and thin walls. An optional hierarchy of tight boxes
 * over runs of the tree order serves the half-space radius query (proximity-AO). Built
 * once, then read by any number of threads. */
#ifndef VALO_POINTTREE_H
#define VALO_POINTTREE_H
#include "core/vec.h"
#include <stddef.h>
#include <stdint.h>

/* A node of the optional box hierarchy (point_tree_build_boxes), 32 bytes: the tight box
 * of its tree-order points; a leaf holds the points [a, b) (b > 0), an inner node its
 * right child's index in a and 0 in b (the left child is the next node). */
typedef struct point_box { float lo[3]; uint32_t a; float hi[3]; uint32_t b; } point_box;

typedef struct point_tree {
  vec3 *p;          /* the points in tree order */
  uint32_t *id;     /* id[i]: the caller's index of point i */
  uint8_t *axis;    /* split axis of the node at i */
  uint32_t n;
  bbox bounds;      /* of all points */
  point_box *box;   /* the box hierarchy, or NULL (point_tree_build_boxes) */
  uint32_t n_box;
} point_tree;

/* Builds the tree over pts[0..n) (copied). Returns 0, or -1 when out of memory. */
int point_tree_build(point_tree *t, const vec3 *pts, uint32_t n);
/* The one point-set build (photon maps, VPL radii, proximity points): the tree over the
 * positions at byte `pos_offset` of n records of `stride` bytes, and, when out is not
 * NULL, the records in tree order in *out (malloc'd; free it). 0, or -1 out of memory. */
int point_set_build(point_tree *t, const void *recs, uint32_t n, size_t stride, size_t pos_offset, void **out);
/* Another array of the same points into tree order: (*out)[i] = in[t->id[i]], elements
 * of `size` bytes (malloc'd). 0, or -1 out of memory. */
int point_tree_gather(const point_tree *t, const void *in, size_t size, void **out);
void point_tree_free(point_tree *t);

typedef struct point_near { float d2; uint32_t i; } point_near; /* i: tree order */
/* Up to k nearest points to q with (squeezed) squared distance < r2max, in out[] (any
 * order); returns how many. n_squeeze (unit) and squeeze f >= 0 give the metric
 * |v|^2 + f (v.n)^2 (f = 0: Euclidean). k <= POINT_KNN_MAX. */
#define POINT_KNN_MAX 1024
int point_tree_knn(const point_tree *t, vec3 q, int k, float r2max, vec3 n_squeeze, float f, point_near *out);
/* Calls fn for every point with |p - q|^2 < r2 (i in tree order). */
typedef void (*point_visit_fn)(void *user, uint32_t i, float d2);
void point_tree_radius(const point_tree *t, vec3 q, float r2, point_visit_fn fn, void *user);
/* Builds the box hierarchy the half-space queries below need: tight boxes over runs of
 * the tree order. 0, or -1 out of memory. */
int point_tree_build_boxes(point_tree *t);
/* Calls fn for every point with |p - q|^2 < r2 and (p - q).n > eps (n unit), skipping
 * whole boxes outside the sphere or behind the plane (needs point_tree_build_boxes). */
void point_tree_radius_halfspace(const point_tree *t, vec3 q, float r2, vec3 n, float eps, point_visit_fn fn, void *user);
/* The same search, handing the caller runs [lo, hi) of tree-order points that may
 * qualify (every qualifying point is in exactly one run; the caller tests each point),
 * so that a caller can keep its per-point data in tree-order arrays and test a run in a
 * branch-free loop. */
typedef void (*point_run_fn)(void *user, uint32_t lo, uint32_t hi);
void point_tree_halfspace_runs(const point_tree *t, vec3 q, float r2, vec3 n, float eps, point_run_fn fn, void *user);
#endif
