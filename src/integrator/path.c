/* path.c — owns the `path` integrator: unidirectional path tracing with next-event
 * estimation and multiple importance sampling (power heuristic, Veach 1997) between light
 * and BSDF sampling, delta lights and specular lobes handled without MIS, and unbiased
 * Russian roulette (digest 000: divide by the continuation probability). Emission found
 * by BSDF-sampled rays is MIS-weighted against the NEE that could have found it, so
 * nothing is counted twice. Scenes with participating media or null surfaces take the
 * walk of path_media.c. */
#include "integrator/path_common.h"
#include "integrator/integrator.h"
#include "core/sampling.h"

rgb path_radiance(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, int count_first_emission) {
  const scene *s = c->s;
  rgb L = c3(0, 0, 0), beta = c3(1, 1, 1);
  path_state st = path_state_start(r.o); /* camera rays count emission fully */
  int max_depth = c->max_depth >= 0 ? c->max_depth : PATH_HARD_CAP;
  for (int depth = 0;; depth++) {
    isect it;
    rgb Le;
    float w;
    int surface = path_trace_vertex(c, &r, &st, ts, &it, &Le, &w);
    if (!c3_black(Le) && (depth > 0 || count_first_emission)) L = c3_add(L, c3_scale(c3_mul(beta, Le), w));
    if (!surface || depth >= max_depth) break;
    vec3 wo = v3_neg(r.d);

    bsdf b2, b = bsdf_at_blend(s, &it, &b2); /* a blend: both its BSDFs */
    frame fr = shading_frame(&it, &b, wo); /* opaque surfaces are two-sided */
    sampler_set_dim(smp, sdim_bounce(depth, SDIM_LIGHT_PICK));
    if (bsdf_has_smooth(&b)) L = c3_add(L, c3_mul(beta, estimate_direct(c, &it, &b, &fr, wo, smp, ts)));

    rgb weight;
    sampler_set_dim(smp, sdim_bounce(depth, SDIM_LOBE));
    if (!path_continue(&it, &b, &fr, wo, smp, ts, &st, &weight, &r)) break;
    beta = c3_mul(beta, weight);
    if (!path_survive(&st, &beta, depth, c->rr_depth, smp)) break;
  }
  return L;
}

static rgb path_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) {
  int first = !c->hide_emitters;
  return c->s->has_media ? path_radiance_media(c, r, smp, ts, first) : path_radiance(c, r, smp, ts, first);
}

const integrator_ops integrator_path = {
    .name = "path",
    .description = "unidirectional path tracing with next-event estimation, MIS and Russian roulette",
    .kind = INTEGRATOR_RAY,
    .li = path_li,
};
