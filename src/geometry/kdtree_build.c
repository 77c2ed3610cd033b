/* kdtree_build.c — owns the exact SAH sweep that builds the kd-tree's subtrees below the
 * binned top levels (kdtree_top.c; layout: kdtree_internal.h): Wald & Havran, "On
 * building fast kd-trees for ray tracing, and on doing that in O(N log N)" (2006) —
 * per-axis event lists sorted once per subtree, a linear sweep per node, order-preserving
 * list splitting (an empty-space cut's child takes its parent's lists as they are) and
 * exact clipping of straddling triangles to the child voxels (kd_clip_split,
 * kdtree_clip.c) — and the leaves: triangles in leaf order in SSE groups of four, tested
 * four at a time (1.3-1.5x faster than one by one; docs/performance.md). Also the box
 * nodes made once the tree is joined. SAH costs: digest 000's formula with leaves
 * priced by groups of four (kdtree_internal.h), empty bonus 0.5. */
#include "geometry/kdtree_internal.h"
#include "core/error.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- build */

enum { EV_END = 0, EV_PLANAR = 1, EV_START = 2 };
typedef struct kd_event { float pos; uint32_t v; } kd_event; /* v = tri << 2 | type */
typedef struct evlist { kd_event *e[3]; uint32_t n[3]; uint32_t ntris; } evlist;
enum { SIDE_BOTH = 0, SIDE_LEFT = 1, SIDE_RIGHT = 2 };

typedef struct kd_builder {
  kdtree *kd;
  uint8_t *side;
  kd_arena *arena;
  int oom;
} kd_builder;

/* ---------------------------------------------------------------- arena */

/* Event lists live on a per-thread stack of blocks: a node's lists are taken above its
 * parent's and given back when its subtree is done, so the build calls malloc only when
 * a block is first needed (blocks are kept for the thread's next subtree). */
static void *arena_alloc(kd_arena *a, size_t bytes) {
  bytes = (bytes + 15) & ~(size_t)15;
  while (a->cur < a->nblk && a->off + bytes > a->cap[a->cur]) { a->cur++; a->off = 0; }
  if (a->cur == a->nblk) {
    if (a->nblk == KD_ARENA_BLOCKS) return NULL;
    size_t c = a->nblk ? 2 * a->cap[a->nblk - 1] : (size_t)1 << 18;
    while (c < bytes) c *= 2;
    if (!(a->blk[a->nblk] = malloc(c))) return NULL;
    a->cap[a->nblk++] = c;
    a->off = 0;
  }
  void *p = a->blk[a->cur] + a->off;
  a->off += bytes;
  return p;
}

/* Where the stack stands, and going back there: everything taken since is given back. */
typedef struct arena_mark { int cur; size_t off; } arena_mark;
static arena_mark arena_top(const kd_arena *a) { return (arena_mark){a->cur, a->off}; }
static void arena_release(kd_arena *a, arena_mark m) { a->cur = m.cur; a->off = m.off; }

void kd_arena_free(kd_arena *a) {
  for (int i = 0; i < a->nblk; i++) free(a->blk[i]);
  memset(a, 0, sizeof *a);
}

static inline int ev_less(const kd_event *a, const kd_event *b) {
  return a->pos < b->pos || (a->pos == b->pos && (a->v & 3) < (b->v & 3));
}

/* The sort key of a position: its bits made to order as unsigned integers (-0 as +0,
 * since the sweep groups events by ==). */
static inline uint32_t ev_key(float pos) {
  float p = pos + 0.0f;
  uint32_t u;
  memcpy(&u, &p, sizeof u);
  return u ^ ((uint32_t)((int32_t)u >> 31) | 0x80000000u);
}

/* Long lists: a stable LSD radix sort, by type and then by the key's four bytes (a pass
 * whose byte is the same for every event is skipped). */
