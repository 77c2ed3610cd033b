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
 * restricted to the half-space in front of x, which never visits the shaded surface's
 * own (coplanar) points. Deterministic and noise-free: every sample per pixel only
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
typedef struct prox_state { splat_points pts; point_tree tree; vec3 *n; float *area; } prox_state;

static void prox_destroy(void *st) {
  prox_state *ps = st;
  if (!ps) return;
  splat_free(&ps->pts);
  point_tree_free(&ps->tree);
  free(ps->n); free(ps->area);
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
  if (point_tree_build(&ps->tree, ps->pts.p, ps->pts.n_pts)) { prox_destroy(ps); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  /* normals and areas in tree order, beside the positions */
  if (point_tree_gather(&ps->tree, ps->pts.n, sizeof *ps->n, (void **)&ps->n) ||
      point_tree_gather(&ps->tree, ps->pts.area, sizeof *ps->area, (void **)&ps->area)) {
    prox_destroy(ps);
    return err_set(err, VALO_ERR_NOMEM, "out of memory");
  }
  *out = ps;
  return VALO_OK;
}

typedef struct prox_q { const prox_state *ps; vec3 x, n; float inv_r2, eps, T; } prox_q;
static void prox_visit(void *user, uint32_t i, float d2) {
  prox_q *q = user;
  vec3 v = v3_sub(q->ps->tree.p[i], q->x);
  float vn = v3_dot(v, q->n);
  if (!(vn > q->eps)) return;
  float A = vn / sqrtf(d2);
  float D = 1 - d2 * q->inv_r2;
  float P = 0.5f + 0.5f * fabsf(v3_dot(q->n, q->ps->n[i]));
  q->T += A * D * P * q->ps->area[i] * q->inv_r2;
}

/* Darkness M K T at x with normal n on triangle tri. */
static float prox_occlusion(const render_ctx *c, vec3 x, vec3 n, uint32_t tri) {
  const prox_state *ps = c->state;
  const shape_ao *sa = scene_shape_ao(c->s, tri);
  float r = sa && sa->radius > 0 ? sa->radius : prox_radius(c);
  float M = sa && sa->strength >= 0 ? sa->strength : (float)c->param[P_STRENGTH];
  prox_q q = {ps, x, n, 1 / (r * r), 1e-3f * r, 0};
  point_tree_radius_halfspace(&ps->tree, x, r * r, n, q.eps, prox_visit, &q);
  return M * PROX_K * q.T;
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
