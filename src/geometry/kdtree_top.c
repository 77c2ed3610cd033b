/* kdtree_top.c — owns building the kd-tree as a whole (layout: kdtree_internal.h). The
 * top levels, where nodes hold many triangles, choose their splits by binned SAH over
 * clipped triangle references (one pass over a node's references per level, no sorted
 * event lists); nodes of at most KD_BIN_MIN references become subtrees built by the exact
 * sweep of kdtree_build.c, in parallel on the thread pool, then joined in depth-first
 * order. The top levels and every subtree depend on the mesh alone, so the tree and its
 * memory layout are the same for any thread count. */
#include "geometry/kdtree_internal.h"
#include "core/error.h"
#include "core/threadpool.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef KD_BIN_MIN
#define KD_BIN_MIN 1024u /* references: at or below, the exact sweep (docs/performance.md) */
#endif
#define KD_BINS 32
#define KD_BUILD_THREADS_MAX 16

/* A subtree left to the exact sweep: its references and, once built, its part. */
typedef struct kd_task { bbox box; kd_ref *refs; uint32_t n; int depth; kdtree part; } kd_task;

typedef struct kd_top {
  kdtree *kd;
  kd_node *nodes;           /* the top levels; every leaf is a task (prim_offset: its index) */
  uint32_t nnodes, cap_nodes;
  kd_task *tasks;
  uint32_t ntasks, cap_tasks;
  uint32_t limit;           /* nodes of at most this many references become tasks */
  int oom;
} kd_top;

static uint32_t top_push(kd_top *t) {
  uint32_t i = kd_node_push(&t->nodes, &t->nnodes, &t->cap_nodes);
  if (i == UINT32_MAX) t->oom = 1;
  return i;
}

/* Leaves the node to the exact sweep; takes ownership of refs. */
static void top_task(kd_top *t, uint32_t node, bbox box, kd_ref *refs, uint32_t n, int depth) {
  if (t->ntasks == t->cap_tasks) {
    uint32_t nc = t->cap_tasks ? t->cap_tasks * 2 : 64;
    kd_task *k = realloc(t->tasks, (size_t)nc * sizeof *k);
    if (!k) { t->oom = 1; free(refs); t->nodes[node].flags = KD_LEAF; t->nodes[node].prim_offset = UINT32_MAX; return; }
    t->tasks = k; t->cap_tasks = nc;
  }
  kd_task *k = &t->tasks[t->ntasks];
  memset(k, 0, sizeof *k);
  k->box = box; k->refs = refs; k->n = n; k->depth = depth;
  t->nodes[node].prim_offset = t->ntasks++;
  t->nodes[node].flags = KD_LEAF;
}

/* The cheapest split of n references by SAH over KD_BINS planes per axis, with the
 * sweep's costs (kdtree_internal.h). Returns the axis, or -1 when no plane lies inside
 * the box. */
static int bin_split(const kd_ref *r, uint32_t n, bbox box, float *pos, float *cost) {
  uint32_t start[3][KD_BINS], end[3][KD_BINS];
  memset(start, 0, sizeof start);
  memset(end, 0, sizeof end);
  float lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z}, scale[3];
  for (int k = 0; k < 3; k++) scale[k] = hi[k] > lo[k] ? KD_BINS / (hi[k] - lo[k]) : 0;
  float gmin[3] = {INFINITY, INFINITY, INFINITY}, gmax[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (uint32_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) {
      gmin[k] = r[i].lo[k] < gmin[k] ? r[i].lo[k] : gmin[k];
      gmax[k] = r[i].hi[k] > gmax[k] ? r[i].hi[k] : gmax[k];
      int b0 = (int)((r[i].lo[k] - lo[k]) * scale[k]), b1 = (int)((r[i].hi[k] - lo[k]) * scale[k]);
      b0 = b0 < 0 ? 0 : b0 > KD_BINS - 1 ? KD_BINS - 1 : b0;
      b1 = b1 < 0 ? 0 : b1 > KD_BINS - 1 ? KD_BINS - 1 : b1;
      start[k][b0]++;
      end[k][b1]++;
    }
  float total = bbox_area(box), inv_total = total > 0 ? 1.0f / total : 0;
  int best = -1;
  *cost = INFINITY;
  for (int k = 0; k < 3; k++) {
    if (!(hi[k] > lo[k])) continue;
    int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
    float d1 = hi[k1] - lo[k1], d2 = hi[k2] - lo[k2], a_perp = d1 * d2, a_side = d1 + d2;
    /* Empty space cut off exactly at the references' bounds, as the sweep would: a
     * cut at a bin's edge leaves a sliver that the next level cuts again, and the depth
     * limit then ends the tree with larger leaves. */
    for (int side = 0; side < 2; side++) {
      float p = side ? gmax[k] : gmin[k];
      if (!(p > lo[k] && p < hi[k])) continue;
      float pa = 2.0f * (a_perp + (side ? p - lo[k] : hi[k] - p) * a_side) * inv_total;
      float c = KD_TRAVERSE_COST + (1.0f - KD_EMPTY_BONUS) * pa * kd_leaf_cost(n);
      if (c < *cost) { *cost = c; *pos = p; best = k; }
    }
    uint32_t nl = 0, nr = n;
    for (int i = 1; i < KD_BINS; i++) {
      nl += start[k][i - 1];
      nr -= end[k][i - 1];
      float p = lo[k] + (hi[k] - lo[k]) * (float)i / KD_BINS;
      if (!(p > lo[k] && p < hi[k])) continue;
      float pl = 2.0f * (a_perp + (p - lo[k]) * a_side) * inv_total, pr = 2.0f * (a_perp + (hi[k] - p) * a_side) * inv_total;
      float eb = (nl == 0 || nr == 0) ? KD_EMPTY_BONUS : 0.0f;
      float c = KD_TRAVERSE_COST + (1.0f - eb) * (pl * kd_leaf_cost(nl) + pr * kd_leaf_cost(nr));
      if (c < *cost) { *cost = c; *pos = p; best = k; }
    }
  }
  return best;
}