static void ev_radix(kd_event *e, uint32_t n, kd_event *tmp) {
  uint32_t hist[5][256];
  memset(hist, 0, sizeof hist);
  for (uint32_t i = 0; i < n; i++) {
    uint32_t k = ev_key(e[i].pos);
    hist[0][e[i].v & 3]++;
    for (int b = 0; b < 4; b++) hist[1 + b][(k >> (8 * b)) & 255]++;
  }
  kd_event *src = e, *dst = tmp;
  for (int pass = 0; pass < 5; pass++) {
    uint32_t *h = hist[pass], sum = 0;
    int skip = 0;
    for (int d = 0; d < 256; d++) {
      if (h[d] == n) skip = 1;
      uint32_t c = h[d];
      h[d] = sum;
      sum += c;
    }
    if (skip) continue;
    for (uint32_t i = 0; i < n; i++) {
      uint32_t d = pass == 0 ? src[i].v & 3 : (ev_key(src[i].pos) >> (8 * (pass - 1))) & 255;
      dst[h[d]++] = src[i];
    }
    kd_event *x = src; src = dst; dst = x;
  }
  if (src != e) memcpy(e, src, (size_t)n * sizeof *e);
}

/* Merges sorted a and b into o (na + nb entries), stably: on equal events a's first. */
static void ev_merge(kd_event *o, const kd_event *a, uint32_t na, const kd_event *b, uint32_t nb) {
  uint32_t i = 0, j = 0, m = 0;
  while (i < na && j < nb) o[m++] = ev_less(&b[j], &a[i]) ? b[j++] : a[i++];
  while (i < na) o[m++] = a[i++];
  while (j < nb) o[m++] = b[j++];
}

/* Sorts events by ev_less, stably (equal events keep their order): radix for long
 * lists; else insertion sort for short runs, then bottom-up merging through tmp (n
 * entries). */
static void ev_sort(kd_event *e, uint32_t n, kd_event *tmp) {
  const uint32_t run = 16;
  if (n >= 256) { ev_radix(e, n, tmp); return; }
  for (uint32_t lo = 0; lo < n; lo += run) {
    uint32_t hi = lo + run < n ? lo + run : n;
    for (uint32_t i = lo + 1; i < hi; i++) {
      kd_event x = e[i];
      uint32_t j = i;
      while (j > lo && ev_less(&x, &e[j - 1])) { e[j] = e[j - 1]; j--; }
      e[j] = x;
    }
  }
  kd_event *src = e, *dst = tmp;
  for (uint32_t w = run; w < n; w *= 2) {
    for (uint32_t lo = 0; lo < n; lo += 2 * w) {
      uint32_t mid = lo + w < n ? lo + w : n, hi = lo + 2 * w < n ? lo + 2 * w : n;
      ev_merge(dst + lo, src + lo, mid - lo, src + mid, hi - mid);
    }
    kd_event *x = src; src = dst; dst = x;
  }
  if (src != e) memcpy(e, src, (size_t)n * sizeof *e);
}


uint32_t kd_node_push(kd_node **nodes, uint32_t *n, uint32_t *cap) {
  if (*n >= KD_MAX_NODES) return UINT32_MAX;
  if (*n == *cap) {
    uint32_t nc = *cap ? *cap * 2 : 256;
    kd_node *g = realloc(*nodes, (size_t)nc * sizeof *g);
    if (!g) return UINT32_MAX;
    *nodes = g; *cap = nc;
  }
  return (*n)++;
}

static uint32_t push_node(kd_builder *b) {
  uint32_t i = kd_node_push(&b->kd->nodes, &b->kd->nnodes, &b->kd->cap_nodes);
  if (i == UINT32_MAX) b->oom = 1;
  return i;
}

static void make_leaf(kd_builder *b, uint32_t node, const evlist *l) {
  kdtree *kd = b->kd;
  uint64_t groups = (l->ntris + 3) / 4;
  if (kd->nprims + groups > kd->cap_prims) {
    uint64_t nc = kd->cap_prims ? kd->cap_prims : 1024;
    while (nc < kd->nprims + groups) nc *= 2;
    kd_tri4 *p = realloc(kd->prims, nc * sizeof *p);
    if (p) kd->prims = p;
    uint32_t *ids = realloc(kd->ids, nc * 4 * sizeof *ids);
    if (ids) kd->ids = ids;
    uint8_t *gf = realloc(kd->gfilt, nc);
    if (gf) kd->gfilt = gf;
    if (!p || !ids || !gf) { b->oom = 1; return; }
    kd->cap_prims = nc;
  }
  if (kd->nprims > 0xFFFFFFFFu) { b->oom = 1; return; }
  kd->nodes[node].prim_offset = (uint32_t)kd->nprims;
  uint32_t count = 0;
  for (uint32_t i = 0; i < l->n[0] && count < groups * 4; i++) {
    uint32_t type = l->e[0][i].v & 3;
    if (type != EV_START && type != EV_PLANAR) continue;
    uint32_t t = l->e[0][i].v >> 2;
    uint64_t gi = kd->nprims + count / 4;
    kd_tri4 *g = &kd->prims[gi];
    int lane = count % 4;
    int last = lane == 0 ? 3 : lane; /* the first triangle of a group also fills the unused lanes */
    for (int k = lane; k <= last; k++)
      for (int vtx = 0; vtx < 3; vtx++)
        for (int ax = 0; ax < 3; ax++) g->v[vtx][ax][k] = kd->tv[9 * (size_t)t + 3 * vtx + ax];
    if (lane == 0) { for (int k = 0; k < 4; k++) kd->ids[4 * gi + k] = UINT32_MAX; kd->gfilt[gi] = 0; }
    kd->ids[4 * gi + lane] = t;
    if (kd->has_filter && (kd->filter.tri_flags[t] & kd->filter.flag_bit)) kd->gfilt[gi] |= (uint8_t)(1u << lane);
    count++;
  }
  kd->nprims += (count + 3) / 4;
  kd->nodes[node].flags = KD_LEAF | (count << 2);
}

