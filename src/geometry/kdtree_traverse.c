/* kdtree_traverse.c — owns the kd-tree's ray queries (layout: kdtree_internal.h):
 * pbrt's stack-based front-to-back traversal with early exit over 8-byte nodes and box
 * nodes, and the watertight test of four leaf triangles at a time (SSE). Closest hit and
 * any hit (shadow rays) share one loop; bench_raykernel --bound instruments it
 * (kdtree_trace, kdtree_walk: accel.h). */
#include "geometry/kdtree_internal.h"
#include <stdlib.h>
#include <string.h>
#include <emmintrin.h>

/* ---------------------------------------------------------------- queries */

/* Clips [*tmin, *tmax] to the box f = lo[3], hi[3], entering by faces fin and leaving by
 * faces fout (chosen by the sign of 1/d, not by comparing t: for a ray lying in a face's
 * plane t = 0 * inf = NaN, and a NaN clips nothing). Conservative: a plane's t = (p - o)/d
 * has relative error <= gamma_3, so entry times shrink by lo_scale and exit times grow
 * by hi_scale (1 -/+ 2 gamma_3): a triangle whose edge lies in a cell's face is hit at a t
 * that may round below the computed entry of that cell (test_kdtree camera_rays). */
#define KD_T_LO (1.0f - 2 * fp_gamma(3))
#define KD_T_HI (1.0f + 2 * fp_gamma(3))
static inline int slab_clip(const float f[6], const int fin[3], const int fout[3], const float o[3], const float id[3],
                            float *tmin, float *tmax) {
  for (int k = 0; k < 3; k++) {
    float t0 = (f[fin[k]] - o[k]) * id[k] * KD_T_LO, t1 = (f[fout[k]] - o[k]) * id[k] * KD_T_HI;
    *tmin = t0 > *tmin ? t0 : *tmin;
    *tmax = t1 < *tmax ? t1 : *tmax;
  }
  return *tmin <= *tmax;
}

/* Four triangles against one ray: the watertight test of triangle.h with SSE2, in the
 * same operation order, so every lane's t and barycentrics equal the scalar test's bit
 * for bit. A lane whose edge function is exactly zero sends the group to the scalar
 * test (which then re-evaluates in double precision). Returns the nearest hit. */
