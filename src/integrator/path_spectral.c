/* path_spectral.c — owns the spectral variant of the `path` integrator (`--spectral`):
 * the same estimator as path.c (NEE + MIS, Russian roulette) with radiance carried at 4
 * wavelengths per path (hero wavelength sampling, core/spectrum.h). RGB reflectances,
 * emission and BSDF weights are upsampled to spectra at the path's wavelengths, and every
 * product (BSDF x light, throughput x BSDF) is taken per wavelength. At a dispersive
 * dielectric the index comes from its Sellmeier/Cauchy preset at the hero wavelength and
 * the other wavelengths are dropped (the hero then counts 4 times), so each colour
 * refracts at its own angle. A conductor given per wavelength (JSON "spectrum") has its
 * BSDF evaluated with F = 1 and the Fresnel term of each wavelength's eta, k applied
 * here. The result is converted through CIE XYZ to linear sRGB. */
#include "integrator/path_common.h"
#include "integrator/integrator.h"
#include "core/sampling.h"
#include "core/spectrum.h"
#include "material/fresnel.h"

/* At the half vector, which is the microfacet normal of a rough conductor and the normal
 * of a smooth one. */
spec4 nk_fresnel(const nk_curve *nk, vec3 wo, vec3 wi, const wavelengths *wl) {
  vec3 h = v3_add(wo, wi);
  float len = v3_len(h), c = len > 1e-7f ? fabsf(v3_dot(wo, h)) / len : 0;
  spec4 F;
  for (int i = 0; i < N_LAMBDA; i++)
    F.v[i] = fresnel_conductor1(c, tab_eval(nk->nm, nk->eta, nk->n, wl->lambda[i]), tab_eval(nk->nm, nk->k, nk->n, wl->lambda[i]));
  return F;
}

/* Next-event estimation with f and Li upsampled separately and multiplied per
 * wavelength (path.c multiplies them per RGB channel). */
static spec4 direct_spectral(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                             thread_stats *ts, const wavelengths *wl, const nk_curve *nk) {
  direct_sample d;
  if (!sample_direct(c, it, b, fr, wo, smp, ts, 1, &d)) return spec_const(0);
  spec4 f = spec_from_rgb(d.f_cos, wl);
  if (nk) f = spec_mul(f, nk_fresnel(nk, wo, d.wi, wl));
  return spec_scale(spec_mul(f, spec_from_rgb(d.Li, wl)), d.scale);
}

const nk_curve *spectral_bsdf(const scene *s, const isect *it, bsdf *b, wavelengths *wl) {
  if (it->m->dispersion && bsdf_transmits(b)) {
    b->eta = dispersion_ior((dispersion)it->m->dispersion, wl->lambda[0]);
    wavelengths_terminate_secondary(wl);
  }
  const nk_curve *nk = it->m->nk ? &s->nk[it->m->nk - 1] : NULL;
  if (nk) b->fresnel_white = 1;
  return nk;
}

static rgb path_spectral_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) {
  const scene *s = c->s;
  sampler_set_dim(smp, SDIM_WAVELENGTH);
  wavelengths wl = wavelengths_sample(sampler_1d(smp));
  if (s->has_media) {
    spec4 Lm = path_media_walk(c, r, smp, ts, !c->hide_emitters, &wl);
    return spec_to_rgb(Lm, &wl);
  }
  spec4 L = spec_const(0), beta = spec_const(1);
  path_state st = path_state_start(r.o);
  int max_depth = c->max_depth >= 0 ? c->max_depth : PATH_HARD_CAP;
  for (int depth = 0;; depth++) {
    isect it;
    rgb Le;
    float w;
    int surface = path_trace_vertex(c, &r, &st, ts, &it, &Le, &w);
    if (!c3_black(Le) && (depth > 0 || !c->hide_emitters)) L = spec_add(L, spec_scale(spec_mul(beta, spec_from_rgb(Le, &wl)), w));
    if (!surface || depth >= max_depth) break;
    vec3 wo = v3_neg(r.d);
    bsdf b = bsdf_at(s, &it);
    const nk_curve *nk = spectral_bsdf(s, &it, &b, &wl);
    frame fr = shading_frame(&it, &b, wo);
    sampler_set_dim(smp, sdim_bounce(depth, SDIM_LIGHT_PICK));
    if (bsdf_has_smooth(&b)) L = spec_add(L, spec_mul(beta, direct_spectral(c, &it, &b, &fr, wo, smp, ts, &wl, nk)));
    rgb weight;
    sampler_set_dim(smp, sdim_bounce(depth, SDIM_LOBE));
    if (!path_continue(&it, &b, &fr, wo, smp, ts, &st, &weight, &r)) break;
    beta = spec_mul(beta, spec_from_rgb(weight, &wl));
    if (nk) beta = spec_mul(beta, nk_fresnel(nk, wo, r.d, &wl));
    if (spec_black(beta)) break;
    sampler_set_dim(smp, sdim_bounce(depth, SDIM_ROULETTE));
    float survive = path_roulette(&st, spec_max(beta), depth, c->rr_depth, smp);
    if (survive == 0) break;
    beta = spec_scale(beta, survive);
  }
  return spec_to_rgb(L, &wl);
}

const integrator_ops integrator_path_spectral = {
    .name = "path-spectral",
    .description = "spectral path tracing (what --spectral selects for path): hero wavelength + 3, dispersion, CIE XYZ to linear sRGB",
    .kind = INTEGRATOR_RAY,
    .li = path_spectral_li,
};
