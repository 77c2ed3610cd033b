/* light.h — owns light sampling for next-event estimation: the power-proportional light
 * selector (alias table) and, per light type (one switch), sampling an incident direction
 * at a reference point, the solid-angle density of that sampling, and emitted radiance.
 * Area lights sample the solid angle the triangle subtends uniformly (Arvo 1995), or,
 * when that is tiny or huge, the triangle uniformly by area with pdf_w = pdf_A * d^2 /
 * |cos theta_l|; light_pdf_area makes the same choice. */
#ifndef VALO_LIGHT_H
#define VALO_LIGHT_H
#include "scene/scene.h"
#include "core/alias.h"

/* Light selection for next-event estimation (and restir's candidates). By power (alias
 * table), except:
 *  - in scenes with at most LIGHT_LOCAL_MAX lights the choice is made per shading point:
 *    one-sided area lights the point is behind (or level with) get weight 0, the rest
 *    keep their power, so no sample is spent on a light that cannot reach the point;
 *  - above that count, with the light grid (LIGHT_SELECT_GRID, the default): the scene's
 *    bounds are cut into up to LIGHT_GRID_CELLS cells, and each cell holds a distribution
 *    over the lights with weight power / (pi max(d^2, r^2)) (d from the cell's centre to
 *    the light's, r the two radii: a bound on the irradiance the light can bring to the
 *    cell), 0 for one-sided lights the whole cell is behind; directional lights and the
 *    environment weigh power / (pi R^2) (R the scene's radius). A point picks from its
 *    cell's distribution with probability 1 - LIGHT_GRID_POWER, else by power, and the
 *    pmf is that mixture, so every light that can reach the point keeps a positive
 *    probability (unbiased whatever the bound misjudges).
 * Infinite lights (the environment, directional lights) are not ranked against the
 * others by power (pi^2 R^2 L for the environment, R the scene's radius, outweighs a lamp
 * that lights most of the scene): as pbrt-v4's BVH light sampler does, each of the n
 * infinite lights is picked with probability 1 / (n + 1) and the finite lights share the
 * rest (the infinite lights take it all when no finite light has power). On a floor lit by a constant sky and a
 * rectangle lamp (the hide scene of tests/data/mitsuba-xml without its mirror and ball)
 * this cut the relMSE at 64 spp (independent sampler) to 0.28x of the power rule's.
 * light_select_power, which photon and VPL tracing use, stays by power over all lights.
 * light_select and light_select_pmf make the same choice. */
#define LIGHT_LOCAL_MAX 64
#define LIGHT_GRID_CELLS 4096
#define LIGHT_GRID_POWER 0.2f
typedef enum light_select_mode { LIGHT_SELECT_GRID, LIGHT_SELECT_POWER } light_select_mode;
/* Above LIGHT_LOCAL_MAX lights, with emitting spheres sampled by their cones, the choice is
 * made between units: each such sphere's lights are one unit (grid weight: its power over
 * 4 pi max(d^2, r^2), the irradiance a Lambertian sphere can bring), every other light one
 * of its own. A unit of several lights then gives one of them by power, from where the
 * number fell within the unit's share (alias_sample_rest; pbrt's light sampler reuses it
 * so), and the light's pmf is the unit's times its power share. */
typedef struct light_sampler {
  alias_table table;    /* by power, over the units */
  int env_index; float *power; uint32_t n; int local;
  int sphere_cones;     /* emitting spheres sampled whole (light_sphere_at) */
  uint32_t nu;          /* units (n when each light is its own) */
  uint32_t *unit0;      /* unit u holds lights [unit0[u], unit0[u + 1]); NULL: each light its own */
  uint32_t *unit_of;    /* the unit of each light (with unit0) */
  float *upower;        /* each unit's power (with unit0) */
  double *power_cdf;    /* running sums of the lights' power (with unit0) */
  float *grid_cdf;      /* per cell, nu running sums normalised to 1 (cells with nothing: all 0) */
  int gdim[3];
  vec3 glo, ginv;       /* grid origin and cells per unit length */
  uint32_t ninf, *inf;  /* the infinite lights of positive power (none: NULL) */
  float p_inf;          /* their share of the choice */
  alias_table ftable;   /* with inf: the finite lights' table (units' power, infinite 0) */
  int has_finite;       /* with inf: ftable was built (some finite light has power) */
} light_sampler;

