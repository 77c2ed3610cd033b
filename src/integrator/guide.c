/* guide.c — see guide.h. */
#include "integrator/guide.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define QT_RHO 0.01   /* a quadrant holding more of its leaf's flux than this is split */
#define QT_DEPTH 20
#define FIX_BITS 36
#define FIX_MAX_UNITS 16.0

static void qtree_free(qtree *t) { free(t->n); memset(t, 0, sizeof *t); }

static uint32_t qtree_add(guide *g, qtree *t) { /* a zeroed node; UINT32_MAX when full */
  if (g->nodes + 1 > g->max_nodes) { g->full = 1; return UINT32_MAX; }
  if (t->count == t->cap) {
    uint32_t cap = t->cap ? 2 * t->cap : 4;
    qnode *n = realloc(t->n, cap * sizeof *n);
    if (!n) return UINT32_MAX - 1;
    t->n = n; t->cap = cap;
  }
  memset(&t->n[t->count], 0, sizeof(qnode));
  g->nodes++;
  return t->count++;
}

static int qtree_copy(guide *g, const qtree *src, qtree *dst) {
  memset(dst, 0, sizeof *dst);
  if (!src->count) return 0;
  dst->n = malloc(src->count * sizeof(qnode));
  if (!dst->n) return -1;
  memcpy(dst->n, src->n, src->count * sizeof(qnode));
  dst->count = dst->cap = src->count;
  g->nodes += src->count;
  return 0;
}

static double node_total(const qnode *n) {
  double t = 0;
  for (int q = 0; q < 4; q++) t += (double)atomic_load_explicit(&n->sum[q], memory_order_relaxed);
  return t;
}

int guide_init(guide *g, bbox box, uint64_t max_nodes, double spatial_c) {
  memset(g, 0, sizeof *g);
  g->box = box;
  g->max_nodes = max_nodes < 16 ? 16 : max_nodes;
  g->spatial_c = spatial_c;
  g->sn = calloc(1, sizeof *g->sn);
  g->leaves = calloc(1, sizeof *g->leaves);
  if (!g->sn || !g->leaves) { guide_free(g); return -1; }
  g->nsn = g->capsn = g->nleaves = g->capleaves = 1;
  g->sn[0].lo = box.lo;
  g->sn[0].hi = box.hi;
  if (qtree_add(g, &g->leaves[0].building) != 0) { guide_free(g); return -1; }
  return 0;
}

void guide_free(guide *g) {
  for (uint32_t i = 0; i < g->nleaves; i++) { qtree_free(&g->leaves[i].sampling); qtree_free(&g->leaves[i].building); }
  free(g->leaves);
  free(g->sn);
  memset(g, 0, sizeof *g);
}

void guide_set_scale(guide *g, double scale) { g->scale = scale > 0 && isfinite(scale) ? scale : 1; }

const gleaf *guide_leaf(const guide *g, vec3 p) {
  uint32_t i = 0;
  while (g->sn[i].child) {
    const gsnode *n = &g->sn[i];
    float lo = n->axis == 0 ? n->lo.x : n->axis == 1 ? n->lo.y : n->lo.z, hi = n->axis == 0 ? n->hi.x : n->axis == 1 ? n->hi.y : n->hi.z;
    float x = n->axis == 0 ? p.x : n->axis == 1 ? p.y : p.z;
    i = n->child + (x >= 0.5f * (lo + hi));
  }
  return &g->leaves[g->sn[i].leaf];
}

void guide_dir_to_square(vec3 d, float *u, float *v) {
  *u = clampf(0.5f * (d.z + 1), 0, 1);
  float phi = atan2f(d.y, d.x) * (0.5f * INV_PI_F);
  *v = phi < 0 ? phi + 1 : phi;
  if (*v >= 1) *v = 0;
}
vec3 guide_square_to_dir(float u, float v) {
  float z = 2 * u - 1, r = sqrtf(fmaxf(0, 1 - z * z)), phi = 2 * PI_F * v;
  return v3(r * cosf(phi), r * sinf(phi), z);
}

