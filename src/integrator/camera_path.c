/* camera_path.c — see camera_path.h. */
#include "integrator/path_common.h"
#include "integrator/camera_path.h"
#include "core/sampling.h"

int delta_chain_vertex(const render_ctx *c, const ray *r, rgb beta, int depth, int max_depth, thread_stats *ts, rgb *L, isect *it, bsdf *b,
                       frame *fr, vec3 *wo) {
  rgb Le;
  float w;
  path_state st0 = path_state_start(r->o); /* emission along a delta chain counts fully */
  int surface = path_trace_vertex(c, r, &st0, ts, it, &Le, &w);
  *L = c3_add(*L, c3_mul(beta, Le));
  if (!surface || depth >= max_depth) return 0;
  *wo = v3_neg(r->d);
  *b = bsdf_at(c->s, it);
  *fr = shading_frame(it, b, *wo);
  return 1;
}

int delta_chain_continue(const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp, thread_stats *ts, rgb *beta, ray *r) {
  path_state st = path_state_start(r->o);
  rgb wgt;
  if (!path_continue(it, b, fr, wo, smp, ts, &st, &wgt, r) || !st.specular) return 0;
  *beta = c3_mul(*beta, wgt);
  return !c3_black(*beta) && c3_finite(*beta);
}

rgb li_shade_through_delta(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, surface_shade_fn shade) {
  rgb L = c3(0, 0, 0), beta = c3(1, 1, 1);
  int max_depth = c->max_depth >= 0 ? c->max_depth : 32;
  for (int depth = 0;; depth++) {
    isect it;
    bsdf b;
    frame fr;
    vec3 wo;
    if (!delta_chain_vertex(c, &r, beta, depth, max_depth, ts, &L, &it, &b, &fr, &wo)) break;
    if (bsdf_has_smooth(&b)) L = c3_add(L, c3_mul(beta, shade(c, &it, &b, &fr, wo, depth, smp, ts)));
    /* delta lobes carry the camera path on; a non-delta sample ends it */
    sampler_set_dim(smp, sdim_bounce(depth, SDIM_LOBE));
    if (!delta_chain_continue(&it, &b, &fr, wo, smp, ts, &beta, &r)) break;
  }
  return L;
}

