/* path.c — owns the `path` integrator: unidirectional path tracing with next-event
 * estimation and multiple importance sampling (power heuristic, Veach 1997) between light
 * and BSDF sampling, delta lights and specular lobes handled without MIS, and unbiased
 * Russian roulette (digest 000: divide by the continuation probability). Emission found
 * by BSDF-sampled rays is MIS-weighted against the NEE that could have found it, so
 * nothing is counted twice. */
#include "integrator/integrator.h"
#include "core/sampling.h"

static rgb path_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) {
  const scene *s = c->s;
  rgb L = c3(0, 0, 0), beta = c3(1, 1, 1);
  int specular = 1;          /* camera rays count emission fully */
  float prev_pdf = 0, eta_acc = 1;
  vec3 prev_p = r.o;
  int max_depth = c->max_depth >= 0 ? c->max_depth : PATH_HARD_CAP;
  for (int depth = 0;; depth++) {
    hit h;
    if (!ctx_intersect(c, &r, &h, ts)) {
      if (c->ls.env_index >= 0) {
        const light *env = &s->lights[c->ls.env_index];
        float w = 1;
        if (!specular) w = power_heuristic(prev_pdf, light_select_pmf(c, (uint32_t)c->ls.env_index) * light_pdf_env(s, env, r.d));
        L = c3_add(L, c3_scale(c3_mul(beta, light_env_radiance(s, env, r.d)), w));
      }
      break;
    }
    isect it;
    isect_from_hit(s, &r, &h, &it);
    vec3 wo = v3_neg(r.d);
    int32_t lid = s->tri_light[h.tri];
    if (lid >= 0) {
      const light *l = &s->lights[lid];
      rgb Le = light_area_radiance(s, l, it.ng, wo, it.u, it.v);
      if (!c3_black(Le)) {
        float w = 1;
        if (!specular) w = power_heuristic(prev_pdf, light_select_pmf(c, (uint32_t)lid) * light_pdf_area(s, l, prev_p, it.p, it.ng));
        L = c3_add(L, c3_scale(c3_mul(beta, Le), w));
      }
    }
    if (depth >= max_depth) break;

    bsdf b = bsdf_at(s, &it);
    vec3 ns = it.ns;
    if (!bsdf_transmits(&b)) {
      /* Opaque surfaces are two-sided: face both normals towards the viewer. */
      if (v3_dot(it.ng, wo) < 0) it.ng = v3_neg(it.ng);
      if (v3_dot(ns, wo) < 0) ns = v3_neg(ns);
    }
    frame fr = frame_from_n(ns);
    if (bsdf_has_smooth(&b)) L = c3_add(L, c3_mul(beta, estimate_direct(c, &it, &b, &fr, wo, smp, ts)));

    bsdf_sample bs;
    float ul = sampler_1d(smp), u1, u2;
    sampler_2d(smp, &u1, &u2);
    vec3 wo_l = frame_to_local(&fr, wo);
    if (!bsdf_sample_dir(&b, wo_l, ul, u1, u2, &bs)) break;
    vec3 wi = v3_norm(frame_to_world(&fr, bs.wi));
    /* The sampled direction must agree with the geometric normal about reflection vs
     * transmission, or shading normals would leak light. */
    int refl_l = (bs.wi.z > 0) == (wo_l.z > 0), refl_g = (v3_dot(wi, it.ng) > 0) == (v3_dot(wo, it.ng) > 0);
    if (refl_l != refl_g) break;
    beta = c3_mul(beta, bs.weight);
    if (c3_black(beta) || !c3_finite(beta)) break;
    specular = bs.delta;
    prev_pdf = bs.pdf;
    prev_p = it.p;
    eta_acc /= bs.eta_scale;
    r = spawn_ray(&it, wi);

    /* Russian roulette (pbrt-v4): survive with probability min(1, max(beta) * eta^2). */
    float rr = c3_max(beta) * eta_acc;
    if (depth >= 2 && rr < 1) {
      float q = fmaxf(0.0f, 1 - rr);
      if (sampler_1d(smp) < q) break;
      beta = c3_scale(beta, 1 / (1 - q));
    }
  }
  return L;
}

const integrator_ops integrator_path = {
    "path", "unidirectional path tracing with next-event estimation, MIS and Russian roulette", path_li};
