/* test_pointtree.c — the point kd-tree (src/geometry/pointtree.c) against brute force:
 * k-nearest (Euclidean and squeezed along a normal, with a radius cap) and fixed-radius
 * queries on 10^5 random queries over points in a volume and on planes (photons lie on
 * surfaces, with many equal coordinates), including duplicates and an empty tree. */
#include "harness.h"
#include "geometry/pointtree.h"
#include "core/rng.h"
#include <stdlib.h>
#include <string.h>
#include <math.h>

static float rnd(uint64_t *s) { *s = rng_mix64(*s + 0x9e3779b97f4a7c15ULL); return (float)(*s >> 40) * 0x1p-24f; }

static int cmp_float(const void *a, const void *b) { float x = *(const float *)a, y = *(const float *)b; return (x > y) - (x < y); }

typedef struct rad_acc { uint64_t count; double sum_d2; const point_tree *t; uint64_t id_sum; } rad_acc;
static void rad_visit(void *user, uint32_t i, float d2) {
  rad_acc *a = user;
  a->count++;
  a->sum_d2 += d2;
  a->id_sum += a->t->id[i];
}

/* half-space visits: the callback filters to the points in front (as proximity-ao does) */
static const vec3 *g_hs_pts;
static vec3 g_hs_q, g_hs_n;
static float g_hs_eps;
static void hs_visit(void *user, uint32_t i, float d2) {
  rad_acc *a = user;
  vec3 v = v3_sub(a->t->p[i], g_hs_q);
  if (!(v3_dot(v, g_hs_n) > g_hs_eps)) return;
  (void)g_hs_pts;
  rad_visit(user, i, d2);
}

static float metric(vec3 p, vec3 q, vec3 n, float f) {
  vec3 v = v3_sub(p, q);
  float dn = v3_dot(v, n);
  return v3_len2(v) + f * dn * dn;
}

static int queries_match_brute_force(void) {
  enum { NP = 6000, NQ = 100000 };
  vec3 *pts = malloc(NP * sizeof *pts);
  CHECK(pts, "oom");
  uint64_t s = 12345;
  for (int i = 0; i < NP; i++) {
    float a = rnd(&s), b = rnd(&s), c = rnd(&s);
    if (i % 3 == 0) pts[i] = v3(a, b, c);            /* volume */
    else if (i % 3 == 1) pts[i] = v3(a, 0.25f, c);   /* a plane: all y equal */
    else pts[i] = v3(0.75f, b, c);                  /* a wall */
    if (i % 97 == 0 && i > 0) pts[i] = pts[i - 1];  /* duplicates */
  }
  point_tree t;
  CHECK(point_tree_build(&t, pts, NP) == 0 && point_tree_build_boxes(&t) == 0, "build");
  CHECK(t.n == NP, "n");
  /* the tree holds a permutation of the points */
  char *seen = calloc(NP, 1);
  for (uint32_t i = 0; i < t.n; i++) {
    CHECK(t.id[i] < NP && !seen[t.id[i]], "id %u", t.id[i]);
    seen[t.id[i]] = 1;
    CHECK(v3_len2(v3_sub(t.p[i], pts[t.id[i]])) == 0, "position of %u", i);
  }
  free(seen);
  float *bd = malloc(NP * sizeof *bd), got[64], want[64];
  point_near out[64];
  int bad_knn = 0, bad_rad = 0, bad_hs = 0;
  g_hs_pts = pts;
  for (int qi = 0; qi < NQ; qi++) {
    vec3 q = v3(rnd(&s) * 1.2f - 0.1f, rnd(&s) * 1.2f - 0.1f, rnd(&s) * 1.2f - 0.1f);
    int k = 1 + (int)(rnd(&s) * 40);
    float r2 = qi % 4 == 0 ? INFINITY : 0.002f + 0.05f * rnd(&s);
    vec3 n = v3_norm(v3(rnd(&s) - 0.5f, rnd(&s) - 0.5f, rnd(&s) - 0.5f));
    float f = qi % 2 ? 16.0f : 0.0f;
    int cnt = point_tree_knn(&t, q, k, r2, n, f, out);
    /* brute force: the k smallest metric values below r2 */
    int m = 0;
    for (int i = 0; i < NP; i++) {
      float d = metric(pts[i], q, n, f);
      if (d < r2) bd[m++] = d;
    }
    qsort(bd, (size_t)m, sizeof *bd, cmp_float);
    int expect = m < k ? m : k;
    if (cnt != expect) { bad_knn++; continue; }
    for (int i = 0; i < cnt; i++) {
      got[i] = metric(t.p[out[i].i], q, n, f);
      want[i] = bd[i];
      if (fabsf(got[i] - out[i].d2) > 1e-6f * (1 + got[i])) bad_knn++;
    }
    qsort(got, (size_t)cnt, sizeof *got, cmp_float);
    for (int i = 0; i < cnt; i++)
      if (got[i] != want[i]) { bad_knn++; break; }
    /* fixed radius */
    float rr = 0.001f + 0.02f * rnd(&s);
    rad_acc a = {0, 0, &t, 0};
    point_tree_radius(&t, q, rr, rad_visit, &a);
    uint64_t bc = 0, bid = 0;
    for (int i = 0; i < NP; i++)
      if (v3_len2(v3_sub(pts[i], q)) < rr) { bc++; bid += (uint64_t)i; }
    if (bc != a.count || bid != a.id_sum) bad_rad++;
    /* the same in front of a plane through q */
    float eps = qi % 3 == 0 ? 0 : 1e-3f;
    rad_acc hsa = {0, 0, &t, 0};
    g_hs_q = q; g_hs_n = n; g_hs_eps = eps;
    point_tree_radius_halfspace(&t, q, rr, n, eps, hs_visit, &hsa);
    bc = 0; bid = 0;
    for (int i = 0; i < NP; i++) {
      vec3 v = v3_sub(pts[i], q);
      if (v3_len2(v) < rr && v3_dot(v, n) > eps) { bc++; bid += (uint64_t)i; }
    }
    /* the visitor gets the sphere's points of unpruned subtrees: count those in front */
    if (bc != hsa.count || bid != hsa.id_sum) bad_hs++;
  }
  free(bd);
  fprintf(stderr, "%d queries: %d k-nearest, %d radius and %d half-space radius mismatches\n", NQ, bad_knn, bad_rad, bad_hs);
  CHECK(bad_knn == 0 && bad_rad == 0 && bad_hs == 0, "mismatches");
  point_tree_free(&t);
  /* an empty tree answers nothing */
  CHECK(point_tree_build(&t, pts, 0) == 0 && point_tree_build_boxes(&t) == 0, "empty build");
  CHECK(point_tree_knn(&t, v3(0, 0, 0), 5, INFINITY, v3(0, 0, 1), 0, out) == 0, "empty knn");
  point_tree_free(&t);
  free(pts);
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"queries_match_brute_force", queries_match_brute_force}, {NULL, NULL}};
  return test_main(argc, argv, cases);
}