static void top_build(kd_top *t, uint32_t node, bbox box, kd_ref *refs, uint32_t n, int depth) {
  if (n <= t->limit || depth <= 0 || t->oom) { top_task(t, node, box, refs, n, depth); return; }
  float pos = 0, cost;
  int k = bin_split(refs, n, box, &pos, &cost);
  if (k < 0 || cost >= kd_leaf_cost(n)) { top_task(t, node, box, refs, n, depth); return; }
  /* Left: below the plane or in it; right: above it; straddlers clipped to each side. */
  kd_ref *L = malloc((size_t)n * sizeof *L), *R = malloc((size_t)n * sizeof *R);
  if (!L || !R) { free(L); free(R); t->oom = 1; top_task(t, node, box, refs, n, depth); return; }
  bbox lbox = box, rbox = box;
  v3_set(&lbox.hi, k, pos);
  v3_set(&rbox.lo, k, pos);
  uint32_t nl = 0, nr = 0;
  for (uint32_t i = 0; i < n; i++) {
    const kd_ref *r = &refs[i];
    if (r->hi[k] <= pos) L[nl++] = *r;
    else if (r->lo[k] >= pos) R[nr++] = *r;
    else {
      const float *v = &t->kd->tv[9 * (size_t)r->tri];
      bbox cl, cr;
      int mask = kd_clip_split(v, box, k, pos, lbox, rbox, &cl, &cr);
      if (mask & 1) L[nl++] = (kd_ref){{cl.lo.x, cl.lo.y, cl.lo.z}, {cl.hi.x, cl.hi.y, cl.hi.z}, r->tri};
      if (mask & 2) R[nr++] = (kd_ref){{cr.lo.x, cr.lo.y, cr.lo.z}, {cr.hi.x, cr.hi.y, cr.hi.z}, r->tri};
    }
  }
  free(refs);
  t->nodes[node].split = pos;
  uint32_t fl = (uint32_t)k; /* written once the children are placed */
  if (nl == 0) { fl |= KD_BELOW_EMPTY; free(L); }
  else {
    uint32_t below = top_push(t);
    if (below == UINT32_MAX) { free(L); free(R); return; }
    top_build(t, below, lbox, L, nl, depth - 1);
  }
  if (nr == 0) { fl |= KD_ABOVE_EMPTY; free(R); }
  else {
    uint32_t above = top_push(t);
    if (above == UINT32_MAX) { free(R); return; }
    fl |= above << 4;
    top_build(t, above, rbox, R, nr, depth - 1);
  }
  t->nodes[node].flags = fl;
}

/* Appends the top subtree at si to kd in depth-first order, each task's part in place of
 * its leaf (the layout a single depth-first build would have made). */