static inline __attribute__((always_inline)) int tri4_intersect(const ray_shear *s, const kd_tri4 *g, uint32_t nvalid, float tmax, float *t_out, float *b1_out,
                                 float *b2_out, int *lane_out) {
  const float o[3] = {s->o.x, s->o.y, s->o.z};
  const int kx = s->kx, ky = s->ky, kz = s->kz;
  __m128 ox = _mm_set1_ps(o[kx]), oy = _mm_set1_ps(o[ky]), oz = _mm_set1_ps(o[kz]);
  __m128 sx = _mm_set1_ps(s->sx), sy = _mm_set1_ps(s->sy), sz = _mm_set1_ps(s->sz);
  __m128 ax = _mm_sub_ps(_mm_loadu_ps(g->v[0][kx]), ox), ay = _mm_sub_ps(_mm_loadu_ps(g->v[0][ky]), oy), az = _mm_sub_ps(_mm_loadu_ps(g->v[0][kz]), oz);
  __m128 bx = _mm_sub_ps(_mm_loadu_ps(g->v[1][kx]), ox), by = _mm_sub_ps(_mm_loadu_ps(g->v[1][ky]), oy), bz = _mm_sub_ps(_mm_loadu_ps(g->v[1][kz]), oz);
  __m128 cx = _mm_sub_ps(_mm_loadu_ps(g->v[2][kx]), ox), cy = _mm_sub_ps(_mm_loadu_ps(g->v[2][ky]), oy), cz = _mm_sub_ps(_mm_loadu_ps(g->v[2][kz]), oz);
  ax = _mm_sub_ps(ax, _mm_mul_ps(sx, az)); ay = _mm_sub_ps(ay, _mm_mul_ps(sy, az));
  bx = _mm_sub_ps(bx, _mm_mul_ps(sx, bz)); by = _mm_sub_ps(by, _mm_mul_ps(sy, bz));
  cx = _mm_sub_ps(cx, _mm_mul_ps(sx, cz)); cy = _mm_sub_ps(cy, _mm_mul_ps(sy, cz));
  __m128 u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
  __m128 v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
  __m128 w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
  __m128 zero = _mm_setzero_ps();
  static const int32_t lanes_valid[5][4] = {{0, 0, 0, 0}, {-1, 0, 0, 0}, {-1, -1, 0, 0}, {-1, -1, -1, 0}, {-1, -1, -1, -1}};
  __m128 valid = _mm_castsi128_ps(_mm_loadu_si128((const __m128i *)lanes_valid[nvalid < 4 ? nvalid : 4]));
  __m128 anyzero = _mm_and_ps(valid, _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(v, zero)), _mm_cmpeq_ps(w, zero)));
  if (_mm_movemask_ps(anyzero)) {
    /* Rare: an edge function is exactly zero; the scalar test handles it in double. */
    int found = 0;
    for (int k = 0; k < 4 && (uint32_t)k < nvalid; k++) {
      float tv[9], t, b1, b2;
      for (int vtx = 0; vtx < 3; vtx++)
        for (int a = 0; a < 3; a++) tv[3 * vtx + a] = g->v[vtx][a][k];
      if (tri_intersect(s, tv, tmax, &t, &b1, &b2)) { tmax = t; *t_out = t; *b1_out = b1; *b2_out = b2; *lane_out = k; found = 1; }
    }
    return found;
  }
  __m128 neg = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(u, zero), _mm_cmplt_ps(v, zero)), _mm_cmplt_ps(w, zero));
  __m128 pos = _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(u, zero), _mm_cmpgt_ps(v, zero)), _mm_cmpgt_ps(w, zero));
  __m128 det = _mm_add_ps(_mm_add_ps(u, v), w);
  __m128 hitm = _mm_andnot_ps(_mm_or_ps(_mm_and_ps(neg, pos), _mm_cmpeq_ps(det, zero)), valid);
  if (!_mm_movemask_ps(hitm)) return 0;
  az = _mm_mul_ps(az, sz); bz = _mm_mul_ps(bz, sz); cz = _mm_mul_ps(cz, sz);
  __m128 T = _mm_add_ps(_mm_add_ps(_mm_mul_ps(u, az), _mm_mul_ps(v, bz)), _mm_mul_ps(w, cz));
  float dts[4];
  /* t's error bound dt as tri_resolve_t computes it (same operations, lane-wise), so that
   * lanes certainly behind the origin (t < -dt) or certainly beyond the nearest hit so far
   * (t > dt and t >= tmax) are dropped here; the rest are decided lane by lane. */
  {
    __m128 absm = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    __m128 inv4 = _mm_div_ps(_mm_set1_ps(1.0f), det), t4 = _mm_mul_ps(T, inv4);
    __m128 mz = _mm_max_ps(_mm_max_ps(_mm_and_ps(az, absm), _mm_and_ps(bz, absm)), _mm_and_ps(cz, absm));
    __m128 mx = _mm_max_ps(_mm_max_ps(_mm_and_ps(ax, absm), _mm_and_ps(bx, absm)), _mm_and_ps(cx, absm));
    __m128 my = _mm_max_ps(_mm_max_ps(_mm_and_ps(ay, absm), _mm_and_ps(by, absm)), _mm_and_ps(cy, absm));
    __m128 g2 = _mm_set1_ps(fp_gamma(2)), g3 = _mm_set1_ps(fp_gamma(3)), g5 = _mm_set1_ps(fp_gamma(5));
    __m128 dz = _mm_mul_ps(g3, mz), dx = _mm_mul_ps(g5, _mm_add_ps(mx, mz)), dy = _mm_mul_ps(g5, _mm_add_ps(my, mz));
    __m128 de = _mm_mul_ps(_mm_set1_ps(2), _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_mul_ps(g2, mx), my), _mm_mul_ps(dy, mx)), _mm_mul_ps(dx, my)));
    __m128 me = _mm_max_ps(_mm_max_ps(_mm_and_ps(u, absm), _mm_and_ps(v, absm)), _mm_and_ps(w, absm));
    __m128 dt = _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(3), _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_mul_ps(g3, me), mz), _mm_mul_ps(de, mz)),
                                                                  _mm_mul_ps(dz, me))),
                           _mm_and_ps(inv4, absm));
    __m128 behind = _mm_cmplt_ps(t4, _mm_sub_ps(_mm_setzero_ps(), dt));
    __m128 beyond = _mm_and_ps(_mm_cmpgt_ps(t4, dt), _mm_cmpge_ps(t4, _mm_set1_ps(tmax)));
    hitm = _mm_andnot_ps(_mm_or_ps(behind, beyond), hitm);
    _mm_storeu_ps(dts, dt);
  }
  int mask = _mm_movemask_ps(hitm);
  if (!mask) return 0;
  float Us[4], Vs[4], Ws[4], Ts[4], dets[4];
  _mm_storeu_ps(Us, u); _mm_storeu_ps(Vs, v); _mm_storeu_ps(Ws, w); _mm_storeu_ps(Ts, T); _mm_storeu_ps(dets, det);
  int found = 0;
  for (int k = 0; k < 4; k++) {
    if (!(mask & (1 << k))) continue;
    float inv = 1.0f / dets[k];
    float t = Ts[k] * inv;
    /* Conservative t > 0 exactly as tri_intersect decides it (double when float cannot
     * tell), before comparing with the nearest hit so far: order-independent. */
    if (!(t > dts[k])) {
      if (t < -dts[k]) continue;
      float tv[9];
      for (int vtx = 0; vtx < 3; vtx++)
        for (int a = 0; a < 3; a++) tv[3 * vtx + a] = g->v[vtx][a][k];
      if (!tri_t_double(s, tv, INFINITY, &t)) continue;
    }
    if (!(t < tmax)) continue;
    tmax = t;
    *t_out = t; *b1_out = Vs[k] * inv; *b2_out = Ws[k] * inv; *lane_out = k;
    found = 1;
  }
  return found;
}