/* sphere_cones: sample emitting spheres by their cones (light_sphere_at). */
int light_sampler_init(light_sampler *ls, const scene *s, light_select_mode mode, int sphere_cones);
/* A light by power alone, wherever it is received (photon and VPL tracing); *pmf. */
uint32_t light_select_power(const light_sampler *ls, float u, float *pmf);
void light_sampler_free(light_sampler *ls);
/* Picks a light for shading point p with u in [0,1); returns its index and *pmf, or
 * UINT32_MAX when no light can reach p. */
uint32_t light_select(const light_sampler *ls, const scene *s, vec3 p, float u, float *pmf);
/* Several selections at one point: light_locate finds p's grid cell once, and
 * light_select_at then picks exactly as light_select(ls, s, p, u, pmf) would. */
typedef struct light_site { vec3 p; const float *row; } light_site;
light_site light_locate(const light_sampler *ls, vec3 p);
uint32_t light_select_at(const light_sampler *ls, const scene *s, const light_site *at, float u, float *pmf);
/* The probability light_select picks light li at p. */
float light_select_pmf(const light_sampler *ls, const scene *s, uint32_t li, vec3 p);
/* The probability light_select picks any of the lights [l0, l1) at p, when they are one
 * unit (an emitting sphere's lights); else 0. */
float light_range_pmf(const light_sampler *ls, uint32_t l0, uint32_t l1, vec3 p);

/* Emitting spheres (scene.spheres whose lights are [l0, l1)) are sampled whole where
 * they can be: when ls->sphere_cones is set, the sampler is not the local one and p lies
 * outside the sphere by more than LIGHT_SPHERE_MARGIN of its radius, next-event
 * estimation (direct.c) that picks any of its lights takes a direction uniformly in the
 * cone the sphere subtends from p instead, and the sphere's first triangle along it as
 * the light sample: the faces lie inside the sphere, so the cone holds every direction
 * that reaches them, and a direction that meets anything else first brings nothing. The
 * density of a direction is then light_range_pmf(l0, l1, p) * cone.pdf, for light
 * sampling and for the MIS weight of a BSDF-sampled hit alike. Mitsuba samples its
 * analytic spheres so (its sphere's sample_direction); for a small lamp seen from afar
 * area sampling spends half its samples on the far side and weighs the rest by cos. */
#define LIGHT_SPHERE_MARGIN 1e-3f
typedef struct light_cone {
  const sphere_shape *sp;
  vec3 axis;           /* unit, from p towards the centre */
  float one_minus_cos; /* 1 - cos of the cone's half-angle */
  float pdf;           /* 1 / (2 pi one_minus_cos), per steradian */
} light_cone;
/* 1 and *k when light li at p is sampled through its sphere's cone; else 0. */
int light_sphere_at(const light_sampler *ls, const scene *s, uint32_t li, vec3 p, light_cone *k);
/* light_select for next-event estimation: when the light picked is one of an emitting
 * sphere's that light_sphere_at samples by its cone at p, the light within the sphere is
 * not drawn: *k is filled, *pmf is the sphere's probability (light_range_pmf's) and the
 * sphere's first light is returned. Otherwise exactly light_select, with k->sp NULL. */
uint32_t light_select_cone(const light_sampler *ls, const scene *s, vec3 p, float u, float *pmf, light_cone *k);
/* A unit direction uniform in the cone (u1 in [0,1) from its axis outwards). */
vec3 light_cone_sample(const light_cone *k, float u1, float u2);

typedef struct light_li {
  vec3 wi;       /* unit direction from the reference point towards the light */
  float dist;    /* distance to the sampled point (INFINITY for directional/env) */
  vec3 p_light;  /* sampled point on the light (area/point/spot) */
  vec3 n_light;  /* its geometric normal (area) */
  rgb L;         /* incident radiance (area/env) or intensity/d^2 (delta lights) */
  float pdf;     /* solid-angle density (area/env), 1 for delta lights */
  int delta;
  int visible;   /* found as the first solid surface along a traced ray (an emitting
                    sphere's cone sample, direct.c): no shadow ray needed */
} light_li;