/* ---- one quadtree ---- */
void qtree_sample(const qtree *t, float u1, float u2, float *u, float *v, float *pdf) {
  float x0 = 0, y0 = 0, size = 1, p = 1;
  uint32_t i = 0;
  for (int depth = 0; t->count && depth <= QT_DEPTH + 1; depth++) {
    const qnode *n = &t->n[i];
    double s[4], tot = 0;
    for (int q = 0; q < 4; q++) tot += s[q] = (double)atomic_load_explicit(&n->sum[q], memory_order_relaxed);
    if (!(tot > 0)) break;
    /* u-half by the columns' sums, then the v-half within it; each number remapped */
    double left = s[0] + s[2], pl = left / tot;
    int qx = u1 >= pl;
    u1 = qx ? (float)((u1 - pl) / (1 - pl)) : (float)(u1 / pl);
    double a = s[qx], b = s[qx + 2], pa = a / (a + b);
    int qy = u2 >= pa;
    u2 = qy ? (float)((u2 - pa) / (1 - pa)) : (float)(u2 / pa);
    u1 = clampf(u1, 0, 0x1.fffffep-1f);
    u2 = clampf(u2, 0, 0x1.fffffep-1f);
    int q = qx | qy << 1;
    p *= (float)(4 * s[q] / tot);
    size *= 0.5f;
    x0 += qx * size;
    y0 += qy * size;
    if (!n->child[q]) break;
    i = n->child[q];
  }
  *u = x0 + u1 * size;
  *v = y0 + u2 * size;
  *pdf = p;
}

float qtree_pdf(const qtree *t, float u, float v) {
  float p = 1;
  uint32_t i = 0;
  for (int depth = 0; t->count && depth <= QT_DEPTH + 1; depth++) {
    const qnode *n = &t->n[i];
    double tot = node_total(n);
    if (!(tot > 0)) break;
    int qx = u >= 0.5f, qy = v >= 0.5f, q = qx | qy << 1;
    double s = (double)atomic_load_explicit(&n->sum[q], memory_order_relaxed);
    if (!(s > 0)) return 0;
    p *= (float)(4 * s / tot);
    u = 2 * u - (float)qx;
    v = 2 * v - (float)qy;
    if (!n->child[q]) break;
    i = n->child[q];
  }
  return p;
}

int guide_can_sample(const gleaf *l) { return l->sampling.count && node_total(&l->sampling.n[0]) > 0; }

vec3 guide_sample(const gleaf *l, float u1, float u2, float *pdf) {
  float u, v, p;
  qtree_sample(&l->sampling, u1, u2, &u, &v, &p);
  *pdf = p * (0.25f * INV_PI_F);
  return guide_square_to_dir(u, v);
}

float guide_pdf(const gleaf *l, vec3 d) {
  float u, v;
  guide_dir_to_square(d, &u, &v);
  return qtree_pdf(&l->sampling, u, v) * (0.25f * INV_PI_F);
}

static void sat_add(_Atomic uint64_t *a, uint64_t x) {
  uint64_t old = atomic_load_explicit(a, memory_order_relaxed), nw;
  do {
    nw = old + x < old ? UINT64_MAX : old + x;
  } while (!atomic_compare_exchange_weak_explicit(a, &old, nw, memory_order_relaxed, memory_order_relaxed));
}

void guide_record(guide *g, vec3 p, vec3 d, float value) {
  if (!(value > 0) || !(g->scale > 0)) return;
  double units = value / g->scale;
  uint64_t fx = (uint64_t)(fmin(units, FIX_MAX_UNITS) * (double)(1ULL << FIX_BITS));
  gleaf *l = (gleaf *)guide_leaf(g, p);
  atomic_fetch_add_explicit(&l->records, 1, memory_order_relaxed);
  if (!fx) return;
  float u, v;
  guide_dir_to_square(d, &u, &v);
  qtree *t = &l->building;
  uint32_t i = 0;
  for (int depth = 0; t->count && depth <= QT_DEPTH + 1; depth++) {
    int qx = u >= 0.5f, qy = v >= 0.5f, q = qx | qy << 1;
    sat_add(&t->n[i].sum[q], fx);
    u = 2 * u - (float)qx;
    v = 2 * v - (float)qy;
    if (!t->n[i].child[q]) break;
    i = t->n[i].child[q];
  }
}

/* A new building tree from a sampling tree's flux: quadrants over QT_RHO of the total are
 * split; where src has no node, its flux is taken as spread evenly over the quadrant. */