static void add_events(kd_event *dst, uint32_t *n, uint32_t tri, bbox b, int k) {
  float lo = v3_get(b.lo, k), hi = v3_get(b.hi, k);
  if (lo == hi) { dst[(*n)++] = (kd_event){lo, tri << 2 | EV_PLANAR}; }
  else {
    dst[(*n)++] = (kd_event){lo, tri << 2 | EV_START};
    dst[(*n)++] = (kd_event){hi, tri << 2 | EV_END};
  }
}

/* Merges sorted b (nb entries) into sorted a, whose first na entries are used and which
 * has room for na + nb, from the back, in the order ev_merge gives (on equal events a's
 * first). */
static void ev_merge_into(kd_event *a, uint32_t na, const kd_event *b, uint32_t nb) {
  uint32_t i = na, j = nb, m = na + nb;
  while (j > 0) {
    if (i > 0 && ev_less(&b[j - 1], &a[i - 1])) a[--m] = a[--i];
    else a[--m] = b[--j];
  }
}

static void build(kd_builder *b, uint32_t node, bbox box, evlist *l, int depth) {
  kdtree *kd = b->kd;
  uint32_t N = l->ntris;
  if ((uint32_t)(kd->max_depth_seen) < (uint32_t)depth) kd->max_depth_seen = (uint32_t)depth;
  if (N <= 1 || depth <= 0 || b->oom) { make_leaf(b, node, l); return; }

  /* Sweep every axis for the cheapest SAH split (Wald & Havran, Alg. 4). */
  float total = bbox_area(box), inv_total = total > 0 ? 1.0f / total : 0;
  vec3 d = v3_sub(box.hi, box.lo);
  float best_cost = INFINITY, best_pos = 0;
  int best_axis = -1, best_planar_left = 0;
  uint32_t best_cl = 0, best_cr = 0;
  for (int k = 0; k < 3; k++) {
    const kd_event *e = l->e[k];
    uint32_t n = l->n[k], i = 0, nl = 0, np = 0, nr = N;
    int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
    float a_perp = v3_get(d, k1) * v3_get(d, k2), a_side = v3_get(d, k1) + v3_get(d, k2);
    float lo = v3_get(box.lo, k), hi = v3_get(box.hi, k);
    while (i < n) {
      float p = e[i].pos;
      /* The events at p, counted by type without a branch per type (most positions
       * hold one event). */
      uint32_t cnt[3] = {0, 0, 0};
      do { cnt[e[i].v & 3]++; i++; } while (i < n && e[i].pos == p);
      uint32_t pe = cnt[EV_END], pp = cnt[EV_PLANAR], ps = cnt[EV_START];
      np = pp;
      nr -= pp + pe;
      if (p > lo && p < hi) {
        float pl = 2.0f * (a_perp + (p - lo) * a_side) * inv_total;
        float pr = 2.0f * (a_perp + (hi - p) * a_side) * inv_total;
        for (int planar_left = 0; planar_left < 1 + (np > 0); planar_left++) {
          uint32_t cl = nl + (planar_left ? np : 0), cr = nr + (planar_left ? 0 : np);
          float eb = (cl == 0 || cr == 0) ? KD_EMPTY_BONUS : 0.0f;
          float cost = KD_TRAVERSE_COST + (1.0f - eb) * (pl * kd_leaf_cost(cl) + pr * kd_leaf_cost(cr));
          if (cost < best_cost) { best_cost = cost; best_pos = p; best_axis = k; best_planar_left = planar_left; best_cl = cl; best_cr = cr; }
        }
      }
      nl += ps + pp;
      np = 0;
    }
  }
  if (best_axis < 0 || best_cost >= kd_leaf_cost(N)) { make_leaf(b, node, l); return; }
  if (best_cl == 0 || best_cr == 0) {
    /* An empty-space cut: every triangle lies on one side, so that child's event lists
     * are this node's, in the same order (no classifying, splitting or clipping). */
    int below_empty = best_cl == 0;
    bbox cbox = box;
    if (below_empty) v3_set(&cbox.lo, best_axis, best_pos);
    else v3_set(&cbox.hi, best_axis, best_pos);
    kd->nodes[node].split = best_pos;
    uint32_t child = push_node(b);
    uint32_t fl = (uint32_t)best_axis | (below_empty ? KD_BELOW_EMPTY | (child << 4) : KD_ABOVE_EMPTY);
    if (child != UINT32_MAX) build(b, child, cbox, l, depth - 1);
    kd->nodes[node].flags = fl;
    return;
  }

  /* Classify triangles (Alg. 5). Everything below is taken from the arena and given
   * back when this subtree is done. */
  kd_arena *ar = b->arena;
  arena_mark mark = arena_top(ar);
  int k = best_axis;
  const kd_event *e = l->e[k];
  /* Without a branch per event (the sides are data): a triangle is left when it ends at
   * or below the plane, right when it starts at or above it, and a planar one by its
   * position; no triangle can be both, so the bits are or-ed. */
  uint8_t *side = b->side;
  for (uint32_t i = 0; i < l->n[k]; i++) side[e[i].v >> 2] = SIDE_BOTH;
  for (uint32_t i = 0; i < l->n[k]; i++) {
    uint32_t t = e[i].v >> 2, type = e[i].v & 3;
    float p = e[i].pos;
    int planar_left = p < best_pos || (p == best_pos && best_planar_left);
    uint32_t left = (type == EV_END && p <= best_pos) | (type == EV_PLANAR && planar_left);
    uint32_t right = (type == EV_START && p >= best_pos) | (type == EV_PLANAR && !planar_left);
    side[t] |= (uint8_t)(left * SIDE_LEFT | right * SIDE_RIGHT);
  }
  uint32_t *straddle = arena_alloc(ar, ((size_t)N + 1) * sizeof *straddle); /* the loop writes one past the last straddler */
  if (!straddle) { b->oom = 1; make_leaf(b, node, l); arena_release(ar, mark); return; }
  uint32_t nboth = 0, nleft_only = 0, nright_only = 0;
  for (uint32_t i = 0; i < l->n[k]; i++) { /* each triangle once: at START or PLANAR */
    uint32_t t = e[i].v >> 2, first = (e[i].v & 3) != EV_END, sd = side[t];
    straddle[nboth] = t;
    nboth += first & (sd == SIDE_BOTH);
    nleft_only += first & (sd == SIDE_LEFT);
    nright_only += first & (sd == SIDE_RIGHT);
  }
  bbox lbox = box, rbox = box;
  v3_set(&lbox.hi, k, best_pos);
  v3_set(&rbox.lo, k, best_pos);

  /* Split the lists, preserving order, then add clipped straddlers (Alg. 6): each
   * child's list has room for its straddlers' events, which are sorted and merged in
   * from the back. */
  evlist L = {{0}, {0}, 0}, R = {{0}, {0}, 0};
  kd_event *nl_ev[3], *nr_ev[3];
  uint32_t nnl[3] = {0}, nnr[3] = {0};
  kd_event *tmp = arena_alloc(ar, ((size_t)nboth * 2 + 1) * sizeof *tmp);
  int fail = !tmp;
  for (int j = 0; j < 3 && !fail; j++) {
    size_t room = (size_t)l->n[j] + 2 * (size_t)nboth + 1;
    L.e[j] = arena_alloc(ar, room * sizeof(kd_event));
    R.e[j] = arena_alloc(ar, room * sizeof(kd_event));
    nl_ev[j] = arena_alloc(ar, ((size_t)nboth * 2 + 1) * sizeof(kd_event));
    nr_ev[j] = arena_alloc(ar, ((size_t)nboth * 2 + 1) * sizeof(kd_event));
    if (!L.e[j] || !R.e[j] || !nl_ev[j] || !nr_ev[j]) { fail = 1; break; }
    kd_event *le = L.e[j], *re = R.e[j];
    uint32_t nl = 0, nr = 0;
    for (uint32_t i = 0; i < l->n[j]; i++) { /* both written, one kept: no branch on the side */
      kd_event ev = l->e[j][i];
      uint32_t sd = side[ev.v >> 2];
      le[nl] = ev;
      re[nr] = ev;
      nl += sd == SIDE_LEFT;
      nr += sd == SIDE_RIGHT;
    }
    L.n[j] = nl;
    R.n[j] = nr;
  }
  if (fail) { b->oom = 1; make_leaf(b, node, l); arena_release(ar, mark); return; }
  uint32_t lcount = nleft_only, rcount = nright_only;
  for (uint32_t i = 0; i < nboth; i++) {
    uint32_t t = straddle[i];
    const float *v = &kd->tv[9 * (size_t)t];
    bbox cl, cr;
    int mask = kd_clip_split(v, box, k, best_pos, lbox, rbox, &cl, &cr);
    if (mask & 1) { for (int j = 0; j < 3; j++) add_events(nl_ev[j], &nnl[j], t, cl, j); lcount++; }
    if (mask & 2) { for (int j = 0; j < 3; j++) add_events(nr_ev[j], &nnr[j], t, cr, j); rcount++; }
  }
  for (int j = 0; j < 3; j++) {
    ev_sort(nl_ev[j], nnl[j], tmp);
    ev_sort(nr_ev[j], nnr[j], tmp);
    ev_merge_into(L.e[j], L.n[j], nl_ev[j], nnl[j]);
    ev_merge_into(R.e[j], R.n[j], nr_ev[j], nnr[j]);
    L.n[j] += nnl[j];
    R.n[j] += nnr[j];
  }
  L.ntris = lcount;
  R.ntris = rcount;

  kd->nodes[node].split = best_pos;
  uint32_t fl = (uint32_t)k; /* the node's flags are written once its children are placed */
  if (lcount == 0) fl |= KD_BELOW_EMPTY;
  else {
    uint32_t below = push_node(b);
    if (below != UINT32_MAX) build(b, below, lbox, &L, depth - 1);
  }
  if (rcount == 0) fl |= KD_ABOVE_EMPTY;
  else {
    uint32_t above = push_node(b);
    if (above != UINT32_MAX) {
      fl |= above << 4;
      build(b, above, rbox, &R, depth - 1);
    }
  }
  kd->nodes[node].flags = fl;
  arena_release(ar, mark);
}

