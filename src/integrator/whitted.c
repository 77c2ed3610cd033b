/* whitted.c — owns the `whitted` integrator (Whitted 1980; digest 000): at every hit,
 * emission plus direct light from every kind of light by light sampling (point, spot and
 * directional exactly, area lights and the environment with one sample, no MIS), then
 * deterministic branching into the ideal reflection and refraction of mirrors, glass and
 * metals, to a fixed depth (max_depth; 5 when unlimited). No diffuse or glossy
 * interreflection: it equals `path` where every light path is light -> one diffuse or
 * glossy surface -> ideal specular surfaces -> camera, and is darker elsewhere. */
#include "integrator/path_common.h"
#include "integrator/integrator.h"
#include "material/fresnel.h"

#define WHITTED_DEFAULT_DEPTH 5

static rgb whitted_rec(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, int depth) {
  rgb L;
  isect it;
  bsdf b;
  frame fr;
  vec3 wo;
  int max_depth = c->max_depth >= 0 ? c->max_depth : WHITTED_DEFAULT_DEPTH;
  if (!recursive_vertex(c, &r, smp, ts, depth, max_depth, 1, &L, &it, &b, &fr, &wo)) return L;
  vec3 wo_l = frame_to_local(&fr, wo);
  vec3 refl_l = v3(-wo_l.x, -wo_l.y, wo_l.z);
  rgb k_refl = c3(0, 0, 0), k_refr = c3(0, 0, 0);
  vec3 refr_l = v3(0, 0, 0);
  float eta_scale = 1;
  switch (b.type) {
  case BSDF_DIFFUSE: case BSDF_PHONG: case BSDF_ROUGH_CONDUCTOR: case BSDF_ROUGH_DIELECTRIC: case BSDF_PBR: case BSDF_ROUGH_PLASTIC: case BSDF_PRINCIPLED: break; /* direct light only */
  case BSDF_PLASTIC: k_refl = c3_scale(b.ks, fresnel_dielectric(wo_l.z, b.eta)); break; /* its coat's mirror */
  case BSDF_MIRROR: k_refl = b.ks; break;
  case BSDF_CONDUCTOR: k_refl = c3_mul(b.cond_tint, fresnel_conductor(fabsf(wo_l.z), b.cond_eta, b.cond_k)); break;
  case BSDF_DIELECTRIC: {
    float F = fresnel_dielectric(wo_l.z, b.eta);
    k_refl = c3(F, F, F);
    float etap = wo_l.z > 0 ? b.eta : 1 / b.eta;
    if (F < 1 && refract_dir(wo_l, v3(0, 0, wo_l.z > 0 ? 1.0f : -1.0f), etap, &refr_l)) {
      eta_scale = 1 / (etap * etap);
      k_refr = c3((1 - F) * eta_scale, (1 - F) * eta_scale, (1 - F) * eta_scale);
    }
    break;
  }
  case BSDF_THIN_DIELECTRIC: {
    float R = fresnel_thin_dielectric(wo_l.z, b.eta);
    k_refl = c3(R, R, R);
    k_refr = c3(1 - R, 1 - R, 1 - R);
    refr_l = v3_neg(wo_l);
    break;
  }
  }
  if (!c3_black(k_refl) && (wo_l.z != 0)) {
    vec3 wi = v3_norm(frame_to_world(&fr, refl_l));
    if ((v3_dot(wi, it.ng) > 0) == (v3_dot(wo, it.ng) > 0))
      L = c3_add(L, c3_mul(k_refl, whitted_rec(c, spawn_ray(&it, wi), smp, ts, depth + 1)));
  }
  if (!c3_black(k_refr)) {
    vec3 wi = v3_norm(frame_to_world(&fr, refr_l));
    if ((v3_dot(wi, it.ng) > 0) != (v3_dot(wo, it.ng) > 0))
      L = c3_add(L, c3_mul(k_refr, whitted_rec(c, spawn_ray(&it, wi), smp, ts, depth + 1)));
  }
  return L;
}

static rgb whitted_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) { return whitted_rec(c, r, smp, ts, 0); }

const integrator_ops integrator_whitted = {
    .name = "whitted",
    .description = "Whitted ray tracing: direct light and ideal reflection/refraction to a fixed depth",
    .kind = INTEGRATOR_RAY,
    .li = whitted_li,
};