typedef struct kd_todo { uint32_t node; float tmin, tmax; } kd_todo;


/* mode: KD_QUERY (the ray queries), KD_TRACE (the query, counting what it visits into tr
 * and recording the leaf where it ends), KD_WALK (the trace's walk again with no triangle
 * tested: reaching the trace's end leaf gives its hit), KD_WALK_COUNT (KD_WALK, counting),
 * KD_DESCENT (the walk's start alone: it ends at the first leaf). mode is a constant in
 * each caller, so each mode gets its own loop; any is decided at run time in all of them,
 * so the timed walks have the ray queries' loop shape. */
enum { KD_QUERY, KD_TRACE, KD_WALK, KD_WALK_COUNT, KD_DESCENT };
/* KD_TRACE: the triangles a query has tested so far, to count the groups it tests again
 * (all their triangles already tested in an earlier leaf: what mailboxing could skip). */
#define KD_SEEN_MAX 2048u
typedef struct kd_seen { uint32_t n, id[KD_SEEN_MAX]; } kd_seen;
static void trace_group(const kdtree *kd, uint32_t gi, uint32_t nvalid, kd_trace *tr, kd_seen *seen) {
  int all = 1;
  tr->groups++;
  for (uint32_t k = 0; k < 4 && k < nvalid; k++) {
    uint32_t t = kd->ids[4 * (size_t)gi + k], q = 0;
    while (q < seen->n && seen->id[q] != t) q++;
    if (q < seen->n) continue;
    all = 0;
    if (seen->n < KD_SEEN_MAX) seen->id[seen->n++] = t;
  }
  tr->dup_groups += (uint32_t)all;
}