/* Samples light l as seen from p; returns 0 if it contributes nothing. */
int light_sample(const scene *s, const light *l, vec3 p, float u1, float u2, light_li *out);
/* Light l as seen from p through a point y it could have sampled (ReSTIR reuses samples
 * across shading points): area lights, y a point on the triangle; the environment, y a
 * direction; delta lights, y is ignored. Fills wi, dist, p_light, n_light and L as
 * light_sample does (pdf 0) and *g, the factor from y's own measure to solid angle at
 * p: |cos theta_l| / d^2 for area lights, 1 otherwise. Returns 0 when it sends nothing. */
int light_eval_point(const scene *s, const light *l, vec3 p, vec3 y, light_li *o, float *g);
/* Solid-angle density with which light_sample picks direction wi from p to point
 * p_light with normal n_light on area light l (env: the direction alone). */
float light_pdf_area(const light *l, vec3 p, vec3 p_light, vec3 n_light);
float light_pdf_env(const scene *s, const light *l, vec3 wi);
/* Radiance the environment sends along -wi (i.e. arriving from direction wi). */
rgb light_env_radiance(const scene *s, const light *l, vec3 wi);
/* Radiance an area light emits from its surface with normal ng towards direction w. */
static inline rgb light_area_emitted(const light *l, vec3 ng, vec3 w) {
  float c = v3_dot(ng, w);
  return (c > 0 || (l->two_sided && c < 0)) ? l->L : c3(0, 0, 0);
}
/* The same with the emitter's emission map (if any) applied at surface UV (u, v). */
rgb light_area_radiance(const scene *s, const light *l, vec3 ng, vec3 w, float u, float v);
/* The same for the area light of triangle tri (tri_light[tri] >= 0), read from the
 * triangle's material, whose emission, sidedness and emission map its light copies: a hit
 * on an emitter then needs no light record (one per emitting triangle: 20 480 on Veach's
 * MIS scene, 3 MB, where the materials are a few). */
rgb light_tri_radiance(const scene *s, uint32_t tri, vec3 ng, vec3 w, float u, float v);
/* Area lights that overlap in their plane (light.shares_plane, light_overlap.c): where
 * they overlap, the one first in the scene's order is the one seen, and the others emit
 * nothing there, for every ray (rounding, which would otherwise break the tie, breaks it
 * differently for a ray aimed at one and a ray that finds the nearest). So light sampling
 * gives nothing from a hidden point (light_sample, light_eval_point, light_sample_emit
 * return 0 or black there) and a hit on one takes the radiance and the pdf of the light
 * seen (light_hit). */
/* The light a ray that hits emitting triangle tri at p (normal ng, surface UV u, v)
 * sees, in *lid (-1: none), and its radiance towards w: light_tri_radiance, or where
 * tri's light is hidden at p, the light before it that covers p. */
rgb light_hit(const scene *s, uint32_t tri, vec3 p, vec3 ng, vec3 w, float u, float v, int32_t *lid);
float light_power(const scene *s, const light *l);

/* A ray of light leaving light l (photon and VPL tracing): origin, unit direction and
 * beta = Le cos / (pdf_position pdf_direction), the flux this one sample stands for.
 * Area lights: uniform point, cosine-weighted direction about the emitting side (a side
 * picked at random when two-sided); point: uniform sphere; spot: uniform cone to
 * cos_outer; directional and environment: a direction (the map's importance sampling)
 * and a uniform point on the disc of the scene's bounding-sphere radius across it.
 * u: four uniform numbers. Returns 0 when the sample carries nothing. */
typedef struct light_emit { vec3 o, d, n; rgb beta; } light_emit;
int light_sample_emit(const scene *s, const light *l, const float u[4], light_emit *out);
/* The same ray of light, its direction drawn uniformly in the cone that the sphere (c, r)
 * subtends from the point drawn (Jensen's projection maps: caustic photons aimed at the
 * specular objects), beta its flux for that density (zero where the light does not emit
 * that way). Area and point lights only, from outside the sphere: else 0 and nothing is
 * drawn (the caller falls back to light_sample_emit). */
int light_sample_emit_toward(const scene *s, const light *l, const float u[4], vec3 c, float r, light_emit *out);
#endif
