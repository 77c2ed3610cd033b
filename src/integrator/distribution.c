/* distribution.c — owns the `distribution` integrator (Cook et al. 1984; digest 000
 * "distribution (stochastic) ray tracing with branching and fixed depth"): at every hit,
 * emission where a camera or specular ray finds it, direct light by light sampling (no
 * MIS), and DIST_BRANCH BSDF-sampled branches averaged, recursively to a fixed depth
 * (max_depth; 3 when unlimited), with no Russian roulette. Unbiased for the
 * depth-truncated light transport — it agrees with `path` at the same max_depth — and so
 * darker than unlimited `path` by the energy of the longer paths. Cost grows as
 * DIST_BRANCH^depth. */
#include "integrator/path_common.h"
#include "integrator/integrator.h"

#define DIST_BRANCH 4
#define DIST_DEFAULT_DEPTH 3

static rgb dist_rec(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, int depth, int count_emission) {
  rgb L;
  isect it;
  bsdf b;
  frame fr;
  vec3 wo;
  int max_depth = c->max_depth >= 0 ? c->max_depth : DIST_DEFAULT_DEPTH;
  if (!recursive_vertex(c, &r, smp, ts, depth, max_depth, count_emission, &L, &it, &b, &fr, &wo)) return L;
  vec3 wo_l = frame_to_local(&fr, wo);
  rgb acc = c3(0, 0, 0);
  for (int k = 0; k < DIST_BRANCH; k++) {
    bsdf_sample bs;
    float ul = sampler_1d(smp), u1, u2;
    sampler_2d(smp, &u1, &u2);
    if (!bsdf_sample_dir(&b, wo_l, ul, u1, u2, &bs)) continue;
    vec3 wi = v3_norm(frame_to_world(&fr, bs.wi));
    int refl_l = (bs.wi.z > 0) == (wo_l.z > 0), refl_g = (v3_dot(wi, it.ng) > 0) == (v3_dot(wo, it.ng) > 0);
    if (refl_l != refl_g) continue;
    /* Emission reached through a smooth lobe is already counted by light sampling. */
    acc = c3_add(acc, c3_mul(bs.weight, dist_rec(c, spawn_ray(&it, wi), smp, ts, depth + 1, bs.delta)));
  }
  return c3_add(L, c3_scale(acc, 1.0f / DIST_BRANCH));
}

static rgb dist_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) { return dist_rec(c, r, smp, ts, 0, 1); }

const integrator_ops integrator_distribution = {
    .name = "distribution",
    .description = "distribution ray tracing: light sampling plus branching BSDF rays to a fixed depth",
    .kind = INTEGRATOR_RAY,
    .li = dist_li,
};
