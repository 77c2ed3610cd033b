/* ao.h — owns ambient-occlusion rays (digest 003): the ao integrator's and the ao AOV's. */
#ifndef VALO_AO_H
#define VALO_AO_H
#include "integrator/direct.h"

/* Ambient occlusion (digest 003, ao.c): one cosine-weighted ray about the normal n
 * (faced to the viewer) from it, up to length dist. Returns 1 when it escapes (the
 * direction is then *dir), 0 when something is within dist (null surfaces, media's
 * boundaries, are not). */
int ao_sample(const render_ctx *c, const isect *it, vec3 n, float dist, sampler *smp, thread_stats *ts, vec3 *dir);
/* The ao ray length for parameter value d: d itself when > 0, else (automatic) a tenth
 * of the radius of the scene's bounding sphere (contact shadows and corners; the whole
 * radius would leave an interior black). */
float ao_ray_length(const scene *s, double d);
#endif