/* ------------------------------------------------------------- box nodes */


typedef struct kd_boxer { const kd_node *src; kd_node *dst; uint32_t n, cap; int oom; } kd_boxer;

static uint32_t boxer_push(kd_boxer *w, uint32_t k) {
  if (w->n + k > KD_MAX_NODES) { w->oom = 1; return UINT32_MAX; }
  while (w->n + k > w->cap) {
    uint32_t nc = w->cap ? w->cap * 2 : 1024;
    kd_node *d = realloc(w->dst, (size_t)nc * sizeof *d);
    if (!d) { w->oom = 1; return UINT32_MAX; }
    w->dst = d; w->cap = nc;
  }
  w->n += k;
  return w->n - k;
}

static int is_empty_cut(uint32_t fl) {
  return (fl & 3) != KD_LEAF && ((fl & KD_BELOW_EMPTY) != 0) != ((fl & KD_ABOVE_EMPTY) != 0);
}

/* Copies the subtree at src[si] into dst in the same depth-first order, each chain of
 * empty cuts replaced by one box node. Recursion depth is the tree's depth (<= 60). */
static void boxer_copy(kd_boxer *w, uint32_t si) {
  if (w->oom) return;
  float f[6] = {-INFINITY, -INFINITY, -INFINITY, INFINITY, INFINITY, INFINITY};
  int chain = 0;
  while (is_empty_cut(w->src[si].flags)) {
    uint32_t fl = w->src[si].flags, axis = fl & 3;
    if (fl & KD_BELOW_EMPTY) { f[axis] = w->src[si].split; si = fl >> 4; }
    else { f[3 + axis] = w->src[si].split; si++; }
    chain = 1;
  }
  if (chain) {
    uint32_t d = boxer_push(w, KD_BOX_SLOTS);
    if (d == UINT32_MAX) return;
    w->dst[d].prim_offset = 0;
    w->dst[d].flags = KD_BOX;
    memcpy(&w->dst[d + 1], f, sizeof f);
  }
  uint32_t d = boxer_push(w, 1);
  if (d == UINT32_MAX) return;
  kd_node n = w->src[si];
  w->dst[d] = n;
  if ((n.flags & 3) == KD_LEAF) return;
  if (!(n.flags & KD_BELOW_EMPTY)) boxer_copy(w, si + 1);
  if (!(n.flags & KD_ABOVE_EMPTY)) {
    uint32_t above = w->n;
    boxer_copy(w, n.flags >> 4);
    w->dst[d].flags = (n.flags & 15u) | above << 4;
  }
}


