/* guide.c — see guide.h. */
#include "integrator/guide.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define QT_RHO 0.01   /* a quadrant holding more of its leaf's flux than this is split */
#define QT_DEPTH 20
#define FIX_BITS 32
#define FIX_MAX_UNITS 16.0
#define M2_MAX_UNITS 4096.0

const float guide_fraction[GUIDE_FRACTIONS] = {0.25f, 0.5f, 0.75f, 1.0f};

static void qtree_free(qtree *t) { free(t->n); memset(t, 0, sizeof *t); }
static void stree_free(stree *t) { free(t->n); memset(t, 0, sizeof *t); }
static uint64_t node_total_u(const qnode *n) {
  uint64_t t = 0;
  for (int q = 0; q < 4; q++) t += atomic_load_explicit(&n->sum[q], memory_order_relaxed);
  return t;
}
static double node_total_q(const qnode *n) {
  double t = 0;
  for (int q = 0; q < 4; q++) t += (double)atomic_load_explicit(&n->sum[q], memory_order_relaxed);
  return t;
}


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

static int stree_copy(guide *g, const stree *src, stree *dst) {
  memset(dst, 0, sizeof *dst);
  if (!src->count) return 0;
  dst->n = malloc(src->count * sizeof(snode));
  if (!dst->n) return -1;
  memcpy(dst->n, src->n, src->count * sizeof(snode));
  dst->count = src->count;
  g->nodes += src->count;
  return 0;
}

/* The sampling tree of a building tree's flux: each node's quadrant shares (a node whose
 * quadrants got nothing keeps uniform shares, never reached by sampling or pdf as its
 * parent's share is 0); no tree when nothing was recorded. */
static int stree_from(guide *g, const qtree *b, stree *t) {
  memset(t, 0, sizeof *t);
  if (!b->count || !(node_total_q(&b->n[0]) > 0)) return 0;
  t->n = malloc(b->count * sizeof(snode));
  if (!t->n) return -1;
  t->count = b->count;
  g->nodes += b->count;
  for (uint32_t i = 0; i < b->count; i++) {
    double tot = node_total_q(&b->n[i]);
    for (int q = 0; q < 4; q++) {
      t->n[i].child[q] = b->n[i].child[q];
      t->n[i].p[q] = tot > 0 ? (float)((double)atomic_load_explicit(&b->n[i].sum[q], memory_order_relaxed) / tot) : 0.25f;
    }
    const float *pq = t->n[i].p;
    t->n[i].pu = pq[0] + pq[2];
    for (int c = 0; c < 2; c++) t->n[i].pv[c] = pq[c] + pq[c + 2] > 0 ? pq[c] / (pq[c] + pq[c + 2]) : 0.5f;
  }
  return 0;
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
  for (int b = 0; b < GUIDE_BINS; b++) g->leaves[0].frac[b] = -1;
  g->sn[0].lo = box.lo;
  g->sn[0].hi = box.hi;
  g->sn[0].mid = 0.5f * (box.lo.x + box.hi.x);
  for (int b = 0; b < GUIDE_BINS; b++)
    if (qtree_add(g, &g->leaves[0].building[b]) != 0) { guide_free(g); return -1; }
  return 0;
}

void guide_free(guide *g) {
  for (uint32_t i = 0; i < g->nleaves; i++)
    for (int b = 0; b < GUIDE_BINS; b++) { stree_free(&g->leaves[i].sampling[b]); qtree_free(&g->leaves[i].building[b]); }
  free(g->leaves);
  free(g->sn);
  memset(g, 0, sizeof *g);
}

void guide_set_scale(guide *g, double scale) { g->scale = scale > 0 && isfinite(scale) ? scale : 1; }