static inline __attribute__((always_inline)) int kd_query(const kdtree *kd, const ray *r, hit *h, int any, int mode, kd_trace *tr,
                                                          kd_seen *seen) {
  vec3 inv = v3(1.0f / r->d.x, 1.0f / r->d.y, 1.0f / r->d.z);
  float tmin = 0, tmax = r->tmax;
  float o[3] = {r->o.x, r->o.y, r->o.z}, id[3] = {inv.x, inv.y, inv.z};
  int neg[3] = {signbit(inv.x) != 0, signbit(inv.y) != 0, signbit(inv.z) != 0};
  /* The box face a ray enters by and the one it leaves by, per axis (lo = 0-2, hi = 3-5). */
  int fin[3] = {3 * neg[0], 1 + 3 * neg[1], 2 + 3 * neg[2]}, fout[3] = {3 - 3 * neg[0], 4 - 3 * neg[1], 5 - 3 * neg[2]};
  const float root[6] = {kd->bounds.lo.x, kd->bounds.lo.y, kd->bounds.lo.z, kd->bounds.hi.x, kd->bounds.hi.y, kd->bounds.hi.z};
  if (kd->nnodes == 0 || !slab_clip(root, fin, fout, o, id, &tmin, &tmax)) return 0;
  ray_shear sh = ray_shear_make(r->o, r->d);
  const kd_node *nodes = kd->nodes; /* a local copy: gcc would reload kd->nodes per step */
  float best = r->tmax;
  int found = 0;
  kd_todo todo[64];
  int ntodo = 0;
  uint32_t ni = 0;
  for (;;) {
    /* Past the nearest hit: skip this subtree. Not a break, since the stack is not in
     * front-to-back order when a ray lies in a split plane (both children get the whole
     * interval; test axis_rays). */
    if (best < tmin) goto pop;
    const kd_node *n = &nodes[ni];
    uint32_t axis = n->flags & 3;
    if (mode == KD_TRACE || mode == KD_WALK_COUNT) tr->nodes++;
    if (axis != KD_LEAF) {
      uint32_t fl = n->flags;
      if ((fl & KD_BOX) == KD_BOX) {
        if (mode == KD_TRACE || mode == KD_WALK_COUNT) tr->boxes++;
        /* Clip [tmin, tmax] to the box, exactly as its chain of cuts would have (a NaN,
         * ray in a face's plane, passes as the cut would have let it through). */
        float f[6];
        memcpy(f, &nodes[ni + 1], sizeof f);
        if (!slab_clip(f, fin, fout, o, id, &tmin, &tmax)) goto pop;
        ni += KD_BOX_SLOTS;
        continue;
      }
      /* Near child by the sign of 1/d (so -0 counts as negative, +0 as positive): the
       * near side is the one the ray enters first. t = tp splits [tmin, tmax]; within
       * tp's rounding error (gamma_3, as in slab_clip) both children are visited, each
       * interval ending or starting at tp widened. Both children exist: a split with an
       * empty side is an empty cut, now in a box. */
      float tp = (n->split - o[axis]) * id[axis];
      float tp_lo = tp * KD_T_LO, tp_hi = tp * KD_T_HI;
      uint32_t nearc = neg[axis] ? fl >> 4 : ni + 1, farc = neg[axis] ? ni + 1 : fl >> 4;
      if (tp_lo > tmax) ni = nearc;
      else if (tp_hi < tmin) ni = farc;
      else {
        todo[ntodo].node = farc; todo[ntodo].tmax = tmax;
        if (tp == tp) { todo[ntodo].tmin = tp_lo > tmin ? tp_lo : tmin; tmax = tp_hi < tmax ? tp_hi : tmax; }
        else todo[ntodo].tmin = tmin; /* origin on the plane, ray in it: both, whole interval */
        ntodo++;
        ni = nearc;
      }
      continue;
    }
    uint32_t cnt = n->flags >> 2;
    if (mode == KD_TRACE && tr->leaves == 0) tr->descent = tr->nodes;
    if (mode == KD_TRACE || mode == KD_WALK_COUNT) tr->leaves++;
    if (mode == KD_DESCENT) return 1;
    if (mode == KD_WALK || mode == KD_WALK_COUNT) {
      if (ni == tr->end_leaf) {
        if (any) return 1;
        best = tr->t;
        found = 1;
      }
      goto pop;
    }
    uint32_t gi = n->prim_offset;
    const kd_tri4 *g = &kd->prims[gi];
    for (uint32_t i = 0; i < cnt; i += 4, g++, gi++) {
      float t = 0, b1 = 0, b2 = 0;
      int lane;
      if (mode == KD_TRACE) trace_group(kd, gi, cnt - i, tr, seen);
      if (kd->has_filter && kd->gfilt[gi]) {
        /* Alpha-tested triangles: lane by lane, each hit through the filter. */
        const uint32_t *gid = &kd->ids[4 * (size_t)gi];
        for (int k = 0; k < 4; k++) {
          if (gid[k] == UINT32_MAX) continue;
          float tv[9];
          for (int vtx = 0; vtx < 3; vtx++)
            for (int a = 0; a < 3; a++) tv[3 * vtx + a] = g->v[vtx][a][k];
          if (!tri_intersect(&sh, tv, best, &t, &b1, &b2)) continue;
          if (((kd->gfilt[gi] >> k) & 1) && !kd->filter.pass(kd->filter.user, gid[k], b1, b2, accel_ray_key(r->o, r->d))) continue;
          if (mode == KD_TRACE) tr->end_leaf = ni, tr->t = t;
          if (any) return 1;
          best = t;
          found = 1;
          h->t = t; h->b1 = b1; h->b2 = b2; h->tri = gid[k];
        }
        continue;
      }
      if (tri4_intersect(&sh, g, cnt - i, best, &t, &b1, &b2, &lane)) {
        if (mode == KD_TRACE) tr->end_leaf = ni, tr->t = t;
        if (any) return 1;
        best = t;
        found = 1;
        h->t = t; h->b1 = b1; h->b2 = b2; h->tri = kd->ids[4 * (size_t)gi + lane];
      }
    }
  pop:
    if (ntodo == 0) break;
    ntodo--;
    ni = todo[ntodo].node; tmin = todo[ntodo].tmin; tmax = todo[ntodo].tmax;
  }
  return found;
}