typedef struct qwork { uint32_t src, dst; int depth; double frac[4]; } qwork;
static int qtree_refined(guide *g, const qtree *src, qtree *dst) {
  memset(dst, 0, sizeof *dst);
  uint32_t root = qtree_add(g, dst);
  if (root == UINT32_MAX - 1) return -1;
  if (root == UINT32_MAX) return 0; /* the cap: no tree, nothing recorded here */
  double tot = src->count ? node_total(&src->n[0]) : 0;
  if (!(tot > 0)) return 0;
  qwork *stack = malloc(sizeof *stack * (4 * (QT_DEPTH + 2)));
  if (!stack) return -1;
  int sp = 0;
  stack[sp].src = 0; stack[sp].dst = root; stack[sp].depth = 1;
  for (int q = 0; q < 4; q++) stack[sp].frac[q] = (double)atomic_load_explicit(&src->n[0].sum[q], memory_order_relaxed) / tot;
  sp++;
  int rc = 0;
  while (sp > 0 && !rc) {
    qwork w = stack[--sp];
    for (int q = 0; q < 4; q++) {
      if (!(w.frac[q] > QT_RHO) || w.depth >= QT_DEPTH) continue;
      uint32_t c = qtree_add(g, dst);
      if (c == UINT32_MAX - 1) { rc = -1; break; }
      if (c == UINT32_MAX) break;
      dst->n[w.dst].child[q] = c;
      qwork nw = {UINT32_MAX, c, w.depth + 1, {0, 0, 0, 0}};
      uint32_t sc = w.src != UINT32_MAX ? src->n[w.src].child[q] : 0;
      if (sc) {
        nw.src = sc;
        for (int k = 0; k < 4; k++) nw.frac[k] = (double)atomic_load_explicit(&src->n[sc].sum[k], memory_order_relaxed) / tot;
      } else
        for (int k = 0; k < 4; k++) nw.frac[k] = w.frac[q] / 4;
      stack[sp++] = nw;
    }
  }
  free(stack);
  return rc;
}

static int grow_spatial(guide *g) {
  if (g->nsn + 2 > g->capsn) {
    uint32_t cap = 2 * g->capsn + 2;
    gsnode *n = realloc(g->sn, cap * sizeof *n);
    if (!n) return -1;
    g->sn = n; g->capsn = cap;
  }
  if (g->nleaves + 1 > g->capleaves) {
    uint32_t cap = 2 * g->capleaves + 1;
    gleaf *l = realloc(g->leaves, cap * sizeof *l);
    if (!l) return -1;
    g->leaves = l; g->capleaves = cap;
  }
  return 0;
}

static float axis_of(vec3 p, int axis) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; }
static void set_axis(vec3 *p, int axis, float x) {
  if (axis == 0) p->x = x; else if (axis == 1) p->y = x; else p->z = x;
}

int guide_refine(guide *g) {
  for (uint32_t i = 0; i < g->nleaves; i++) {
    gleaf *l = &g->leaves[i];
    g->nodes -= l->sampling.count;
    qtree_free(&l->sampling);
    l->sampling = l->building;
    memset(&l->building, 0, sizeof l->building);
  }
  /* Split leaves that saw too many records; the children (appended, so visited by this
   * same loop) start from their parent's count halved and its sampling tree. */
  double thresh = g->spatial_c * sqrt(ldexp(1, g->pass));
  for (uint32_t i = 0; i < g->nsn; i++) {
    if (g->sn[i].child) continue;
    uint32_t li = g->sn[i].leaf, rec = atomic_load(&g->leaves[li].records);
    if (rec <= thresh || g->nodes + g->leaves[li].sampling.count > g->max_nodes / 2) continue;
    if (grow_spatial(g)) return -1;
    uint32_t nl = g->nleaves, c = g->nsn;
    if (qtree_copy(g, &g->leaves[li].sampling, &g->leaves[nl].sampling)) return -1;
    memset(&g->leaves[nl].building, 0, sizeof g->leaves[nl].building);
    atomic_store(&g->leaves[nl].records, rec / 2);
    atomic_store(&g->leaves[li].records, rec / 2);
    g->nleaves++;
    gsnode n = g->sn[i];
    int axis = n.axis, next = (axis + 1) % 3;
    float mid = 0.5f * (axis_of(n.lo, axis) + axis_of(n.hi, axis));
    gsnode a = {n.lo, n.hi, next, 0, li}, b = {n.lo, n.hi, next, 0, nl};
    set_axis(&a.hi, axis, mid);
    set_axis(&b.lo, axis, mid);
    g->sn[c] = a;
    g->sn[c + 1] = b;
    g->sn[i].child = c;
    g->nsn += 2;
  }
  for (uint32_t i = 0; i < g->nleaves; i++) {
    if (qtree_refined(g, &g->leaves[i].sampling, &g->leaves[i].building)) return -1;
    atomic_store(&g->leaves[i].records, 0);
  }
  g->pass++;
  return 0;
}
