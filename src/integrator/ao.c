/* ao.c — owns the `ao` integrator: ray-traced ambient occlusion (digest 003; Zhukov 1998,
 * Landis 2002). At the surface a camera ray sees, one cosine-weighted ray per sample
 * (Owen-scrambled Sobol, so --spp 256 is the seed's 256-ray reference) up to a maximum
 * distance; the pixel is the unoccluded fraction (1 open, 0 closed), camera rays that
 * escape give 0. The same estimator, ao_sample() below, makes the ao and bent-
 * normal AOVs beside any integrator (-o ao:FILE, -o bent:FILE). */
#include "core/streams.h"
#include "integrator/ao.h"
#include "core/sampling.h"
#include "integrator/integrator.h"

static const integrator_param ao_params[] = {
    {"distance", IPARAM_FLOAT, 0, 0, 1e30,
     "length of the occlusion rays in scene units; 0 = automatic, 1/10 of the radius of the scene's bounding sphere"},
    {"shading_normals", IPARAM_INT, 1, 0, 1,
     "1: rays about the shading normal (normal and bump maps show); 0: about the geometric normal (as proximity-ao sees surfaces)"},
    {NULL, IPARAM_FLOAT, 0, 0, 0, NULL}};

static rgb ao_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) {
  hit h;
  if (!ctx_intersect(c, &r, &h, ts)) return c3(0, 0, 0);
  isect it;
  isect_from_hit(c->s, &r, &h, &it);
  vec3 n = v3_faceforward(c->param[1] > 0 ? it.ns : it.ng, v3_neg(r.d));
  vec3 dir;
  sampler_set_dim(smp, SDIM_AO);
  float v = (float)ao_sample(c, &it, n, ao_ray_length(c->s, c->param[0]), smp, ts, &dir);
  return c3(v, v, v);
}

const integrator_ops integrator_ao = {
    .name = "ao",
    .description = "ray-traced ambient occlusion: one cosine-weighted ray per sample up to a distance; the unoccluded fraction",
    .kind = INTEGRATOR_RAY,
    .params = ao_params,
    .li = ao_li,
};

int ao_sample(const render_ctx *c, const isect *it, vec3 n, float dist, sampler *smp, thread_stats *ts, vec3 *dir) {
  float u1, u2;
  sampler_2d(smp, &u1, &u2);
  frame f = frame_from_n(n);
  vec3 d = frame_to_world(&f, sample_cosine_hemisphere(u1, u2));
  /* a direction under the geometric surface is blocked by it */
  if (v3_dot(d, it->ng) * v3_dot(n, it->ng) <= 0) return 0;
  ray r = spawn_ray(it, d);
  r.tmax = dist;
  if (c->s->has_media) {
    /* null surfaces (media's boundaries) occlude nothing */
    hit h;
    isect solid;
    float before;
    if (ctx_intersect_solid(c, r, &h, &solid, &before, ts)) return 0;
  } else {
    ts->rays++;
    if (accel_occluded(c->acc, &r)) return 0;
  }
  *dir = d;
  return 1;
}

float ao_ray_length(const scene *s, double d) { return d > 0 ? (float)d : 0.1f * s->radius; }

