/* proximity.c — owns `proximity-ao`, the seed's own method (digest 003, "ambient
 * proximity occlusion"): points splatted evenly over every surface at spacing d, kept in
 * the shared point kd-tree with their normals; at the point x a camera ray sees, with
 * normal n faced to the viewer, every splatted point s within radius r in front of x
 * ((s - x).n > 0) adds darkness A D P, with A = cos(n, s - x), D = 1 - |s - x|^2 / r^2
 * and P = (1 + |n . n_s|) / 2 (the angle between the normals mapped into [0.5, 1]: a
 * surface seen face-on occludes twice what one seen edge-on does; points stand for both
 * sides, so the sign of n_s is not used). Each point's darkness is weighted by its share
 * of surface over the search disc, a / r^2 (a: its shape's area over the points placed
 * on it; the midpoint splitting makes the density a step function of d, so d^2 would
 * misjudge it by up to 2x), so the result does not depend on the spacing; the pixel is 1 - min(1, M K T) with strength M and K a constant
 * fitted once so that M = 1 matches ray-traced ao (ray length r) on CornellBox-Original's
 * mean at the default r (docs/integrators.md). Points are found by a radius search
 * restricted to the half-space in front of x over the point tree's box hierarchy, which
 * never visits the shaded surface's own (coplanar) points; each run of points it hands
 * over is tested and summed four at a time (SSE2; a scalar fallback sums the same lanes)
 * from arrays in tree order. Deterministic and noise-free: every sample per pixel only
 * moves the camera ray (antialiasing). d, r and M are parameters, per shape in a JSON
 * scene ("proximity": {"spacing", "radius", "strength"}); r and M are those of the shape
 * being shaded, d that of the shape splatted. */
#include "integrator/direct.h"
#include "integrator/ao.h"
#include "integrator/integrator.h"
#include "scene/splat.h"
#include "geometry/pointtree.h"
#include "core/error.h"
#include "core/threadpool.h"
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#define PROX_K 1.84f           /* fitted: see the comment at the top */
#define PROX_MAX_POINTS 50000000u

enum { P_SPACING, P_RADIUS, P_STRENGTH };
static const integrator_param prox_params[] = {
    {"spacing", IPARAM_FLOAT, 0, 0, 1e30, "distance between splatted points d in scene units; 0 = automatic, radius / 6"},
    {"radius", IPARAM_FLOAT, 0, 0, 1e30,
     "search radius r in scene units (like ao's ray length); 0 = automatic, 1/10 of the radius of the scene's bounding sphere"},
    {"strength", IPARAM_FLOAT, 1, 0, 1e6, "strength M multiplying the darkness (1: calibrated to match ao's mean)"},
    {NULL, IPARAM_FLOAT, 0, 0, 0, NULL}};

/* ---- the integrator ---- */
/* The points' data in tree order as separate arrays (x, y, z, normal x, y, z, area), each
 * padded by PROX_PAD zeros so that a run is read four at a time without a bounds test. */
#define PROX_PAD 3
enum { S_PX, S_PY, S_PZ, S_NX, S_NY, S_NZ, S_AREA, S_COUNT };
typedef struct prox_state { splat_points pts; point_tree tree; float *soa[S_COUNT]; float *block; } prox_state;

static void prox_destroy(void *st) {
  prox_state *ps = st;
  if (!ps) return;
  splat_free(&ps->pts);
  point_tree_free(&ps->tree);
  free(ps->block);
  free(ps);
}

static float prox_radius(const render_ctx *c) { return ao_ray_length(c->s, c->param[P_RADIUS]); }
static float prox_spacing(const render_ctx *c) {
  return c->param[P_SPACING] > 0 ? (float)c->param[P_SPACING] : prox_radius(c) / 6;
}

