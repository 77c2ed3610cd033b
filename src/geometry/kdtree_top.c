/* kdtree_top.c — owns building the kd-tree as a whole (layout: kdtree_internal.h). The
 * top levels, where nodes hold many triangles, choose their splits by binned SAH over
 * clipped triangle references (one pass over a node's references per level, no sorted
 * event lists; a large node's passes run in chunks on the thread pool); nodes of at most
 * KD_BIN_MIN references become subtrees built by the exact sweep of kdtree_build.c, in
 * parallel on the thread pool (while one thread still builds the smaller top levels:
 * kd_run), then joined in depth-first order (the parts copied in parallel). The top
 * levels and every subtree depend on the mesh alone, so the tree and its memory layout
 * are the same for any thread count. */
#include "geometry/kdtree_internal.h"
#include "core/error.h"
#include "core/threadpool.h"
#include <pthread.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef KD_BIN_MIN
#define KD_BIN_MIN 1024u /* references: at or below, the exact sweep (docs/performance.md) */
#endif
#define KD_BINS 32
#define KD_BUILD_THREADS_MAX 16

/* A subtree left to the exact sweep: its references and, once built, its part. A
 * frontier task (front) is a subtree of the top levels instead, built later into sub. */
struct kd_top;
typedef struct kd_task {
  bbox box; kd_ref *refs; uint32_t n; int depth; kdtree part;
  uint32_t at_node; uint64_t at_prim; /* where the join places the part */
  int front;
  struct kd_top *sub;
} kd_task;

typedef struct kd_top {
  kdtree *kd;
  kd_node *nodes;           /* the top levels; every leaf is a task (prim_offset: its index) */
  uint32_t nnodes, cap_nodes;
  kd_task *tasks;
  uint32_t ntasks, cap_tasks;
  uint32_t limit;           /* nodes of at most this many references become tasks */
  int oom;
  int threads;              /* for the passes over a large node's references */
  uint32_t front_min;       /* nodes of fewer references (and more than limit) become frontier tasks */
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

/* Binning: counts of references starting and ending in each of KD_BINS slabs per axis,
 * and the references' exact bounds. Sums of counts and extremes of bounds, so chunks of
 * references binned apart and merged give the same result as one pass. */
typedef struct bin_acc { uint32_t start[3][KD_BINS], end[3][KD_BINS]; float gmin[3], gmax[3]; } bin_acc;

static void bin_add(bin_acc *a, const kd_ref *r, uint32_t n, bbox box) {
  memset(a->start, 0, sizeof a->start);
  memset(a->end, 0, sizeof a->end);
  float lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z}, scale[3];
  for (int k = 0; k < 3; k++) {
    scale[k] = hi[k] > lo[k] ? KD_BINS / (hi[k] - lo[k]) : 0;
    a->gmin[k] = INFINITY;
    a->gmax[k] = -INFINITY;
  }
  for (uint32_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) {
      a->gmin[k] = r[i].lo[k] < a->gmin[k] ? r[i].lo[k] : a->gmin[k];
      a->gmax[k] = r[i].hi[k] > a->gmax[k] ? r[i].hi[k] : a->gmax[k];
      int b0 = (int)((r[i].lo[k] - lo[k]) * scale[k]), b1 = (int)((r[i].hi[k] - lo[k]) * scale[k]);
      b0 = b0 < 0 ? 0 : b0 > KD_BINS - 1 ? KD_BINS - 1 : b0;
      b1 = b1 < 0 ? 0 : b1 > KD_BINS - 1 ? KD_BINS - 1 : b1;
      a->start[k][b0]++;
      a->end[k][b1]++;
    }
}

static void bin_merge(bin_acc *a, const bin_acc *b) {
  for (int k = 0; k < 3; k++) {
    for (int i = 0; i < KD_BINS; i++) { a->start[k][i] += b->start[k][i]; a->end[k][i] += b->end[k][i]; }
    a->gmin[k] = b->gmin[k] < a->gmin[k] ? b->gmin[k] : a->gmin[k];
    a->gmax[k] = b->gmax[k] > a->gmax[k] ? b->gmax[k] : a->gmax[k];
  }
}

