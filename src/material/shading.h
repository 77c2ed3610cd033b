/* shading.h — owns surface interactions: the hit point with its error bound, geometric
 * and shading normals (interpolated, normal-mapped, bump-mapped), UVs and material; the
 * BSDF there with the material's texture maps applied (pbrt's Material::GetBSDF);
 * the shading frame; and rays spawned off the surface with robust offsets. */
#ifndef VALO_SHADING_H
#define VALO_SHADING_H
#include "material/bsdf.h"
#include "geometry/accel.h"
#include "geometry/offset.h"
#include "scene/scene.h"

typedef struct isect {
  vec3 p, perr;       /* point and its floating-point error bound */
  vec3 ng;            /* unit geometric normal (counter-clockwise winding side) */
  vec3 ns;            /* unit shading normal (interpolated, or ng) */
  float u, v;
  float b1, b2;       /* the hit's barycentrics in triangle tri (vertex colours) */
  uint32_t tri;
  const material *m;
  const material *blend_a, *blend_b; /* a weighted blend's two materials (neither a blend), else NULL; */
  float blend_w;      /* blend_b's weight there (m is the one picked, as every hit has) */
  vec3 dpdu;          /* an anisotropic material's u direction at the hit (shading_frame's s) */
  int mapped;         /* ns is a normal or bump map's under Mitsuba's conventions, and */
  vec3 n0;            /* the surface's own (interpolated) shading normal */
} isect;

void isect_from_hit(const scene *s, const ray *r, const hit *h, isect *it);
/* The BSDF at it, with the material's texture maps applied at its UV. */
bsdf bsdf_at(const scene *s, const isect *it);
/* The same, except where it is a weighted blend of two materials that both transmit or
 * both do not: then the blend of both (bsdf.mix points to *second, which must outlive
 * the result), which path's next-event estimation evaluates whole. */
bsdf bsdf_at_blend(const scene *s, const isect *it, bsdf *second);
/* 1 when triangle t's surface has a non-delta lobe whichever material a blend on it picks
 * (light paths store photons there whatever their own pick was). */
int surface_has_smooth(const scene *s, uint32_t t);
static inline vec3 offset_origin_isect(const isect *it, vec3 d) { return offset_origin(it->p, it->perr, it->ng, d); }
/* Shading frame at it for viewer direction wo, faced for opaque BSDFs (geometric normal
 * too); returns the frame and updates it->ng; gives b the surface's own normal in the
 * frame when the frame's is a mapped one (bsdf.mapped). */
frame shading_frame(isect *it, bsdf *b, vec3 wo);
/* A ray leaving it in direction d, from an origin offset past its error bound. */
static inline ray spawn_ray(const isect *it, vec3 d) {
  ray r;
  r.o = offset_origin_isect(it, d);
  r.d = d;
  r.tmax = INFINITY;
  return r;
}

#endif
