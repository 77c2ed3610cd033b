/* kdtree_internal.h — owns the kd-tree's layout, shared by its build (kdtree_top.c,
 * kdtree_build.c) and its traversal (kdtree_traverse.c): the 8-byte nodes, box nodes,
 * the leaf triangle groups, the tree object and the build's triangle references. */
#ifndef VALO_KDTREE_INTERNAL_H
#define VALO_KDTREE_INTERNAL_H
#include "geometry/accel.h"
#include "geometry/triangle.h"
#include <stdint.h>

/* The SAH's costs, in units of one node step. Leaves are tested four triangles at a
 * time, so a leaf of n triangles costs KD_GROUP_COST per group of four, ceil(n / 4): the
 * seed's per-triangle form with a measured group cost in place of pbrt's 80 per
 * triangle (docs/performance.md). A node becomes a leaf when no split is cheaper.
 * KD_GROUP_COST and KD_DEPTH_FACTOR are overridable (-D) for bench_raykernel sweeps. */
#define KD_TRAVERSE_COST 1.0f
#ifndef KD_GROUP_COST
#define KD_GROUP_COST 2.0f
#endif
#ifndef KD_DEPTH_FACTOR
#define KD_DEPTH_FACTOR 1.2f /* depth limit 8 + KD_DEPTH_FACTOR log2 N */
#endif
#define KD_EMPTY_BONUS 0.5f
static inline float kd_leaf_cost(uint32_t n) { return KD_GROUP_COST * (float)((n + 3) / 4); }
#define KD_LEAF 3u
#define KD_BELOW_EMPTY 4u /* interior: the child below the plane is an empty leaf, not stored */
#define KD_ABOVE_EMPTY 8u /* interior: the child above the plane is an empty leaf, not stored */
#define KD_MAX_NODES (1u << 28)

/* 8 bytes: split position or leaf primitive offset; low 2 bits of flags: axis or leaf.
 * Leaf: upper 30 bits = primitive count. Interior: bits 2-3 = KD_BELOW_EMPTY and
 * KD_ABOVE_EMPTY, upper 28 bits = index of the above child; the below child, when
 * stored, follows its parent. Empty leaves (over half of all leaves: the SAH cuts off
 * empty space) are not stored, so rays never load them.
 * Box node: both empty bits set (no split makes that). The SAH's empty-space cuts come
 * in chains (a cut whose one child is the next cut); after the build each chain becomes
 * one box node: the node, then 3 slots holding the box's lo[3] and hi[3] (an infinite
 * face where the chain does not cut), then the chain's non-empty end; so every split
 * left has two stored children, and the empty bits only mark boxes. A ray clips its
 * interval to the box without a branch per plane: each cut was a hard-to-predict branch,
 * and bounce rays pass about 20 of them (docs/performance.md). */
typedef struct kd_node {
  union { float split; uint32_t prim_offset; };
  uint32_t flags;
} kd_node;

/* A leaf's triangles are stored in leaf order, vertices inline, in groups of four laid
 * out for SSE (v[vertex][axis][lane]), so a leaf is read sequentially and tested four
 * triangles at a time (tri4_intersect). Unused lanes of a leaf's last group repeat its
 * first triangle and are masked by the leaf's count. Triangle ids (read only for a hit)
 * and alpha-filter lanes sit in parallel arrays: triangle data is where the cache
 * misses are (docs/performance.md), so the groups hold vertices only. */
typedef struct kd_tri4 { float v[3][3][4]; } kd_tri4; /* 144 bytes */

typedef struct kdtree {
  accel base;
  float *tv;          /* build only: 9 floats per triangle: v0 v1 v2 */
  uint32_t ntris;
  kd_node *nodes;
  uint32_t nnodes, cap_nodes;
  kd_tri4 *prims;     /* leaf-ordered triangle groups */
  uint32_t *ids;      /* 4 per group: triangle index (UINT32_MAX in unused lanes) */
  uint8_t *gfilt;     /* per group: lanes that need the hit filter (alpha) */
  accel_filter filter;
  int has_filter;
  uint64_t nprims, cap_prims;
  bbox bounds;
  uint32_t max_depth_seen;
  kd_stats st;        /* counted before empty cuts become box nodes */
} kdtree;


/* Box nodes: both empty bits set; the node, then KD_BOX_SLOTS - 1 slots of bounds. */
#define KD_BOX (KD_BELOW_EMPTY | KD_ABOVE_EMPTY)
#define KD_BOX_SLOTS 4u

/* A triangle reference during the build: its bounds clipped to the node's box. */
typedef struct kd_ref { float lo[3], hi[3]; uint32_t tri; } kd_ref;

/* The exact sweep (kdtree_build.c), used by the whole build (kdtree_top.c). */
int kd_clip_split(const float *v, bbox box, int axis, float pos, bbox lbox, bbox rbox, bbox *l, bbox *r);
/* Appends a node to a growing array; UINT32_MAX when out of memory or nodes. */
uint32_t kd_node_push(kd_node **nodes, uint32_t *n, uint32_t *cap);
/* A build thread's stack of scratch blocks (kdtree_build.c). */
#define KD_ARENA_BLOCKS 40
typedef struct kd_arena { char *blk[KD_ARENA_BLOCKS]; size_t cap[KD_ARENA_BLOCKS], off; int nblk, cur; } kd_arena;
void kd_arena_free(kd_arena *a);
int kd_build_part(kdtree *part, uint8_t *side, kd_arena *arena, bbox box, const kd_ref *refs, uint32_t n, int depth);
int kd_box_nodes(kdtree *kd);

/* The kd-tree's accelerator operations (kdtree_traverse.c). */
extern const accel_ops kdtree_ops;
void kdtree_free(kdtree *kd);
#endif
