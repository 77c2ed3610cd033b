/* pointtree.c — owns the point kd-tree's build (median split by quickselect on the
 * widest axis of each range) and its k-nearest (max-heap) and fixed-radius queries. */
#include "geometry/pointtree.h"
#include <stdlib.h>
#include <string.h>

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
  free(t->p); free(t->id); free(t->axis);
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

/* The radius query restricted to the half-space (p - q).n > eps, pruning subtrees by
 * their boxes (kept from the split planes on the way down): outside the sphere, or all
 * on or behind the plane. Proximity-AO's points on the shaded surface itself (coplanar:
 * most of what a plain radius query finds on a wall) are never visited. */
typedef struct hs_q { vec3 q, n; float r2, eps; point_visit_fn fn; void *user; } hs_q;
#define HS_LEAF 32
static void hs_rec(const point_tree *t, const hs_q *s, uint32_t lo, uint32_t hi, const float bmin[3], const float bmax[3]) {
  if (hi <= lo) return;
  const float q[3] = {s->q.x, s->q.y, s->q.z}, n[3] = {s->n.x, s->n.y, s->n.z};
  float d2box = 0, hmax = 0;
  for (int k = 0; k < 3; k++) {
    float e = bmin[k] - q[k] > 0 ? bmin[k] - q[k] : (q[k] - bmax[k] > 0 ? q[k] - bmax[k] : 0);
    d2box += e * e;
    hmax += n[k] * (n[k] > 0 ? bmax[k] - q[k] : bmin[k] - q[k]);
  }
  if (d2box >= s->r2 || hmax <= s->eps) return;
  if (hi - lo <= HS_LEAF) {
    /* a small subtree is a contiguous run of points: testing them in a row costs less
     * than descending further (the caller's half-space test sees the same points) */
    for (uint32_t i = lo; i < hi; i++) {
      vec3 v = v3_sub(t->p[i], s->q);
      if (!(v3_dot(v, s->n) > s->eps)) continue;
      float d2 = v3_len2(v);
      if (d2 < s->r2) s->fn(s->user, i, d2);
    }
    return;
  }
  uint32_t m = lo + (hi - lo) / 2;
  vec3 vm = v3_sub(t->p[m], s->q);
  float d2 = v3_len2(vm);
  if (d2 < s->r2 && v3_dot(vm, s->n) > s->eps) s->fn(s->user, m, d2);
  int a = t->axis[m];
  float split = coord(t->p[m], a);
  float lmax[3] = {bmax[0], bmax[1], bmax[2]}, rmin[3] = {bmin[0], bmin[1], bmin[2]};
  lmax[a] = split;
  rmin[a] = split;
  hs_rec(t, s, lo, m, bmin, lmax);
  hs_rec(t, s, m + 1, hi, rmin, bmax);
}

void point_tree_radius_halfspace(const point_tree *t, vec3 q, float r2, vec3 n, float eps, point_visit_fn fn, void *user) {
  hs_q s = {q, n, r2, eps, fn, user};
  const float bmin[3] = {t->bounds.lo.x, t->bounds.lo.y, t->bounds.lo.z}, bmax[3] = {t->bounds.hi.x, t->bounds.hi.y, t->bounds.hi.z};
  hs_rec(t, &s, 0, t->n, bmin, bmax);
}

int point_tree_gather(const point_tree *t, const void *in, size_t size, void **out) {
  char *o = malloc((size_t)(t->n ? t->n : 1) * size);
  *out = o;
  if (!o) return -1;
  for (uint32_t i = 0; i < t->n; i++) memcpy(o + (size_t)i * size, (const char *)in + (size_t)t->id[i] * size, size);
  return 0;
}
