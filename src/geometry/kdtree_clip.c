/* kdtree_clip.c — owns clipping a straddling triangle to a kd-tree cell and cutting it
 * at the split plane (kd_clip_split, used by both build phases: kdtree_top.c,
 * kdtree_build.c): the "perfect splits" of Wald & Havran, with bounds that contain the
 * true clipped polygon whatever the rounding, so no hit is lost to a cell. */
#include "geometry/kdtree_internal.h"
#include <math.h>
#include <string.h>

/* A float at or below x (at or above with up set), one ulp further out when x came from
 * interpolation: the clipped polygon's bounds must contain the true polygon, since a
 * triangle nearly in an axis plane (a wall at x = -5 whose vertices round to x values an
 * ulp or two apart) covers a large area within one ulp of x. Rounding them to nearest
 * dropped such walls from cells they reach (veach-mis' back wall; test_kdtree
 * camera_rays). */
static float round_out(double x, int exact, int up) {
  float f = (float)x;
  if (up) { if ((double)f < x || !exact) f = next_float_up(f); }
  else if ((double)f > x || !exact) f = next_float_down(f);
  return f;
}

/* A polygon being clipped, in double: a vertex's coordinate is exact (its bit set) when
 * it is an input vertex's, the clipping plane's, or shared by both ends of the clipped
 * edge. */
typedef struct clip_poly { double p[12][3]; uint8_t exact[12]; int n; } clip_poly;

/* Keeps the part of a with sgn*(x[axis] - plane) >= 0, into o (o != a). */
static void clip_plane(const clip_poly *a, int axis, double plane, double sgn, clip_poly *o) {
  int m = 0;
  for (int i = 0; i < a->n; i++) {
    int ic = (i + 1) % a->n;
    const double *x = a->p[i], *c = a->p[ic];
    double da = sgn * (x[axis] - plane), dc = sgn * (c[axis] - plane);
    if (da >= 0 && m < 12) { memcpy(o->p[m], x, sizeof(double) * 3); o->exact[m++] = a->exact[i]; }
    if ((da >= 0) != (dc >= 0) && m < 12) {
      double t = da / (da - dc);
      uint8_t ex = (uint8_t)(1u << axis);
      for (int k = 0; k < 3; k++) {
        o->p[m][k] = x[k] + t * (c[k] - x[k]);
        if (x[k] == c[k] && (a->exact[i] & a->exact[ic] & (1u << k))) ex |= (uint8_t)(1u << k);
      }
      o->p[m][axis] = plane;
      o->exact[m] = ex;
      m++;
    }
  }
  o->n = m;
}

/* Whether every vertex of a lies on the kept side of the plane (most do: nothing to clip). */
static int clip_inside(const clip_poly *a, int axis, double plane, double sgn) {
  for (int i = 0; i < a->n; i++) if (!(sgn * (a->p[i][axis] - plane) >= 0)) return 0;
  return 1;
}

/* Clips buf[0] to box's six planes, through buf[1]; returns the buffer holding the result. */
static const clip_poly *clip_box(clip_poly buf[2], bbox box) {
  int cur = 0;
  for (int axis = 0; axis < 3; axis++)
    for (int sidei = 0; sidei < 2 && buf[cur].n > 0; sidei++) {
      double plane = sidei == 0 ? v3_get(box.lo, axis) : v3_get(box.hi, axis), sgn = sidei == 0 ? 1.0 : -1.0;
      if (clip_inside(&buf[cur], axis, plane, sgn)) continue;
      clip_plane(&buf[cur], axis, plane, sgn, &buf[1 - cur]);
      cur = 1 - cur;
    }
  return &buf[cur];
}

static void clip_start(const float *v, clip_poly *a) {
  a->n = 3;
  for (int i = 0; i < 3; i++) {
    a->exact[i] = 7;
    for (int k = 0; k < 3; k++) a->p[i][k] = v[3 * i + k];
  }
}