/* Leaves and references of the tree as built (before box nodes). */
static void count_tree(const kdtree *kd, kd_stats *st) {
  memset(st, 0, sizeof *st);
  for (uint32_t i = 0; i < kd->nnodes; i++) {
    uint32_t f = kd->nodes[i].flags;
    if ((f & 3) == KD_LEAF) { st->leaves++; st->refs += f >> 2; if ((f >> 2) == 0) st->empty_leaves++; }
    else { /* elided empty children count as (unstored) empty leaves */
      uint32_t elided = ((f & KD_BELOW_EMPTY) != 0) + ((f & KD_ABOVE_EMPTY) != 0);
      st->leaves += elided;
      st->empty_leaves += elided;
    }
  }
}

void kdtree_stats(const accel *a, kd_stats *st) {
  memset(st, 0, sizeof *st);
  if (a->ops != &kdtree_ops) return;
  const kdtree *kd = (const kdtree *)a;
  *st = kd->st;
  st->nodes = kd->nnodes; /* 8-byte slots, box nodes included */
  st->max_depth = kd->max_depth_seen;
  st->bytes = kd->nnodes * sizeof(kd_node) + kd->nprims * (sizeof(kd_tri4) + 4 * sizeof(uint32_t) + 1);
}

/* Builds a subtree by the exact sweep from references (their clipped bounds give its
 * events) into part, whose tv, filter and has_filter are set and whose arrays start
 * empty. side: a byte per triangle of the whole mesh; arena: the calling thread's, given
 * back as it was. Returns 0, or -1 when out of memory. */
