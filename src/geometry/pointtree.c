/* pointtree.c — owns the point kd-tree's build (median split by quickselect on the
 * widest axis of each range), its k-nearest (max-heap) and fixed-radius queries, and the
 * box hierarchy with its half-space radius query (SSE2 box test, scalar fallback). */
#include "geometry/pointtree.h"
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

static float coord(vec3 p, int a) { return a == 0 ? p.x : a == 1 ? p.y : p.z; }

static void swap_pt(point_tree *t, uint32_t a, uint32_t b) {
  vec3 p = t->p[a]; t->p[a] = t->p[b]; t->p[b] = p;
  uint32_t i = t->id[a]; t->id[a] = t->id[b]; t->id[b] = i;
}

/* Puts the element of rank m (by coordinate a, ties by id) at m within [lo, hi). */
static void select_median(point_tree *t, uint32_t lo, uint32_t hi, uint32_t m, int a) {
  while (hi - lo > 1) {
    uint32_t mid = lo + (hi - lo) / 2, last = hi - 1;
    swap_pt(t, mid, last);
    float pv = coord(t->p[last], a);
    uint32_t pid = t->id[last], store = lo;
    for (uint32_t i = lo; i < last; i++) {
      float v = coord(t->p[i], a);
      if (v < pv || (v == pv && t->id[i] < pid)) swap_pt(t, i, store++);
    }
    swap_pt(t, store, last);
    if (store == m) return;
    if (store > m) hi = store;
    else lo = store + 1;
  }
}

static void build(point_tree *t, uint32_t lo, uint32_t hi) {
  while (hi > lo) {
    bbox b = bbox_empty();
    for (uint32_t i = lo; i < hi; i++) b = bbox_add(b, t->p[i]);
    vec3 e = v3_sub(b.hi, b.lo);
    int a = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    uint32_t m = lo + (hi - lo) / 2;
    select_median(t, lo, hi, m, a);
    t->axis[m] = (uint8_t)a;
    build(t, lo, m);
    lo = m + 1; /* the right half by iteration */
  }
}

int point_tree_build(point_tree *t, const vec3 *pts, uint32_t n) { return point_set_build(t, pts, n, sizeof *pts, 0, NULL); }

int point_set_build(point_tree *t, const void *recs, uint32_t n, size_t stride, size_t pos_offset, void **out) {
  memset(t, 0, sizeof *t);
  if (out) *out = NULL;
  t->p = malloc((size_t)(n ? n : 1) * sizeof *t->p);
  t->id = malloc((size_t)(n ? n : 1) * sizeof *t->id);
  t->axis = malloc(n ? n : 1);
  if (!t->p || !t->id || !t->axis) { point_tree_free(t); return -1; }
  for (uint32_t i = 0; i < n; i++) memcpy(&t->p[i], (const char *)recs + (size_t)i * stride + pos_offset, sizeof(vec3));
  const vec3 *pts = t->p;
  for (uint32_t i = 0; i < n; i++) t->id[i] = i;
  t->n = n;
  t->bounds = bbox_empty();
  for (uint32_t i = 0; i < n; i++) t->bounds = bbox_add(t->bounds, pts[i]);
  build(t, 0, n);
  if (out && point_tree_gather(t, recs, stride, out)) { point_tree_free(t); return -1; }
  return 0;
}

void point_tree_free(point_tree *t) {
  free(t->p); free(t->id); free(t->axis); free(t->box);
  memset(t, 0, sizeof *t);
}

typedef struct knn_q { vec3 q, n; float f; int k, cnt; float r2; point_near *h; } knn_q;

/* max-heap on d2 */
static void heap_push(knn_q *s, float d2, uint32_t i) {
  if (s->cnt < s->k) {
    int c = s->cnt++;
    while (c > 0) {
      int p = (c - 1) / 2;
      if (s->h[p].d2 >= d2) break;
      s->h[c] = s->h[p];
      c = p;
    }
    s->h[c].d2 = d2; s->h[c].i = i;
    if (s->cnt == s->k) s->r2 = s->h[0].d2;
    return;
  }
  /* replace the top */
  int c = 0;
  for (;;) {
    int l = 2 * c + 1, r = l + 1, m = c;
    float md = d2;
    if (l < s->k && s->h[l].d2 > md) { m = l; md = s->h[l].d2; }
    if (r < s->k && s->h[r].d2 > md) m = r;
    if (m == c) break;
    s->h[c] = s->h[m];
    c = m;
  }
  s->h[c].d2 = d2; s->h[c].i = i;
  s->r2 = s->h[0].d2;
}