/* The cheapest split of n binned references by SAH over KD_BINS planes per axis, with
 * the sweep's costs (kdtree_internal.h). Returns the axis, or -1 when no plane lies
 * inside the box. */
static int bin_split(const bin_acc *a, uint32_t n, bbox box, float *pos, float *cost) {
  float lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
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
      float p = side ? a->gmax[k] : a->gmin[k];
      if (!(p > lo[k] && p < hi[k])) continue;
      float pa = 2.0f * (a_perp + (side ? p - lo[k] : hi[k] - p) * a_side) * inv_total;
      float c = KD_TRAVERSE_COST + (1.0f - KD_EMPTY_BONUS) * pa * kd_leaf_cost(n);
      if (c < *cost) { *cost = c; *pos = p; best = k; }
    }
    uint32_t nl = 0, nr = n;
    for (int i = 1; i < KD_BINS; i++) {
      nl += a->start[k][i - 1];
      nr -= a->end[k][i - 1];
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

/* A top node's passes over its references. A large node's run on the thread pool in
 * chunks: binning, then the partition at the chosen plane, where a first pass counts
 * each chunk's references per side and clips its straddlers and a second writes them at
 * their chunk's offsets. Chunks keep their references' order, so the result does not
 * depend on how many there are or which thread runs them; a smaller node makes one
 * pass of each kind. */
#define KD_PAR_MIN 16384u  /* references: at or above, a node's passes use the thread pool */
#define KD_PAR_CHUNK 4096u
typedef struct kd_chunk {
  bin_acc bins;
  uint32_t nl, nr, ns, cap, ol, or_; /* counts, straddlers, their room, write offsets */
  kd_ref *cut;                      /* per straddler: its part below, then above (tri UINT32_MAX: empty) */
  int oom;
} kd_chunk;
typedef struct kd_pass {
  const kd_top *t;
  const kd_ref *refs;
  uint32_t n, chunk;
  bbox box, lbox, rbox;
  int k;
  float pos;
  kd_ref *L, *R;
  kd_chunk *c;
} kd_pass;

/* 1: below the plane or in it; 2: above it; 0: straddling. */
static int ref_side(const kd_pass *p, const kd_ref *r) { return r->hi[p->k] <= p->pos ? 1 : r->lo[p->k] >= p->pos ? 2 : 0; }

/* A straddler's parts below and above the plane (tri UINT32_MAX where a part is empty). */
static void ref_cut(const kd_pass *p, const kd_ref *r, kd_ref o[2]) {
  bbox cl = p->lbox, cr = p->rbox; /* kept as they are for an empty part */
  int mask = kd_clip_split(&p->t->kd->tv[9 * (size_t)r->tri], p->box, p->k, p->pos, p->lbox, p->rbox, &cl, &cr);
  o[0] = (kd_ref){{cl.lo.x, cl.lo.y, cl.lo.z}, {cl.hi.x, cl.hi.y, cl.hi.z}, mask & 1 ? r->tri : UINT32_MAX};
  o[1] = (kd_ref){{cr.lo.x, cr.lo.y, cr.lo.z}, {cr.hi.x, cr.hi.y, cr.hi.z}, mask & 2 ? r->tri : UINT32_MAX};
}

static void pass_bin(void *user, int64_t i, int th) {
  (void)th;
  kd_pass *p = user;
  uint32_t lo = (uint32_t)i * p->chunk, hi = lo + p->chunk < p->n ? lo + p->chunk : p->n;
  bin_add(&p->c[i].bins, p->refs + lo, hi - lo, p->box);
}

static void pass_count(void *user, int64_t i, int th) {
  (void)th;
  kd_pass *p = user;
  kd_chunk *c = &p->c[i];
  uint32_t lo = (uint32_t)i * p->chunk, hi = lo + p->chunk < p->n ? lo + p->chunk : p->n;
  for (uint32_t j = lo; j < hi; j++) {
    int sd = ref_side(p, &p->refs[j]);
    c->nl += sd == 1;
    c->nr += sd == 2;
    if (sd) continue;
    if (c->ns == c->cap) {
      uint32_t nc = c->cap ? 2 * c->cap : 64;
      kd_ref *g = realloc(c->cut, (size_t)nc * 2 * sizeof *g);
      if (!g) { c->oom = 1; return; }
      c->cut = g; c->cap = nc;
    }
    kd_ref *o = &c->cut[2 * c->ns++];
    ref_cut(p, &p->refs[j], o);
    c->nl += o[0].tri != UINT32_MAX;
    c->nr += o[1].tri != UINT32_MAX;
  }
}

static void pass_write(void *user, int64_t i, int th) {
  (void)th;
  kd_pass *p = user;
  kd_chunk *c = &p->c[i];
  uint32_t lo = (uint32_t)i * p->chunk, hi = lo + p->chunk < p->n ? lo + p->chunk : p->n, s = 0, nl = c->ol, nr = c->or_;
  for (uint32_t j = lo; j < hi; j++) {
    const kd_ref *r = &p->refs[j];
    int sd = ref_side(p, r);
    if (sd == 1) p->L[nl++] = *r;
    else if (sd == 2) p->R[nr++] = *r;
    else {
      const kd_ref *o = &c->cut[2 * s++];
      if (o[0].tri != UINT32_MAX) p->L[nl++] = o[0];
      if (o[1].tri != UINT32_MAX) p->R[nr++] = o[1];
    }
  }
}

/* Partitions p's references into p->L and p->R (allocated here); returns 0, or -1 when
 * out of memory. */
static int partition(kd_pass *p, int threads, uint32_t nchunks, uint32_t *nl, uint32_t *nr) {
  *nl = *nr = 0;
  if (threads <= 1) { /* one pass: each side has room for every reference */
    p->L = malloc(((size_t)p->n + 1) * sizeof *p->L);
    p->R = malloc(((size_t)p->n + 1) * sizeof *p->R);
    if (!p->L || !p->R) return -1;
    for (uint32_t j = 0; j < p->n; j++) {
      const kd_ref *r = &p->refs[j];
      int sd = ref_side(p, r);
      kd_ref o[2];
      if (sd == 1) p->L[(*nl)++] = *r;
      else if (sd == 2) p->R[(*nr)++] = *r;
      else {
        ref_cut(p, r, o);
        if (o[0].tri != UINT32_MAX) p->L[(*nl)++] = o[0];
        if (o[1].tri != UINT32_MAX) p->R[(*nr)++] = o[1];
      }
    }
    return 0;
  }
  parallel_for(threads, nchunks, pass_count, p);
  int oom = 0;
  for (uint32_t i = 0; i < nchunks; i++) {
    p->c[i].ol = *nl; p->c[i].or_ = *nr;
    *nl += p->c[i].nl; *nr += p->c[i].nr;
    oom |= p->c[i].oom;
  }
  p->L = oom ? NULL : malloc(((size_t)*nl + 1) * sizeof *p->L);
  p->R = oom ? NULL : malloc(((size_t)*nr + 1) * sizeof *p->R);
  if (!p->L || !p->R) return -1;
  parallel_for(threads, nchunks, pass_write, p);
  return 0;
}

static void top_build(kd_top *t, uint32_t node, bbox box, kd_ref *refs, uint32_t n, int depth) {
  if (n <= t->limit || depth <= 0 || t->oom) { top_task(t, node, box, refs, n, depth); return; }
  if (n < t->front_min) {
    top_task(t, node, box, refs, n, depth);
    if (!t->oom) t->tasks[t->ntasks - 1].front = 1;
    return;
  }
  int threads = n >= KD_PAR_MIN ? t->threads : 1;
  uint32_t chunk = threads > 1 ? KD_PAR_CHUNK : n, nchunks = (n + chunk - 1) / chunk;
  kd_chunk *ch = calloc(nchunks, sizeof *ch);
  if (!ch) { t->oom = 1; top_task(t, node, box, refs, n, depth); return; }
  kd_pass p = {t, refs, n, chunk, box, box, box, 0, 0, NULL, NULL, ch};
  parallel_for(threads, nchunks, pass_bin, &p);
  for (uint32_t i = 1; i < nchunks; i++) bin_merge(&ch[0].bins, &ch[i].bins);
  float pos = 0, cost;
  int k = bin_split(&ch[0].bins, n, box, &pos, &cost);
  if (k < 0 || cost >= kd_leaf_cost(n)) { free(ch); top_task(t, node, box, refs, n, depth); return; }
  /* Left: below the plane or in it; right: above it; straddlers clipped to each side. */
  v3_set(&p.lbox.hi, k, pos);
  v3_set(&p.rbox.lo, k, pos);
  p.k = k;
  p.pos = pos;
  uint32_t nl, nr;
  int fail = partition(&p, threads, nchunks, &nl, &nr);
  for (uint32_t i = 0; i < nchunks; i++) free(ch[i].cut);
  free(ch);
  if (fail) { free(p.L); free(p.R); t->oom = 1; top_task(t, node, box, refs, n, depth); return; }
  free(refs);
  kd_ref *L = p.L, *R = p.R;
  t->nodes[node].split = pos;
  uint32_t fl = (uint32_t)k; /* written once the children are placed */
  if (nl == 0) { fl |= KD_BELOW_EMPTY; free(L); }
  else {
    uint32_t below = top_push(t);
    if (below == UINT32_MAX) { free(L); free(R); return; }
    top_build(t, below, p.lbox, L, nl, depth - 1);
  }
  if (nr == 0) { fl |= KD_ABOVE_EMPTY; free(R); }
  else {
    uint32_t above = top_push(t);
    if (above == UINT32_MAX) { free(R); return; }
    fl |= above << 4;
    top_build(t, above, p.rbox, R, nr, depth - 1);
  }
  t->nodes[node].flags = fl;
}

/* Lays out the top subtree at si in kd in depth-first order, each task's part in place
 * of its leaf (the layout a single depth-first build would have made): writes the top
 * nodes and records where each part goes (copied by place_part). */
typedef struct kd_placing { kdtree *kd; kd_task **list; uint32_t n; } kd_placing;
static int join(kd_placing *w, kd_top *t, uint32_t si) {
  kdtree *kd = w->kd;
  kd_node n = t->nodes[si];
  if ((n.flags & 3) == KD_LEAF) {
    kd_task *k = &t->tasks[n.prim_offset];
    if (k->sub) return join(w, k->sub, 0);
    w->list[w->n++] = k;
    if (kd->nprims + k->part.nprims > 0xFFFFFFFFu || (uint64_t)kd->nnodes + k->part.nnodes > KD_MAX_NODES) return -1;
    k->at_node = kd->nnodes;
    k->at_prim = kd->nprims;
    kd->nnodes += k->part.nnodes;
    kd->nprims += k->part.nprims;
    return 0;
  }
  uint32_t d = kd->nnodes++;
  kd->nodes[d] = n;
  if (!(n.flags & KD_BELOW_EMPTY) && join(w, t, si + 1)) return -1;
  if (!(n.flags & KD_ABOVE_EMPTY)) {
    uint32_t above = kd->nnodes;
    if (join(w, t, n.flags >> 4)) return -1;
    kd->nodes[d].flags = (n.flags & 15u) | above << 4;
  }
  return 0;
}

/* Copies the part of the join's task i to where join placed it, its node links and leaf
 * offsets moved. */
static void place_part(void *user, int64_t i, int th) {
  (void)th;
  kd_placing *w = user;
  const kd_task *k = w->list[i];
  const kdtree *p = &k->part;
  kdtree *kd = w->kd;
  uint32_t nb = k->at_node;
  uint64_t pb = k->at_prim;
  for (uint32_t j = 0; j < p->nnodes; j++) {
    kd_node m = p->nodes[j];
    if ((m.flags & 3) == KD_LEAF) m.prim_offset += (uint32_t)pb;
    else if (!(m.flags & KD_ABOVE_EMPTY)) m.flags = (m.flags & 15u) | ((m.flags >> 4) + nb) << 4;
    kd->nodes[nb + j] = m;
  }
  memcpy(kd->prims + pb, p->prims, p->nprims * sizeof *p->prims);
  memcpy(kd->ids + 4 * pb, p->ids, p->nprims * 4 * sizeof *p->ids);
  memcpy(kd->gfilt + pb, p->gfilt, p->nprims);
}

static void top_free(kd_top *t) {
  for (uint32_t i = 0; i < t->ntasks; i++) {
    kd_task *k = &t->tasks[i];
    free(k->refs); free(k->part.nodes); free(k->part.prims); free(k->part.ids); free(k->part.gfilt);
    if (k->sub) { top_free(k->sub); free(k->sub); }
  }
  free(t->tasks); free(t->nodes);
}

/* The nodes, triangle groups and parts of t with its frontier subtrees. */
static void top_size(const kd_top *t, uint64_t *nn, uint64_t *np, uint32_t *nparts) {
  *nn += t->nnodes;
  for (uint32_t i = 0; i < t->ntasks; i++) {
    const kd_task *k = &t->tasks[i];
    if (k->sub) top_size(k->sub, nn, np, nparts);
    else { *nn += k->part.nnodes; *np += k->part.nprims; (*nparts)++; }
  }
}

/* A part shares the tree's triangles and hit filter; its arrays start empty. */
static void part_init(kdtree *part, const kdtree *kd) {
  part->tv = kd->tv; part->filter = kd->filter; part->has_filter = kd->has_filter;
}

/* Allocates out's arrays for the top nodes of t and all its tasks' parts, then joins them
 * depth-first. Returns 0, or -1 when out of memory or past the layout's limits. */
static int join_all(kdtree *out, kd_top *t) {
  uint64_t nn = 0, np = 0;
  uint32_t nparts = 0;
  top_size(t, &nn, &np, &nparts);
  if (nn > KD_MAX_NODES || np > 0xFFFFFFFFu) return -1;
  out->nodes = malloc((size_t)nn * sizeof *out->nodes);
  out->prims = malloc((size_t)(np + 1) * sizeof *out->prims);
  out->ids = malloc((size_t)(np + 1) * 4 * sizeof *out->ids);
  out->gfilt = malloc((size_t)np + 1);
  if (!out->nodes || !out->prims || !out->ids || !out->gfilt) return -1;
  out->cap_nodes = (uint32_t)nn; out->cap_prims = np;
  kd_placing w = {out, malloc(((size_t)nparts + 1) * sizeof *w.list), 0};
  int fail = !w.list || join(&w, t, 0);
  if (!fail) parallel_for(t->threads, w.n, place_part, &w);
  free(w.list);
  return fail ? -1 : 0;
}

/* Builds the subtree of a node into out (tv and filter set, arrays empty): binned
 * levels down to KD_BIN_MIN references, then the exact sweep of each, joined. */
static int build_subtree(kdtree *out, uint8_t *side, kd_arena *arena, kd_task *k) {
  kd_top sub = {out, NULL, 0, 0, NULL, 0, 0, KD_BIN_MIN, 0, 1, 0};
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

/* The rest of the build, on the thread pool: one thread builds the frontier subtrees'
 * top levels, in order, and queues each one's tasks as soon as they exist, while every
 * thread (that one too, once done) takes tasks from the queue and builds their subtrees
 * with its own scratch. Which thread builds what does not change any result. */
typedef struct kd_run {
  kd_top *t;
  uint8_t *side[KD_BUILD_THREADS_MAX];
  kd_arena arena[KD_BUILD_THREADS_MAX];
  int oom[KD_BUILD_THREADS_MAX];
  pthread_mutex_t m;
  pthread_cond_t cv;
  kd_task **q;              /* the queue: tasks ready to build */
  uint32_t qn, qcap, qnext;
  int done;                 /* no more tasks will be queued */
} kd_run;

/* Queues t's tasks (not its frontier ones); 0, or -1 when out of memory. */
static int run_queue(kd_run *r, kd_top *t) {
  int fail = 0;
  pthread_mutex_lock(&r->m);
  for (uint32_t i = 0; i < t->ntasks && !fail; i++) {
    if (t->tasks[i].front) continue;
    if (r->qn == r->qcap) {
      uint32_t nc = r->qcap ? 2 * r->qcap : 256;
      kd_task **g = realloc(r->q, (size_t)nc * sizeof *g);
      if (!g) { fail = 1; break; }
      r->q = g; r->qcap = nc;
    }
    r->q[r->qn++] = &t->tasks[i];
  }
  pthread_cond_broadcast(&r->cv);
  pthread_mutex_unlock(&r->m);
  return fail ? -1 : 0;
}

static void run_item(void *user, int64_t i, int th) {
  kd_run *r = user;
  if (i == 0) {
    kd_top *t = r->t;
    if (run_queue(r, t)) r->oom[th] = 1;
    for (uint32_t j = 0; j < t->ntasks && !r->oom[th]; j++) {
      kd_task *f = &t->tasks[j];
      if (!f->front) continue;
      kd_top *sub = calloc(1, sizeof *sub);
      if (!sub) { r->oom[th] = 1; break; }
      *sub = (kd_top){t->kd, NULL, 0, 0, NULL, 0, 0, t->limit, 0, 1, 0};
      f->sub = sub;
      uint32_t root = top_push(sub);
      if (root == UINT32_MAX) { r->oom[th] = 1; break; }
      top_build(sub, root, f->box, f->refs, f->n, f->depth);
      f->refs = NULL;
      if (sub->oom || run_queue(r, sub)) r->oom[th] = 1;
    }
    pthread_mutex_lock(&r->m);
    r->done = 1;
    pthread_cond_broadcast(&r->cv);
    pthread_mutex_unlock(&r->m);
  }
  for (;;) {
    pthread_mutex_lock(&r->m);
    while (r->qnext == r->qn && !r->done) pthread_cond_wait(&r->cv, &r->m);
    kd_task *k = r->qnext < r->qn ? r->q[r->qnext++] : NULL;
    pthread_mutex_unlock(&r->m);
    if (!k) break;
    part_init(&k->part, r->t->kd);
    if (r->oom[th] || build_subtree(&k->part, r->side[th], &r->arena[th], k)) r->oom[th] = 1;
    free(k->refs);
    k->refs = NULL;
  }
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
  kd_top t = {kd, NULL, 0, 0, NULL, 0, 0, 0, 0, 1, 0};
  kd_run run;
  memset(&run, 0, sizeof run);
  pthread_mutex_init(&run.m, NULL);
  pthread_cond_init(&run.cv, NULL);
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
  if (ntris == 0) {
    free(refs); free(kd->tv); kd->tv = NULL;
    pthread_mutex_destroy(&run.m); pthread_cond_destroy(&run.cv);
    *out = &kd->base;
    return VALO_OK;
  }
  /* The top levels down to nodes of N / 64 references: first those of KD_PAR_MIN
   * references or more, their passes on the thread pool; then the frontier below them
   * while the tasks are built (kd_run). The tree depends neither on where either
   * stops nor on the threads. */
  int nth = threads > 0 ? threads : threads_available();
  if (nth > KD_BUILD_THREADS_MAX) nth = KD_BUILD_THREADS_MAX;
  t.threads = nth;
  t.limit = ntris / 64 > KD_BIN_MIN ? ntris / 64 : KD_BIN_MIN;
  t.front_min = KD_PAR_MIN;
  uint32_t root = top_push(&t);
  if (root == UINT32_MAX) { free(refs); goto oom; }
  top_build(&t, root, kd->bounds, refs, ntris, max_depth);
  if (t.oom) goto oom;

  run.t = &t;
  for (int i = 0; i < nth; i++)
    if (!(run.side[i] = malloc((size_t)ntris + 1))) goto oom;
  parallel_for(nth, nth, run_item, &run);
  for (int i = 0; i < nth; i++) if (run.oom[i]) goto oom;

  if (join_all(kd, &t) || kd_box_nodes(kd)) goto oom;
  for (int i = 0; i < nth; i++) { free(run.side[i]); kd_arena_free(&run.arena[i]); }
  free(run.q);
  pthread_mutex_destroy(&run.m);
  pthread_cond_destroy(&run.cv);
  top_free(&t);
  free(kd->tv);
  kd->tv = NULL;
  *out = &kd->base;
  return VALO_OK;
oom:
  for (int i = 0; i < KD_BUILD_THREADS_MAX; i++) { free(run.side[i]); kd_arena_free(&run.arena[i]); }
  free(run.q);
  pthread_mutex_destroy(&run.m);
  pthread_cond_destroy(&run.cv);
  top_free(&t);
  kdtree_free(kd);
  return err_set(err, VALO_ERR_NOMEM, "kd-tree: out of memory while building");
}