int kd_build_part(kdtree *part, uint8_t *side, kd_arena *arena, bbox box, const kd_ref *refs, uint32_t n, int depth) {
  kd_builder b = {part, side, arena, 0};
  arena_mark mark = arena_top(arena);
  evlist l = {{0}, {0}, n};
  kd_event *tmp = arena_alloc(arena, ((size_t)n * 2 + 1) * sizeof *tmp);
  int ok = tmp != NULL;
  for (int k = 0; k < 3 && ok; k++) {
    l.e[k] = arena_alloc(arena, ((size_t)n * 2 + 1) * sizeof(kd_event));
    if (!(ok = l.e[k] != NULL)) break;
    for (uint32_t i = 0; i < n; i++) {
      bbox rb = {v3(refs[i].lo[0], refs[i].lo[1], refs[i].lo[2]), v3(refs[i].hi[0], refs[i].hi[1], refs[i].hi[2])};
      add_events(l.e[k], &l.n[k], refs[i].tri, rb, k);
    }
    ev_sort(l.e[k], l.n[k], tmp);
  }
  uint32_t root = ok ? push_node(&b) : UINT32_MAX;
  if (root != UINT32_MAX) build(&b, root, box, &l, depth);
  arena_release(arena, mark);
  return root == UINT32_MAX || b.oom ? -1 : 0;
}

/* Statistics of the tree as built, then each chain of empty cuts becomes a box node.
 * Returns 0, or -1 when out of memory. */
int kd_box_nodes(kdtree *kd) {
  if (!kd->nnodes) return 0;
  count_tree(kd, &kd->st);
  kd_boxer w = {kd->nodes, NULL, 0, 0, 0};
  boxer_copy(&w, 0);
  if (w.oom) { free(w.dst); return -1; }
  free(kd->nodes);
  kd->nodes = w.dst; kd->nnodes = w.n; kd->cap_nodes = w.cap;
  return 0;
}
