/* splat.h — owns splatting points evenly over the scene's surfaces (digest 003, "ambient
 * proximity occlusion": proximity-ao's points; its tests and benchmark read them too).
 * Geometry over the scene model, so it sits in the model's module (a module below it
 * could not read the scene's per-shape settings). */
#ifndef VALO_SPLAT_H
#define VALO_SPLAT_H
#include "scene/scene.h"

typedef struct splat_points {
  vec3 *p, *n;      /* position and unit geometric normal (points stand for both sides) */
  float *spacing;   /* d of the shape the point came from */
  float *area;      /* its share of surface: the area of its shape (or of all shapes
                       without settings) over the points placed there */
  uint32_t n_pts, cap;
  float max_edge_ratio;  /* longest edge of a final (unsplit) triangle over its 2d: < 1 */
} splat_points;

/* Places points at spacing d(tri) on every triangle (deterministically, in triangle
 * order, whatever the thread count): each vertex, then the midpoint of the longest edge while it is longer than 2d
 * (splitting the triangle there), then the centroid of each final triangle; a point
 * closer than d/2 to one already placed is skipped, so none is placed twice on a shared
 * edge. d(tri) is the shape's "proximity" spacing or default_spacing. Returns 0, or -1
 * (out of memory, or more than max_points points: spacing too fine). */
int splat_scene(const scene *s, float default_spacing, uint32_t max_points, int threads, splat_points *out);
void splat_free(splat_points *sp);
#endif