static int join(kdtree *kd, const kd_top *t, uint32_t si) {
  kd_node n = t->nodes[si];
  if ((n.flags & 3) == KD_LEAF) {
    const kdtree *p = &t->tasks[n.prim_offset].part;
    uint32_t nb = kd->nnodes;
    uint64_t pb = kd->nprims;
    if (pb + p->nprims > 0xFFFFFFFFu || (uint64_t)nb + p->nnodes > KD_MAX_NODES) return -1;
    for (uint32_t i = 0; i < p->nnodes; i++) {
      kd_node m = p->nodes[i];
      if ((m.flags & 3) == KD_LEAF) m.prim_offset += (uint32_t)pb;
      else if (!(m.flags & KD_ABOVE_EMPTY)) m.flags = (m.flags & 15u) | ((m.flags >> 4) + nb) << 4;
      kd->nodes[nb + i] = m;
    }
    memcpy(kd->prims + pb, p->prims, p->nprims * sizeof *p->prims);
    memcpy(kd->ids + 4 * pb, p->ids, p->nprims * 4 * sizeof *p->ids);
    memcpy(kd->gfilt + pb, p->gfilt, p->nprims);
    kd->nnodes += p->nnodes;
    kd->nprims += p->nprims;
    return 0;
  }
  uint32_t d = kd->nnodes++;
  kd->nodes[d] = n;
  if (!(n.flags & KD_BELOW_EMPTY) && join(kd, t, si + 1)) return -1;
  if (!(n.flags & KD_ABOVE_EMPTY)) {
    uint32_t above = kd->nnodes;
    if (join(kd, t, n.flags >> 4)) return -1;
    kd->nodes[d].flags = (n.flags & 15u) | above << 4;
  }
  return 0;
}

static void top_free(kd_top *t) {
  for (uint32_t i = 0; i < t->ntasks; i++) {
    kd_task *k = &t->tasks[i];
    free(k->refs); free(k->part.nodes); free(k->part.prims); free(k->part.ids); free(k->part.gfilt);
  }
  free(t->tasks); free(t->nodes);
}

/* A part shares the tree's triangles and hit filter; its arrays start empty. */
static void part_init(kdtree *part, const kdtree *kd) {
  part->tv = kd->tv; part->filter = kd->filter; part->has_filter = kd->has_filter;
}

/* Allocates out's arrays for the top nodes of t and all its tasks' parts, then joins them
 * depth-first. Returns 0, or -1 when out of memory or past the layout's limits. */
static int join_all(kdtree *out, const kd_top *t) {
  uint64_t nn = t->nnodes, np = 0;
  for (uint32_t i = 0; i < t->ntasks; i++) { nn += t->tasks[i].part.nnodes; np += t->tasks[i].part.nprims; }
  if (nn > KD_MAX_NODES || np > 0xFFFFFFFFu) return -1;
  out->nodes = malloc((size_t)nn * sizeof *out->nodes);
  out->prims = malloc((size_t)(np + 1) * sizeof *out->prims);
  out->ids = malloc((size_t)(np + 1) * 4 * sizeof *out->ids);
  out->gfilt = malloc((size_t)np + 1);
  if (!out->nodes || !out->prims || !out->ids || !out->gfilt) return -1;
  out->cap_nodes = (uint32_t)nn; out->cap_prims = np;
  return join(out, t, 0);
}

/* Builds the subtree of a node into out (tv and filter set, arrays empty): binned
 * levels down to KD_BIN_MIN references, then the exact sweep of each, joined. */
static int build_subtree(kdtree *out, uint8_t *side, kd_arena *arena, kd_task *k) {
  kd_top sub = {out, NULL, 0, 0, NULL, 0, 0, KD_BIN_MIN, 0};
  uint32_t root = top_push(&sub);
  if (root == UINT32_MAX) return -1;
  top_build(&sub, root, k->box, k->refs, k->n, k->depth);
  k->refs = NULL;
  int fail = sub.oom;
  for (uint32_t i = 0; i < sub.ntasks && !fail; i++) {
    kd_task *f = &sub.tasks[i];
    part_init(&f->part, out);
    fail = kd_build_part(&f->part, side, arena, f->box, f->refs, f->n, f->depth);
    free(f->refs);
    f->refs = NULL;
  }
  if (!fail) fail = join_all(out, &sub);
  top_free(&sub);
  return fail ? -1 : 0;
}

/* The subtrees below the top levels, on the thread pool: each thread has its own scratch. */
typedef struct kd_run { kd_top *t; uint8_t *side[KD_BUILD_THREADS_MAX]; kd_arena arena[KD_BUILD_THREADS_MAX]; int oom[KD_BUILD_THREADS_MAX]; } kd_run;
static void run_task(void *user, int64_t i, int th) {
  kd_run *run = user;
  kd_task *k = &run->t->tasks[i];
  part_init(&k->part, run->t->kd);
  if (run->oom[th] || build_subtree(&k->part, run->side[th], &run->arena[th], k)) run->oom[th] = 1;
  free(k->refs);
  k->refs = NULL;
}