static void knn_rec(const point_tree *t, knn_q *s, uint32_t lo, uint32_t hi) {
  while (hi > lo) {
    uint32_t m = lo + (hi - lo) / 2;
    int a = t->axis[m];
    vec3 v = v3_sub(t->p[m], s->q);
    float d2 = v3_len2(v);
    if (s->f > 0) { float dn = v3_dot(v, s->n); d2 += s->f * dn * dn; }
    if (d2 < s->r2) heap_push(s, d2, m);
    float diff = coord(s->q, a) - coord(t->p[m], a);
    uint32_t nlo = diff < 0 ? lo : m + 1, nhi = diff < 0 ? m : hi;
    uint32_t flo = diff < 0 ? m + 1 : lo, fhi = diff < 0 ? hi : m;
    knn_rec(t, s, nlo, nhi);
    if (!(diff * diff < s->r2)) return;
    lo = flo; hi = fhi;
  }
}

int point_tree_knn(const point_tree *t, vec3 q, int k, float r2max, vec3 n_squeeze, float f, point_near *out) {
  if (k <= 0) return 0;
  if (k > POINT_KNN_MAX) k = POINT_KNN_MAX;
  knn_q s = {q, n_squeeze, f, k, 0, r2max, out};
  knn_rec(t, &s, 0, t->n);
  return s.cnt;
}

typedef struct rad_q { vec3 q; float r2; point_visit_fn fn; void *user; } rad_q;
static void rad_rec(const point_tree *t, const rad_q *s, uint32_t lo, uint32_t hi) {
  while (hi > lo) {
    uint32_t m = lo + (hi - lo) / 2;
    int a = t->axis[m];
    float d2 = v3_len2(v3_sub(t->p[m], s->q));
    if (d2 < s->r2) s->fn(s->user, m, d2);
    float diff = coord(s->q, a) - coord(t->p[m], a);
    uint32_t nlo = diff < 0 ? lo : m + 1, nhi = diff < 0 ? m : hi;
    uint32_t flo = diff < 0 ? m + 1 : lo, fhi = diff < 0 ? hi : m;
    rad_rec(t, s, nlo, nhi);
    if (!(diff * diff < s->r2)) return;
    lo = flo; hi = fhi;
  }
}

void point_tree_radius(const point_tree *t, vec3 q, float r2, point_visit_fn fn, void *user) {
  rad_q s = {q, r2, fn, user};
  rad_rec(t, &s, 0, t->n);
}

/* The box hierarchy over the tree order: node [lo, hi) splits at its median m into
 * [lo, m) and [m, hi) (the kd-tree's split, the median going right), down to runs of at
 * most BOX_LEAF points; each node keeps the tight box of its own points, so that a run
 * lying in a wall is pruned whole by the half-space test. Nodes in preorder (the left
 * child follows its parent). */
#define BOX_LEAF 32
static uint32_t box_build(point_tree *t, uint32_t lo, uint32_t hi) {
  uint32_t id = t->n_box++;
  point_box *b = &t->box[id];
  bbox bb = bbox_empty();
  for (uint32_t i = lo; i < hi; i++) bb = bbox_add(bb, t->p[i]);
  b->lo[0] = bb.lo.x; b->lo[1] = bb.lo.y; b->lo[2] = bb.lo.z;
  b->hi[0] = bb.hi.x; b->hi[1] = bb.hi.y; b->hi[2] = bb.hi.z;
  b->a = lo; b->b = hi;
  if (hi - lo > BOX_LEAF) {
    uint32_t m = lo + (hi - lo) / 2;
    box_build(t, lo, m);
    uint32_t r = box_build(t, m, hi);
    t->box[id].a = r;
    t->box[id].b = 0;
  }
  return id;
}

int point_tree_build_boxes(point_tree *t) {
  free(t->box);
  t->n_box = 0;
  /* at most 2 n / BOX_LEAF + 1 nodes, one for an empty tree */
  size_t cap = 2 * ((size_t)t->n / (BOX_LEAF / 2) + 1);
  t->box = malloc(cap * sizeof *t->box);
  if (!t->box) return -1;
  if (t->n) box_build(t, 0, t->n);
  return 0;
}

/* Whether box b may hold points within the sphere (q, r2) and in front of the plane
 * (x - q).n > eps: its distance to q below r, and its corner farthest along n in front. */
