/* light_overlap.c — owns finding area lights that overlap another in their plane
 * (light.shares_plane, and each one's list of the others, scene.light_ov). Two emitting
 * triangles in one plane whose interiors overlap would be a tie for a ray that meets them
 * there, broken by rounding one way for a shadow ray aimed at one and another for a ray
 * that finds the nearest; light.h defines it instead (the first in the scene's order is
 * seen there). Triangles that only share an edge or a corner do not overlap. Found by a
 * sweep over the lights' boxes along x, coplanarity, then separating axes in the plane. */
#include "scene/scene.h"
#include "core/grow.h"
#include <string.h>
#include <math.h>
#include <stdlib.h>

typedef struct ov_item { float lo; uint32_t li; } ov_item;
static int ov_cmp(const void *a, const void *b) {
  float x = ((const ov_item *)a)->lo, y = ((const ov_item *)b)->lo;
  return (x > y) - (x < y);
}

/* Interiors of two triangles in one plane (projected to 2D) overlap: no edge normal of
 * either separates them by more than eps. */
static int tri2_overlap(const float a[3][2], const float b[3][2], float eps) {
  const float(*t[2])[2] = {a, b};
  for (int s = 0; s < 2; s++)
    for (int e = 0; e < 3; e++) {
      const float *p = t[s][e], *q = t[s][(e + 1) % 3];
      float nx = q[1] - p[1], ny = p[0] - q[0];
      float len = sqrtf(nx * nx + ny * ny);
      if (!(len > 0)) return 0;
      nx /= len; ny /= len;
      float lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
      for (int k = 0; k < 2; k++)
        for (int v = 0; v < 3; v++) {
          float d = t[k][v][0] * nx + t[k][v][1] * ny;
          lo[k] = fminf(lo[k], d); hi[k] = fmaxf(hi[k], d);
        }
      if (hi[0] <= lo[1] + eps || hi[1] <= lo[0] + eps) return 0;
    }
  return 1;
}

static int lights_overlap(const light *a, const light *b, float tol) {
  if (fabsf(v3_dot(a->n, b->n)) < 1 - 1e-5f) return 0;
  for (int k = 0; k < 3; k++)
    if (fabsf(v3_dot(a->n, v3_sub(b->v[k], a->v[0]))) > tol) return 0;
  /* 2D coordinates in a's plane */
  vec3 u = v3_norm(v3_sub(a->v[1], a->v[0])), w = v3_cross(a->n, u);
  float pa[3][2], pb[3][2];
  for (int k = 0; k < 3; k++) {
    vec3 da = v3_sub(a->v[k], a->v[0]), db = v3_sub(b->v[k], a->v[0]);
    pa[k][0] = v3_dot(da, u); pa[k][1] = v3_dot(da, w);
    pb[k][0] = v3_dot(db, u); pb[k][1] = v3_dot(db, w);
  }
  return tri2_overlap(pa, pb, tol);
}

/* A bound on the pairs tested, so that a pathological emitting mesh (every triangle's box
 * spanning the scene) cannot stall loading: past it the rest stay unflagged. */
#define OV_MAX_PAIRS 50000000ull

int scene_flag_light_overlaps(scene *s) {
  free(s->light_ov0); free(s->light_ov);
  s->light_ov0 = s->light_ov = NULL;
  uint32_t n = 0;
  for (uint32_t i = 0; i < s->nlights; i++) {
    s->lights[i].shares_plane = 0;
    n += s->lights[i].type == LIGHT_AREA;
  }
  if (n < 2) return 0;
  ov_item *it = malloc((size_t)n * sizeof *it);
  if (!it) return -1;
  n = 0;
  for (uint32_t i = 0; i < s->nlights; i++) {
    const light *l = &s->lights[i];
    if (l->type != LIGHT_AREA) continue;
    it[n].lo = fminf(fminf(l->v[0].x, l->v[1].x), l->v[2].x);
    it[n++].li = i;
  }
  qsort(it, n, sizeof *it, ov_cmp);
  /* positions are compared to a few ulps of the scene's largest coordinate */
  float scale = fmaxf(fmaxf(fabsf(s->bounds.lo.x), fabsf(s->bounds.hi.x)),
                      fmaxf(fmaxf(fabsf(s->bounds.lo.y), fabsf(s->bounds.hi.y)), fmaxf(fabsf(s->bounds.lo.z), fabsf(s->bounds.hi.z))));
  float tol = 1e-6f * fmaxf(scale, 1e-6f);
  uint64_t pairs = 0;
  uint32_t *pr = NULL, npr = 0; /* the overlapping pairs found */
  int oom = 0;
  for (uint32_t i = 0; i < n && pairs < OV_MAX_PAIRS; i++) {
    light *a = &s->lights[it[i].li];
    bbox ba = bbox_add(bbox_add(bbox_add(bbox_empty(), a->v[0]), a->v[1]), a->v[2]);
    for (uint32_t j = i + 1; j < n && it[j].lo <= ba.hi.x + tol; j++, pairs++) {
      light *b = &s->lights[it[j].li];
      bbox bb = bbox_add(bbox_add(bbox_add(bbox_empty(), b->v[0]), b->v[1]), b->v[2]);
      if (bb.lo.y > ba.hi.y + tol || ba.lo.y > bb.hi.y + tol || bb.lo.z > ba.hi.z + tol || ba.lo.z > bb.hi.z + tol) continue;
      if (!lights_overlap(a, b, tol)) continue;
      a->shares_plane = b->shares_plane = 1;
      uint32_t *np = grow_for(pr, npr, 2 * sizeof *pr);
      if (!np) { oom = 1; break; }
      pr = np;
      pr[2 * npr] = it[i].li;
      pr[2 * npr++ + 1] = it[j].li;
    }
  }
  free(it);
  if (!oom && npr) { /* each light's partners, both ways */
    s->light_ov0 = calloc((size_t)s->nlights + 1, sizeof *s->light_ov0);
    s->light_ov = malloc(2 * (size_t)npr * sizeof *s->light_ov);
    if (s->light_ov0 && s->light_ov) {
      for (uint32_t k = 0; k < 2 * npr; k++) s->light_ov0[pr[k] + 1]++;
      for (uint32_t i = 0; i < s->nlights; i++) s->light_ov0[i + 1] += s->light_ov0[i];
      uint32_t *fill = malloc((size_t)s->nlights * sizeof *fill);
      if (fill) {
        memcpy(fill, s->light_ov0, (size_t)s->nlights * sizeof *fill);
        for (uint32_t k = 0; k < 2 * npr; k++) s->light_ov[fill[pr[k]]++] = pr[k ^ 1];
        free(fill);
      } else oom = 1;
    } else oom = 1;
  }
  free(pr);
  if (oom) {
    free(s->light_ov0); free(s->light_ov);
    s->light_ov0 = s->light_ov = NULL;
    for (uint32_t i = 0; i < s->nlights; i++) s->lights[i].shares_plane = 0;
    return -1;
  }
  return 0;
}