/* The extremes of a set of polygon vertices, kept apart for exact and inexact
 * coordinates: round_out is monotonic for a given exactness, so only they are rounded. */
typedef struct clip_ext { double mn[2][3], mx[2][3]; uint8_t any[2][3]; } clip_ext;

static void ext_add(clip_ext *e, const double *x, uint8_t exact) {
  for (int k = 0; k < 3; k++) {
    int ex = (exact >> k) & 1;
    if (!e->any[ex][k]) { e->mn[ex][k] = e->mx[ex][k] = x[k]; e->any[ex][k] = 1; }
    e->mn[ex][k] = x[k] < e->mn[ex][k] ? x[k] : e->mn[ex][k];
    e->mx[ex][k] = x[k] > e->mx[ex][k] ? x[k] : e->mx[ex][k];
  }
}

/* Conservative float bounds of the vertices in e, limited to box; 0 when empty. */
static int ext_bounds(const clip_ext *e, bbox box, bbox *out) {
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  int any = 0;
  for (int ex = 0; ex < 2; ex++)
    for (int k = 0; k < 3; k++) {
      if (!e->any[ex][k]) continue;
      any = 1;
      float l = round_out(e->mn[ex][k], ex, 0), h = round_out(e->mx[ex][k], ex, 1);
      lo[k] = l < lo[k] ? l : lo[k];
      hi[k] = h > hi[k] ? h : hi[k];
    }
  if (!any) return 0;
  bbox r = {v3(lo[0], lo[1], lo[2]), v3(hi[0], hi[1], hi[2])};
  r.lo = v3_max(r.lo, box.lo);
  r.hi = v3_min(r.hi, box.hi);
  if (r.lo.x > r.hi.x || r.lo.y > r.hi.y || r.lo.z > r.hi.z) return 0;
  *out = r;
  return 1;
}

/* A triangle that straddles the plane axis = pos inside box: clipped to box once, then
 * cut by the plane; the bounds of the parts below and above (lbox and rbox, box's two
 * halves) in *l and *r. The cut is clip_plane's arithmetic for each side, with an edge's
 * crossing point computed once for both (it is the same number from either side).
 * Returns a mask: 1 when the part below is not empty, 2 above. */
int kd_clip_split(const float *v, bbox box, int axis, float pos, bbox lbox, bbox rbox, bbox *l, bbox *r) {
  clip_poly buf[2];
  clip_start(v, &buf[0]);
  const clip_poly *c = clip_box(buf, box);
  if (c->n == 0) return 0;
  clip_ext el, er;
  memset(el.any, 0, sizeof el.any);
  memset(er.any, 0, sizeof er.any);
  for (int i = 0; i < c->n; i++) {
    int ic = (i + 1) % c->n;
    const double *x = c->p[i], *y = c->p[ic];
    double da = -(x[axis] - pos), dc = -(y[axis] - pos); /* below: da >= 0; above: -da >= 0 */
    int in_l = da >= 0, in_r = -da >= 0, cross_l = in_l != (dc >= 0), cross_r = in_r != (-dc >= 0);
    if (in_l) ext_add(&el, x, c->exact[i]);
    if (in_r) ext_add(&er, x, c->exact[i]);
    if (cross_l || cross_r) {
      double t = da / (da - dc), q[3];
      uint8_t ex = (uint8_t)(1u << axis);
      for (int k = 0; k < 3; k++) {
        q[k] = x[k] + t * (y[k] - x[k]);
        if (x[k] == y[k] && (c->exact[i] & c->exact[ic] & (1u << k))) ex |= (uint8_t)(1u << k);
      }
      q[axis] = pos;
      if (cross_l) ext_add(&el, q, ex);
      if (cross_r) ext_add(&er, q, ex);
    }
  }
  return ext_bounds(&el, lbox, l) | ext_bounds(&er, rbox, r) << 1;
}
