/* lightpath.h — light paths for the integrators that shoot them before the camera rays
 * (photon mapping, instant radiosity): paths leave the lights in proportion to power,
 * driven by an Owen-scrambled Sobol sequence over the path index, and are carried on by
 * BSDF sampling in adjoint form with Russian roulette; at every surface with a non-delta
 * lobe the caller's visit function may store a record. Paths are shot in fixed chunks,
 * each chunk's records concatenated in chunk order: the same set for any thread count;
 * either in rounds until `target` records are stored (or 64x target paths were tried:
 * photon maps), or exactly a given number of paths (virtual point lights). */
#ifndef VALO_LIGHTPATH_H
#define VALO_LIGHTPATH_H
#include "integrator/integrator.h"

typedef struct lp_vertex {
  const isect *it;
  const bsdf *b;
  const frame *fr;     /* shading frame faced towards where the path came from */
  vec3 d;              /* direction of travel arriving here */
  rgb power;           /* flux the path carries here, before division by paths emitted */
  int depth;           /* 0: the first surface after the light */
  int specular_path;   /* every earlier vertex was a delta bounce */
} lp_vertex;

/* Writes a record for v into rec (rec_size bytes) and returns 1, or returns 0. */
typedef int (*lp_visit_fn)(void *user, const lp_vertex *v, void *rec);

typedef struct lp_set { unsigned char *rec; uint32_t n; uint64_t emitted; } lp_set;

/* Shoots paths keyed by `key` until target records are stored. only_specular: end a path
 * after its first non-delta bounce (caustic paths). The caller divides powers by
 * out->emitted. out->rec is malloc'd (free it). */
/* aim (only_specular paths, or NULL): a sphere around every surface with a delta lobe;
 * area and point lights then emit only into the cone it subtends (light_sample_emit_toward):
 * a path that misses it could not be L S+ D, so the records' estimate is the same. */
typedef struct lp_aim { vec3 c; float r; } lp_aim;
valo_status lightpath_shoot(const render_ctx *c, uint64_t key, uint64_t target, size_t rec_size, int only_specular, const lp_aim *aim,
                            lp_visit_fn visit, void *user, lp_set *out, valo_error *err);
/* Shoots exactly npaths paths (all their records kept): for estimators that must stay
 * unbiased, where a stopping rule on the records stored would not. */
valo_status lightpath_shoot_paths(const render_ctx *c, uint64_t key, uint64_t npaths, size_t rec_size, lp_visit_fn visit, void *user,
                                  lp_set *out, valo_error *err);
#endif