valo_status kdtree_create(const vec3 *pos, const uint32_t *idx, uint32_t ntris, int threads, const accel_filter *filter, accel **out,
                          valo_error *err) {
  *out = NULL;
  if (ntris >= (1u << 30)) return err_set(err, VALO_ERR_INVALID, "kd-tree: too many triangles (%u)", ntris);
  kdtree *kd = calloc(1, sizeof *kd);
  if (!kd) return err_set(err, VALO_ERR_NOMEM, "kd-tree: out of memory");
  kd->base.ops = &kdtree_ops;
  kd->ntris = ntris;
  if (filter && filter->pass && filter->tri_flags) { kd->filter = *filter; kd->has_filter = 1; }
  kd->bounds = bbox_empty();
  kd_top t = {kd, NULL, 0, 0, NULL, 0, 0, 0, 0};
  kd_run run;
  memset(&run, 0, sizeof run);
  kd->tv = malloc(((size_t)ntris * 9 + 1) * sizeof(float));
  kd_ref *refs = malloc(((size_t)ntris + 1) * sizeof *refs);
  if (!kd->tv || !refs) { free(refs); goto oom; }
  for (uint32_t i = 0; i < ntris; i++) {
    bbox tb = bbox_empty();
    for (int v = 0; v < 3; v++) {
      vec3 p = pos[idx[3 * (size_t)i + v]];
      memcpy(&kd->tv[9 * (size_t)i + 3 * v], &p, sizeof p);
      tb = bbox_add(tb, p);
    }
    kd->bounds = bbox_union(kd->bounds, tb);
    refs[i] = (kd_ref){{tb.lo.x, tb.lo.y, tb.lo.z}, {tb.hi.x, tb.hi.y, tb.hi.z}, i};
  }
  /* On meshes the depth limit, not the SAH, ends most leaves (the bunny's: 92 % of its
   * references), and each level of it multiplies the duplicated references. Triangle
   * data is where incoherent rays miss the cache, so 1.2 log2 N: deeper trees (1.5, or
   * empty-space cuts not counted) traced the meshes' rays 5-15 % slower, shallower ones
   * up to 36 % (docs/performance.md). */
  int max_depth = (int)lroundf(8 + KD_DEPTH_FACTOR * log2f((float)(ntris > 1 ? ntris : 1)));
  if (max_depth > 60) max_depth = 60;
  kd->max_depth_seen = (uint32_t)max_depth;
  if (ntris == 0) { free(refs); free(kd->tv); kd->tv = NULL; *out = &kd->base; return VALO_OK; }
  /* The top levels run on one thread down to nodes of N / 64 references; the tree does
   * not depend on where that stops. */
  t.limit = ntris / 64 > KD_BIN_MIN ? ntris / 64 : KD_BIN_MIN;
  uint32_t root = top_push(&t);
  if (root == UINT32_MAX) { free(refs); goto oom; }
  top_build(&t, root, kd->bounds, refs, ntris, max_depth);
  if (t.oom) goto oom;

  int nth = threads > 0 ? threads : threads_available();
  if (nth > KD_BUILD_THREADS_MAX) nth = KD_BUILD_THREADS_MAX;
  if ((uint32_t)nth > t.ntasks) nth = (int)t.ntasks;
  run.t = &t;
  for (int i = 0; i < nth; i++)
    if (!(run.side[i] = malloc((size_t)ntris + 1))) goto oom;
  parallel_for(nth, t.ntasks, run_task, &run);
  for (int i = 0; i < nth; i++) if (run.oom[i]) goto oom;

  if (join_all(kd, &t) || kd_box_nodes(kd)) goto oom;
  for (int i = 0; i < nth; i++) { free(run.side[i]); kd_arena_free(&run.arena[i]); }
  top_free(&t);
  free(kd->tv);
  kd->tv = NULL;
  *out = &kd->base;
  return VALO_OK;
oom:
  for (int i = 0; i < KD_BUILD_THREADS_MAX; i++) { free(run.side[i]); kd_arena_free(&run.arena[i]); }
  top_free(&t);
  kdtree_free(kd);
  return err_set(err, VALO_ERR_NOMEM, "kd-tree: out of memory while building");
}