/* One loop for both queries, any decided at run time: separate closest-hit and any-hit
 * copies were measured slower (docs/performance.md). */
static __attribute__((noinline)) int kd_ray_query(const kdtree *kd, const ray *r, hit *h, int any) { return kd_query(kd, r, h, any, KD_QUERY, NULL, NULL); }
static int kd_intersect(const accel *a, const ray *r, hit *h) { return kd_ray_query((const kdtree *)a, r, h, 0); }
static int kd_occluded(const accel *a, const ray *r) { hit h; return kd_ray_query((const kdtree *)a, r, &h, 1); }
int kdtree_trace(const accel *a, const ray *r, int any, kd_trace *tr) {
  hit h;
  memset(tr, 0, sizeof *tr);
  tr->end_leaf = UINT32_MAX;
  kd_seen seen;
  seen.n = 0;
  int found = kd_query((const kdtree *)a, r, &h, any, KD_TRACE, tr, &seen);
  if (tr->leaves == 0) tr->descent = tr->nodes;
  return found;
}
int kdtree_walk(const accel *a, const ray *r, int any, kd_trace *tr, int count) {
  hit h;
  const kdtree *kd = (const kdtree *)a;
  if (count < 0) return kd_query(kd, r, &h, any, KD_DESCENT, tr, NULL);
  if (count == 0) return kd_query(kd, r, &h, any, KD_WALK, tr, NULL);
  tr->nodes = tr->boxes = tr->leaves = 0;
  return kd_query(kd, r, &h, any, KD_WALK_COUNT, tr, NULL);
}
void kdtree_free(kdtree *kd) {
  if (!kd) return;
  free(kd->tv); free(kd->nodes); free(kd->prims); free(kd->ids); free(kd->gfilt); free(kd);
}
static void kd_destroy(accel *a) { kdtree_free((kdtree *)a); }
const accel_ops kdtree_ops = {"kdtree", kd_intersect, kd_occluded, kd_destroy, NULL};