static valo_status prox_create(const render_ctx *c, void **out, valo_error *err) {
  prox_state *ps = calloc(1, sizeof *ps);
  if (!ps) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  float d = prox_spacing(c);
  if (splat_scene(c->s, d, PROX_MAX_POINTS, c->threads, &ps->pts)) {
    prox_destroy(ps);
    return err_set(err, VALO_ERR_INVALID, "proximity-ao: spacing %g gives more than %u points (or memory ran out): choose a larger spacing", d,
                   PROX_MAX_POINTS);
  }
  if (point_tree_build(&ps->tree, ps->pts.p, ps->pts.n_pts) || point_tree_build_boxes(&ps->tree)) { prox_destroy(ps); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  /* positions, normals and areas in tree order */
  size_t stride = (size_t)ps->tree.n + PROX_PAD;
  ps->block = calloc(stride * S_COUNT, sizeof(float));
  if (!ps->block) { prox_destroy(ps); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  for (int k = 0; k < S_COUNT; k++) ps->soa[k] = ps->block + k * stride;
  for (uint32_t i = 0; i < ps->tree.n; i++) {
    uint32_t id = ps->tree.id[i];
    vec3 p = ps->tree.p[i], n = ps->pts.n[id];
    ps->soa[S_PX][i] = p.x; ps->soa[S_PY][i] = p.y; ps->soa[S_PZ][i] = p.z;
    ps->soa[S_NX][i] = n.x; ps->soa[S_NY][i] = n.y; ps->soa[S_NZ][i] = n.z;
    ps->soa[S_AREA][i] = ps->pts.area[id];
  }
  *out = ps;
  return VALO_OK;
}

/* One query: T accumulates in four lanes (point i of a run goes to lane (i - lo) mod 4),
 * summed at the end; the same order for any thread count. */
typedef struct prox_q { const prox_state *ps; vec3 x, n; float r2, inv_r2, eps; float acc[4]; } prox_q;

#if defined(__SSE2__)
static void prox_run(void *user, uint32_t lo, uint32_t hi) {
  prox_q *q = user;
  float *const *a = q->ps->soa;
  const __m128 qx = _mm_set1_ps(q->x.x), qy = _mm_set1_ps(q->x.y), qz = _mm_set1_ps(q->x.z);
  const __m128 nx = _mm_set1_ps(q->n.x), ny = _mm_set1_ps(q->n.y), nz = _mm_set1_ps(q->n.z);
  const __m128 eps = _mm_set1_ps(q->eps), r2 = _mm_set1_ps(q->r2), inv_r2 = _mm_set1_ps(q->inv_r2);
  const __m128 one = _mm_set1_ps(1), half = _mm_set1_ps(0.5f), tiny = _mm_set1_ps(1e-30f);
  const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  const __m128i end = _mm_set1_epi32((int)hi), four = _mm_set1_epi32(4);
  __m128i idx = _mm_setr_epi32((int)lo, (int)lo + 1, (int)lo + 2, (int)lo + 3);
  __m128 acc = _mm_loadu_ps(q->acc);
  for (uint32_t i = lo; i < hi; i += 4, idx = _mm_add_epi32(idx, four)) {
    __m128 vx = _mm_sub_ps(_mm_loadu_ps(a[S_PX] + i), qx);
    __m128 vy = _mm_sub_ps(_mm_loadu_ps(a[S_PY] + i), qy);
    __m128 vz = _mm_sub_ps(_mm_loadu_ps(a[S_PZ] + i), qz);
    __m128 vn = _mm_add_ps(_mm_add_ps(_mm_mul_ps(vx, nx), _mm_mul_ps(vy, ny)), _mm_mul_ps(vz, nz));
    __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(vx, vx), _mm_mul_ps(vy, vy)), _mm_mul_ps(vz, vz));
    __m128 ok = _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(vn, eps), _mm_cmplt_ps(d2, r2)), _mm_castsi128_ps(_mm_cmplt_epi32(idx, end)));
    __m128 A = _mm_div_ps(vn, _mm_sqrt_ps(_mm_max_ps(d2, tiny)));
    __m128 D = _mm_sub_ps(one, _mm_mul_ps(d2, inv_r2));
    __m128 cn = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_loadu_ps(a[S_NX] + i), nx), _mm_mul_ps(_mm_loadu_ps(a[S_NY] + i), ny)),
                           _mm_mul_ps(_mm_loadu_ps(a[S_NZ] + i), nz));
    __m128 P = _mm_add_ps(half, _mm_mul_ps(half, _mm_and_ps(cn, abs_mask)));
    __m128 c = _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(A, D), P), _mm_loadu_ps(a[S_AREA] + i));
    acc = _mm_add_ps(acc, _mm_and_ps(ok, c));
  }
  _mm_storeu_ps(q->acc, acc);
}
#else
/* the same arithmetic, lane by lane */
static void prox_run(void *user, uint32_t lo, uint32_t hi) {
  prox_q *q = user;
  float *const *a = q->ps->soa;
  for (uint32_t i = lo; i < hi; i++) {
    float vx = a[S_PX][i] - q->x.x, vy = a[S_PY][i] - q->x.y, vz = a[S_PZ][i] - q->x.z;
    float vn = vx * q->n.x + vy * q->n.y + vz * q->n.z, d2 = vx * vx + vy * vy + vz * vz;
    if (!(vn > q->eps && d2 < q->r2)) continue;
    float A = vn / sqrtf(d2 > 1e-30f ? d2 : 1e-30f), D = 1 - d2 * q->inv_r2;
    float cn = a[S_NX][i] * q->n.x + a[S_NY][i] * q->n.y + a[S_NZ][i] * q->n.z;
    float P = 0.5f + 0.5f * fabsf(cn);
    q->acc[(i - lo) & 3] += A * D * P * a[S_AREA][i];
  }
}
#endif

/* Darkness M K T at x with normal n on triangle tri. */
static float prox_occlusion(const render_ctx *c, vec3 x, vec3 n, uint32_t tri) {
  const prox_state *ps = c->state;
  const shape_ao *sa = scene_shape_ao(c->s, tri);
  float r = sa && sa->radius > 0 ? sa->radius : prox_radius(c);
  float M = sa && sa->strength >= 0 ? sa->strength : (float)c->param[P_STRENGTH];
  prox_q q = {ps, x, n, r * r, 1 / (r * r), 1e-3f * r, {0, 0, 0, 0}};
  point_tree_halfspace_runs(&ps->tree, x, r * r, n, q.eps, prox_run, &q);
  float T = ((q.acc[0] + q.acc[1]) + (q.acc[2] + q.acc[3])) * q.inv_r2;
  return M * PROX_K * T;
}

static rgb prox_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) {
  (void)smp;
  hit h;
  if (!ctx_intersect(c, &r, &h, ts)) return c3(0, 0, 0);
  isect it;
  isect_from_hit(c->s, &r, &h, &it);
  /* the geometric normal: points stand for geometry, and a normal or bump map's shading
   * normal would tilt the surface's own points in front of it */
  vec3 n = v3_faceforward(it.ng, v3_neg(r.d));
  float v = 1 - prox_occlusion(c, it.p, n, it.tri);
  v = v > 0 ? v : 0;
  return c3(v, v, v);
}

const integrator_ops integrator_proximity_ao = {
    .name = "proximity-ao",
    .description = "ambient proximity occlusion (digest 003): splatted points and a fixed-radius kd-tree search; noise-free",
    .kind = INTEGRATOR_RAY,
    .params = prox_params,
    .li = prox_li,
    .create = prox_create,
    .destroy = prox_destroy,
};