#if defined(__SSE2__)
typedef struct box_q { __m128 q, n, npos, xyz, lim; } box_q;
static box_q box_query(vec3 q, vec3 n, float r2, float eps) {
  box_q b;
  b.q = _mm_setr_ps(q.x, q.y, q.z, 0);
  b.n = _mm_setr_ps(n.x, n.y, n.z, 0);
  b.npos = _mm_cmpgt_ps(b.n, _mm_setzero_ps());
  b.xyz = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
  b.lim = _mm_setr_ps(r2, -eps, 0, 0);
  return b;
}
static int box_hit(const box_q *s, const point_box *b) {
  /* lane 3 holds an index word: cleared before any arithmetic (as a float it would be a
   * denormal, which costs a microcode assist per operation) */
  __m128 lo = _mm_and_ps(_mm_loadu_ps(b->lo), s->xyz), hi = _mm_and_ps(_mm_loadu_ps(b->hi), s->xyz);
  __m128 e = _mm_max_ps(_mm_max_ps(_mm_sub_ps(lo, s->q), _mm_sub_ps(s->q, hi)), _mm_setzero_ps());
  __m128 e2 = _mm_mul_ps(e, e);
  __m128 far = _mm_or_ps(_mm_and_ps(s->npos, hi), _mm_andnot_ps(s->npos, lo));
  __m128 h = _mm_mul_ps(_mm_sub_ps(s->q, far), s->n); /* -n.(far - q) per axis */
  /* lane 0: |e|^2, lane 1: -(far - q).n */
  __m128 t = _mm_add_ps(_mm_unpacklo_ps(e2, h), _mm_unpackhi_ps(e2, h));
  t = _mm_add_ps(t, _mm_movehl_ps(t, t));
  return (_mm_movemask_ps(_mm_cmplt_ps(t, s->lim)) & 3) == 3;
}
#else
typedef struct box_q { float q[3], n[3], r2, eps; } box_q;
static box_q box_query(vec3 q, vec3 n, float r2, float eps) {
  box_q b = {{q.x, q.y, q.z}, {n.x, n.y, n.z}, r2, eps};
  return b;
}
static int box_hit(const box_q *s, const point_box *b) {
  float d2box = 0, hmax = 0;
  for (int k = 0; k < 3; k++) {
    float e = b->lo[k] - s->q[k] > 0 ? b->lo[k] - s->q[k] : (s->q[k] - b->hi[k] > 0 ? s->q[k] - b->hi[k] : 0);
    d2box += e * e;
    hmax += s->n[k] * (s->n[k] > 0 ? b->hi[k] - s->q[k] : b->lo[k] - s->q[k]);
  }
  return d2box < s->r2 && hmax > s->eps;
}
#endif

/* The radius query restricted to the half-space (p - q).n > eps, over the box hierarchy:
 * a node is skipped when its box lies outside the sphere or all on or behind the plane.
 * Proximity-AO's points on the shaded surface itself (coplanar: most of what a plain
 * radius query finds on a wall) are never visited. */
void point_tree_halfspace_runs(const point_tree *t, vec3 q, float r2, vec3 n, float eps, point_run_fn fn, void *user) {
  if (!t->n_box) return;
  const box_q bq = box_query(q, n, r2, eps);
  uint32_t stack[64];
  int sp = 0;
  uint32_t id = 0;
  for (;;) {
    const point_box *b = &t->box[id];
    if (box_hit(&bq, b)) {
      if (b->b) fn(user, b->a, b->b);
      else {
        stack[sp++] = b->a;
        id = id + 1;
        continue;
      }
    }
    if (!sp) return;
    id = stack[--sp];
  }
}

typedef struct hs_visit { const point_tree *t; vec3 q, n; float r2, eps; point_visit_fn fn; void *user; } hs_visit;
static void hs_points(void *user, uint32_t lo, uint32_t hi) {
  const hs_visit *s = user;
  for (uint32_t i = lo; i < hi; i++) {
    vec3 v = v3_sub(s->t->p[i], s->q);
    if (!(v3_dot(v, s->n) > s->eps)) continue;
    float d2 = v3_len2(v);
    if (d2 < s->r2) s->fn(s->user, i, d2);
  }
}

void point_tree_radius_halfspace(const point_tree *t, vec3 q, float r2, vec3 n, float eps, point_visit_fn fn, void *user) {
  hs_visit s = {t, q, n, r2, eps, fn, user};
  point_tree_halfspace_runs(t, q, r2, n, eps, hs_points, &s);
}

int point_tree_gather(const point_tree *t, const void *in, size_t size, void **out) {
  char *o = malloc((size_t)(t->n ? t->n : 1) * size);
  *out = o;
  if (!o) return -1;
  for (uint32_t i = 0; i < t->n; i++) memcpy(o + (size_t)i * size, (const char *)in + (size_t)t->id[i] * size, size);
  return 0;
}