const gleaf *guide_leaf(const guide *g, vec3 p) {
  uint32_t i = 0;
  const float pc[3] = {p.x, p.y, p.z};
  while (g->sn[i].child) i = g->sn[i].child + (pc[g->sn[i].axis] >= g->sn[i].mid);
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

/* ---- sampling trees ---- */
void stree_sample(const stree *t, float u1, float u2, float *u, float *v, float *pdf) {
  float x0 = 0, y0 = 0, size = 1, p = 1;
  uint32_t i = 0;
  for (int depth = 0; t->count && depth <= QT_DEPTH + 1; depth++) {
    const snode *n = &t->n[i];
    /* the u-half by the columns' shares, then the v-half within it; each number remapped */
    float pl = n->pu;
    int qx = u1 >= pl;
    u1 = qx ? (u1 - pl) / (1 - pl) : u1 / pl;
    float pa = n->pv[qx];
    int qy = u2 >= pa;
    u2 = qy ? (u2 - pa) / (1 - pa) : u2 / pa;
    u1 = clampf(u1, 0, 0x1.fffffep-1f);
    u2 = clampf(u2, 0, 0x1.fffffep-1f);
    int q = qx | qy << 1;
    p *= 4 * n->p[q];
    size *= 0.5f;
    x0 += (float)qx * size;
    y0 += (float)qy * size;
    if (!n->child[q]) break;
    i = n->child[q];
  }
  *u = x0 + u1 * size;
  *v = y0 + u2 * size;
  *pdf = p;
}

float stree_pdf(const stree *t, float u, float v) {
  float p = 1;
  uint32_t i = 0;
  for (int depth = 0; t->count && depth <= QT_DEPTH + 1; depth++) {
    const snode *n = &t->n[i];
    int qx = u >= 0.5f, qy = v >= 0.5f, q = qx | qy << 1;
    p *= 4 * n->p[q];
    if (!n->child[q] || p == 0) break;
    u = 2 * u - (float)qx;
    v = 2 * v - (float)qy;
    i = n->child[q];
  }
  return p;
}

int guide_bin(vec3 n) {
  float ax = fabsf(n.x), ay = fabsf(n.y), az = fabsf(n.z);
  if (ax >= ay && ax >= az) return n.x < 0;
  if (ay >= az) return 2 + (n.y < 0);
  return 4 + (n.z < 0);
}

int guide_can_sample(const gleaf *l, int b) { return l->sampling[b].count > 0; }

vec3 guide_sample(const gleaf *l, int b, float u1, float u2, float *pdf) {
  float u, v, p;
  stree_sample(&l->sampling[b], u1, u2, &u, &v, &p);
  *pdf = p * (0.25f * INV_PI_F);
  return guide_square_to_dir(u, v);
}

float guide_pdf(const gleaf *l, int b, vec3 d) {
  float u, v;
  guide_dir_to_square(d, &u, &v);
  return stree_pdf(&l->sampling[b], u, v) * (0.25f * INV_PI_F);
}

void guide_record(const guide *g, gleaf *l, int b, vec3 d, float value) {
  atomic_fetch_add_explicit(&l->records, 1, memory_order_relaxed); /* every vertex counts, lit or not */
  if (!(value > 0) || !(g->scale > 0)) return;
  double units = value / g->scale;
  uint64_t fx = (uint64_t)(fmin(units, FIX_MAX_UNITS) * (double)(1ULL << FIX_BITS));
  if (!fx) return;
  float u, v;
  guide_dir_to_square(d, &u, &v);
  /* only the deepest quadrant takes the record (threads seldom meet there); guide_refine
     sums the parents' */
  qtree *t = &l->building[b];
  uint32_t i = 0;
  for (int depth = 0; t->count && depth <= QT_DEPTH + 1; depth++) {
    int qx = u >= 0.5f, qy = v >= 0.5f, q = qx | qy << 1;
    if (!t->n[i].child[q]) { atomic_fetch_add_explicit(&t->n[i].sum[q], fx, memory_order_relaxed); break; }
    u = 2 * u - (float)qx;
    v = 2 * v - (float)qy;
    i = t->n[i].child[q];
  }
}

void guide_record_moments(const guide *g, gleaf *l, int b, double x, float q, float pb, float pg) {
  if (!(x > 0) || !(q > 0) || !(g->scale > 0)) return;
  for (int k = 0; k < GUIDE_FRACTIONS; k++) {
    double a = guide_fraction[k], qa = a * pb + (1 - a) * pg;
    double units = qa > 0 ? x * x * q / qa : M2_MAX_UNITS; /* a cannot draw this direction: as bad as it gets */
    uint64_t fx = (uint64_t)(fmin(units, M2_MAX_UNITS) * (double)(1ULL << FIX_BITS));
    if (fx) atomic_fetch_add_explicit(&l->m2[b][k], fx, memory_order_relaxed);
  }
}

/* The fraction the pass's second moments choose (unchanged when nothing was recorded). */
static void learn_fraction(gleaf *l, int b) {
  uint64_t m[GUIDE_FRACTIONS];
  int best = 0;
  for (int k = 0; k < GUIDE_FRACTIONS; k++) {
    m[k] = atomic_load_explicit(&l->m2[b][k], memory_order_relaxed);
    atomic_store_explicit(&l->m2[b][k], 0, memory_order_relaxed);
    if (m[k] < m[best]) best = k;
  }
  if (m[GUIDE_FRACTIONS - 1] == 0 && m[best] == 0) return;
  if ((double)m[GUIDE_FRACTIONS - 1] <= GUIDE_PURE_MARGIN * (double)m[best]) best = GUIDE_FRACTIONS - 1;
  l->frac[b] = guide_fraction[best];
}

double guide_pure_share(const guide *g) {
  uint64_t n = 0, pure = 0;
  for (uint32_t i = 0; i < g->nleaves; i++)
    for (int b = 0; b < GUIDE_BINS; b++)
      if (g->leaves[i].frac[b] >= 0) { n++; pure += g->leaves[i].frac[b] == 1; }
  return n ? (double)pure / (double)n : 0;
}

/* Each quadrant with a child gets the child's total (children come after their parents). */
static void qtree_sum_up(qtree *t) {
  for (uint32_t i = t->count; i-- > 0;)
    for (int q = 0; q < 4; q++)
      if (t->n[i].child[q]) atomic_store_explicit(&t->n[i].sum[q], node_total_u(&t->n[t->n[i].child[q]]), memory_order_relaxed);
}

/* A new building tree from a sampling tree's flux: quadrants over QT_RHO of the total are
 * split; where src has no node, its flux is taken as spread evenly over the quadrant. */
typedef struct qwork { uint32_t src, dst; int depth; double frac[4]; } qwork;
static int qtree_refined(guide *g, const qtree *src, qtree *dst) {
  memset(dst, 0, sizeof *dst);
  uint32_t root = qtree_add(g, dst);
  if (root == UINT32_MAX - 1) return -1;
  if (root == UINT32_MAX) return 0; /* the cap: no tree, nothing recorded here */
  double tot = src->count ? node_total_q(&src->n[0]) : 0;
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

void guide_stop(guide *g) {
  for (uint32_t i = 0; i < g->nleaves; i++)
    for (int b = 0; b < GUIDE_BINS; b++) {
      g->nodes -= g->leaves[i].building[b].count;
      qtree_free(&g->leaves[i].building[b]);
    }
}

static float axis_of(vec3 p, int axis) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; }
static void set_axis(vec3 *p, int axis, float x) {
  if (axis == 0) p->x = x; else if (axis == 1) p->y = x; else p->z = x;
}

int guide_refine(guide *g) {
  /* each leaf: the pass's flux becomes the sampling tree and shapes the next building tree */
  for (uint32_t i = 0; i < g->nleaves; i++)
    for (int b = 0; b < GUIDE_BINS; b++) {
      gleaf *l = &g->leaves[i];
      learn_fraction(l, b);
      g->nodes -= l->sampling[b].count;
      stree_free(&l->sampling[b]);
      qtree nb;
      qtree_sum_up(&l->building[b]);
      if (qtree_refined(g, &l->building[b], &nb) || stree_from(g, &l->building[b], &l->sampling[b])) { qtree_free(&nb); return -1; }
      g->nodes -= l->building[b].count;
      qtree_free(&l->building[b]);
      l->building[b] = nb;
    }
  /* Split leaves that saw too many records; the children (appended, so visited by this
   * same loop) start from their parent's count halved and its trees. */
  double thresh = g->spatial_c * sqrt(ldexp(1, g->pass));
  for (uint32_t i = 0; i < g->nsn; i++) {
    if (g->sn[i].child) continue;
    uint32_t li = g->sn[i].leaf, rec = atomic_load(&g->leaves[li].records);
    uint64_t held = 0;
    for (int b = 0; b < GUIDE_BINS; b++) held += g->leaves[li].sampling[b].count + g->leaves[li].building[b].count;
    if (rec <= thresh || g->nodes + held > g->max_nodes) continue;
    if (grow_spatial(g)) return -1;
    uint32_t nl = g->nleaves, c = g->nsn;
    gleaf *src = &g->leaves[li], *dst = &g->leaves[nl];
    memset(dst, 0, sizeof *dst);
    for (int b = 0; b < GUIDE_BINS; b++) {
      dst->frac[b] = src->frac[b];
      if (stree_copy(g, &src->sampling[b], &dst->sampling[b])) return -1;
      if (!src->building[b].count) continue;
      dst->building[b].n = malloc(src->building[b].count * sizeof(qnode));
      if (!dst->building[b].n) return -1;
      memcpy(dst->building[b].n, src->building[b].n, src->building[b].count * sizeof(qnode));
      dst->building[b].count = dst->building[b].cap = src->building[b].count;
      g->nodes += src->building[b].count;
    }
    atomic_store(&dst->records, rec / 2);
    atomic_store(&src->records, rec / 2);
    g->nleaves++;
    gsnode n = g->sn[i];
    int axis = n.axis, next = (axis + 1) % 3;
    float mid = 0.5f * (axis_of(n.lo, axis) + axis_of(n.hi, axis));
    gsnode a = {n.lo, n.hi, 0, next, 0, li}, b = {n.lo, n.hi, 0, next, 0, nl};
    set_axis(&a.hi, axis, mid);
    set_axis(&b.lo, axis, mid);
    a.mid = 0.5f * (axis_of(a.lo, next) + axis_of(a.hi, next));
    b.mid = 0.5f * (axis_of(b.lo, next) + axis_of(b.hi, next));
    g->sn[c] = a;
    g->sn[c + 1] = b;
    g->sn[i].child = c;
    g->nsn += 2;
  }
  for (uint32_t i = 0; i < g->nleaves; i++) atomic_store(&g->leaves[i].records, 0);
  g->pass++;
  return 0;
}
