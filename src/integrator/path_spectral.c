/* path_spectral.c — owns the spectral variant of the `path` integrator (`--spectral`):
 * the same estimator as path.c (NEE + MIS, Russian roulette) with radiance carried at 4
 * wavelengths per path (hero wavelength sampling, core/spectrum.h). RGB reflectances,
 * emission and BSDF weights are upsampled to spectra at the path's wavelengths, and every
 * product (BSDF x light, throughput x BSDF) is taken per wavelength. At a dispersive
 * dielectric the index comes from its Sellmeier/Cauchy preset at the hero wavelength and
 * the other wavelengths are dropped (the hero then counts 4 times), so each colour
 * refracts at its own angle. The result is converted through CIE XYZ to linear sRGB. */
#include "integrator/integrator.h"
#include "core/sampling.h"
#include "core/spectrum.h"

/* Next-event estimation with f and Li upsampled separately and multiplied per
 * wavelength (estimate_direct multiplies them per RGB channel). */
static spec4 direct_spectral(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                             thread_stats *ts, const wavelengths *wl) {
  direct_sample d;
  if (!sample_direct(c, it, b, fr, wo, smp, ts, 1, &d)) return spec_const(0);
  return spec_scale(spec_mul(spec_from_rgb(d.f_cos, wl), spec_from_rgb(d.Li, wl)), d.scale);
}

static rgb path_spectral_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) {
  const scene *s = c->s;
  wavelengths wl = wavelengths_sample(sampler_1d(smp));
  spec4 L = spec_const(0), beta = spec_const(1);
  int specular = 1;
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
        L = spec_add(L, spec_scale(spec_mul(beta, spec_from_rgb(light_env_radiance(s, env, r.d), &wl)), w));
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
        L = spec_add(L, spec_scale(spec_mul(beta, spec_from_rgb(Le, &wl)), w));
      }
    }
    if (depth >= max_depth) break;
    bsdf b = bsdf_at(s, &it);
    if (it.m->dispersion && bsdf_transmits(&b)) {
      b.eta = dispersion_ior((dispersion)it.m->dispersion, wl.lambda[0]);
      wavelengths_terminate_secondary(&wl);
    }
    frame fr = shading_frame(&it, &b, wo);
    if (bsdf_has_smooth(&b)) L = spec_add(L, spec_mul(beta, direct_spectral(c, &it, &b, &fr, wo, smp, ts, &wl)));
    bsdf_sample bs;
    float ul = sampler_1d(smp), u1, u2;
    sampler_2d(smp, &u1, &u2);
    vec3 wo_l = frame_to_local(&fr, wo);
    if (!bsdf_sample_dir(&b, wo_l, ul, u1, u2, &bs)) break;
    vec3 wi = v3_norm(frame_to_world(&fr, bs.wi));
    int refl_l = (bs.wi.z > 0) == (wo_l.z > 0), refl_g = (v3_dot(wi, it.ng) > 0) == (v3_dot(wo, it.ng) > 0);
    if (refl_l != refl_g) break;
    beta = spec_mul(beta, spec_from_rgb(bs.weight, &wl));
    if (spec_black(beta)) break;
    specular = bs.delta;
    prev_pdf = bs.pdf;
    prev_p = it.p;
    eta_acc /= bs.eta_scale;
    r = spawn_ray(&it, wi);
    float rr = spec_max(beta) * eta_acc;
    if (depth >= 2 && rr < 1) {
      float q = fmaxf(0.0f, 1 - rr);
      if (sampler_1d(smp) < q) break;
      beta = spec_scale(beta, 1 / (1 - q));
    }
  }
  return spec_to_rgb(L, &wl);
}

const integrator_ops integrator_path_spectral = {
    "path", "spectral path tracing: hero wavelength + 3, dispersion, CIE XYZ to linear sRGB", path_spectral_li};
