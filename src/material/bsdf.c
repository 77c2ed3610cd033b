/* bsdf.c — owns the BSDF models (digest 000): Lambertian, energy-conserving normalised
 * Phong (Lafortune & Willems 1994: kd/pi + ks (n+2)/(2pi) cos^n alpha) with mixture
 * sampling of its lobes, diffuse + ideal mirror (MTL illum 5), smooth dielectric (Fresnel
 * reflection/refraction, total internal reflection, radiance scaled by 1/eta^2 across the
 * boundary as in pbrt-v4), smooth conductor (complex Fresnel), and GGX rough conductor
 * and rough dielectric (Walter et al. 2007) sampled by visible normals (microfacet.h),
 * following pbrt-v4's formulation of the rough dielectric; and the glTF 2.0
 * metallic-roughness model (glTF spec, appendix B): mix(dielectric, metal, metallic)
 * where the dielectric is fresnel_mix(F0 = 0.04; Lambertian base colour, GGX specular)
 * and the metal is the GGX specular with Schlick Fresnel of F0 = base colour; lobes
 * chosen by a fixed mixture probability, specular by visible normals, with glTF's sheen
 * (sheen.h) and clearcoat layers over it; Mitsuba's plastics (plastic.c). */
#include "material/bsdf.h"
#include "material/fresnel.h"
#include "core/sampling.h"
#include "material/microfacet.h"
#include "material/plastic.h"
#include "material/principled.h"
#include "material/sheen.h"

static float lobe_prob(rgb a, rgb b) {
  float wa = c3_avg(a), wb = c3_avg(b);
  return wa + wb > 0 ? wa / (wa + wb) : 1.0f;
}

bsdf bsdf_from_material(const material *m) {
  bsdf b;
  memset(&b, 0, sizeof b);
  b.kd = m->kd; b.ks = m->ks; b.exponent = m->exponent; b.eta = m->ior;
  b.cond_eta = m->eta; b.cond_k = m->k; b.cond_tint = m->tint; b.trans = m->transmittance;
  b.f0 = m->f0; b.f90 = m->f90;
  b.beckmann = m->beckmann && m->type != MAT_PBR;
  b.separable = m->smith_separable && m->type != MAT_PBR;
  b.p_first = 1;
  switch (m->type) {
  case MAT_DIFFUSE: b.type = BSDF_DIFFUSE; break;
  case MAT_NULL: b.type = BSDF_DIFFUSE; b.kd = c3(0, 0, 0); break; /* path passes it by; nothing else sees it */
  case MAT_BLEND: b.type = BSDF_DIFFUSE; b.kd = c3(0, 0, 0); break; /* hits see one of its materials (isect_from_hit) */
  case MAT_PRINCIPLED:
    b.type = BSDF_PRINCIPLED;
    b.metallic = clampf(m->metallic, 0, 1);
    b.roughness = clampf(m->roughness, 0, 1);
    b.alpha = b.alpha_v = fmaxf(1e-3f, b.roughness * b.roughness);
    if (m->anisotropic && m->anisotropy > 0) { /* Mitsuba's: aspect sqrt(1 - 0.9 anisotropic), alpha / aspect along u, alpha * aspect along v */
      float r2 = b.roughness * b.roughness, aspect = sqrtf(1 - 0.9f * clampf(m->anisotropy, 0, 1));
      b.alpha = fmaxf(1e-3f, r2 / aspect);
      b.alpha_v = fmaxf(1e-3f, r2 * aspect);
    }
    b.spec_tint = m->spec_tint; b.sheen = m->sheen; b.sheen_tint = m->sheen_tint;
    b.flatness = m->flatness; b.clearcoat = m->clearcoat; b.spec_trans = clampf(m->spec_trans, 0, 1);
    b.cc_alpha = 0.1f + (0.001f - 0.1f) * clampf(m->clearcoat_gloss, 0, 1);
    return b;
  case MAT_PHONG: b.type = BSDF_PHONG; b.p_first = lobe_prob(m->kd, m->ks); break;
  case MAT_MIRROR: b.type = BSDF_MIRROR; b.p_first = lobe_prob(m->kd, m->ks); break;
  case MAT_DIELECTRIC: b.type = BSDF_DIELECTRIC; break;
  case MAT_THIN_DIELECTRIC: b.type = BSDF_THIN_DIELECTRIC; break;
  case MAT_CONDUCTOR: b.type = BSDF_CONDUCTOR; break;
  case MAT_PLASTIC: {
    b.alpha = m->roughness * m->roughness;
    b.type = b.alpha >= 1e-3f ? BSDF_ROUGH_PLASTIC : BSDF_PLASTIC;
    b.beckmann = m->beckmann;
    b.nonlinear = m->nonlinear;
    float wd = c3_avg(m->kd), ws = c3_avg(m->ks);
    b.spec_w = wd + ws > 0 ? ws / (wd + ws) : 0.5f;
    b.coat_ri = m->coat_ri;
    b.coat_t = m->coat_t;
    return b;
  }
  case MAT_PBR: {
    b.type = BSDF_PBR;
    b.metallic = clampf(m->metallic, 0, 1);
    b.clearcoat = clampf(m->clearcoat, 0, 1); /* glTF's clearcoat: a GGX layer of ior 1.5 */
    b.cc_alpha = fmaxf(1e-3f, m->clearcoat_roughness * m->clearcoat_roughness);
    b.metal_flat = m->metal_flat;
    /* Diffuse lobe weight against the specular one (never 0 unless the diffuse term is). */
    float wd = (1 - b.metallic) * c3_avg(m->kd), ws = b.metallic + (1 - b.metallic) * 0.25f;
    b.p_first = wd + ws > 0 ? wd / (wd + ws) : 0;
    /* alpha >= 1e-3: GGX is used down to a near-mirror (roughness 0 is not a delta). */
    b.alpha = fmaxf(m->roughness * m->roughness, 1e-3f);
    b.sh_max = c3_max(m->sheen_color);
    if (b.sh_max > 0) {
      b.sh_E = m->sheen_E;
      b.sh_color = m->sheen_color;
      b.sh_alpha = sheen_alpha(m->sheen_roughness);
    }
    return b;
  }
  }
  b.alpha = b.alpha_v = m->roughness * m->roughness;
  if (m->anisotropic && (b.type == BSDF_CONDUCTOR || b.type == BSDF_DIELECTRIC)) {
    /* rough if either way is; the other then no smoother than GGX's near-mirror */
    b.alpha_v = m->roughness_v * m->roughness_v;
    if (fmaxf(b.alpha, b.alpha_v) >= 1e-3f) b.alpha = fmaxf(b.alpha, 1e-3f), b.alpha_v = fmaxf(b.alpha_v, 1e-3f);
  }
  if (fmaxf(b.alpha, b.alpha_v) >= 1e-3f) {
    if (b.type == BSDF_CONDUCTOR) b.type = BSDF_ROUGH_CONDUCTOR;
    else if (b.type == BSDF_DIELECTRIC) b.type = BSDF_ROUGH_DIELECTRIC;
  }
  return b;
}

int bsdf_has_smooth(const bsdf *b) {
  if (b->mix && bsdf_has_smooth(b->mix)) return 1;
  switch (b->type) {
  case BSDF_DIFFUSE: case BSDF_PHONG: return 1;
  case BSDF_MIRROR: return b->p_first > 0;
  case BSDF_DIELECTRIC: case BSDF_CONDUCTOR: case BSDF_THIN_DIELECTRIC: return 0;
  case BSDF_ROUGH_CONDUCTOR: case BSDF_ROUGH_DIELECTRIC: case BSDF_PBR: return 1;
  case BSDF_PLASTIC: case BSDF_ROUGH_PLASTIC: case BSDF_PRINCIPLED: return 1;
  }
  return 0;
}

/* glTF metallic-roughness f(wo, wi) for wo.z, wi.z > 0. */
static rgb pbr_eval(const bsdf *b, vec3 wo, vec3 wi) {
  vec3 wm = v3_add(wo, wi);
  if (!(v3_len2(wm) > 0)) return c3(0, 0, 0);
  wm = v3_norm(wm);
  float s5 = schlick_weight(fabsf(v3_dot(wo, wm)));
  float spec = ggx_D(b->alpha, wm) * ggx_G(b->alpha, wo, wi) / (4 * wo.z * wi.z);
  /* Dielectric: F = F0 + (F90 - F0) (1 - v.h)^5, F0 = 0.04 (ior 1.5) and F90 = 1 unless
   * KHR_materials_ior or _specular say otherwise. The specular layer takes F(v.h) as in
   * the spec; the diffuse base is weighted by 1 - F(n.v) instead of the spec's 1 - F(v.h),
   * which returns up to 35 % more energy than arrives at grazing angles (test_chi2
   * furnace). The price: this diffuse base is not reciprocal (test_chi2 bsdf_reciprocity). */
  float so = schlick_weight(wo.z);
  float Fd[3] = {b->f0.r + (b->f90 - b->f0.r) * s5, b->f0.g + (b->f90 - b->f0.g) * s5, b->f0.b + (b->f90 - b->f0.b) * s5};
  float Fo[3] = {b->f0.r + (b->f90 - b->f0.r) * so, b->f0.g + (b->f90 - b->f0.g) * so, b->f0.b + (b->f90 - b->f0.b) * so};
  rgb Fm = b->metal_flat ? b->kd : c3_add(b->kd, c3_scale(c3_sub(c3(1, 1, 1), b->kd), s5));
  rgb diel = c3(b->kd.r * ((1 - Fo[0]) * INV_PI_F) + Fd[0] * spec, b->kd.g * ((1 - Fo[1]) * INV_PI_F) + Fd[1] * spec,
                b->kd.b * ((1 - Fo[2]) * INV_PI_F) + Fd[2] * spec);
  rgb f = c3_add(c3_scale(diel, 1 - b->metallic), c3_scale(Fm, b->metallic * spec));
  if (b->sh_E) { /* KHR_materials_sheen over it, the base scaled by what the sheen leaves (sheen.h) */
    float keep = fminf(1 - b->sh_max * sheen_albedo(b->sh_E, wo.z), 1 - b->sh_max * sheen_albedo(b->sh_E, wi.z));
    f = c3_add(c3_scale(f, keep), c3_scale(b->sh_color, sheen_eval(b->sh_alpha, wo.z, wi.z, wm.z)));
  }
  if (b->clearcoat > 0) { /* KHR_materials_clearcoat: mix(f, coat, clearcoat F(n.v)), F0 = 0.04 */
    float fc = b->clearcoat * (0.04f + 0.96f * so), coat = ggx_D(b->cc_alpha, wm) * ggx_G(b->cc_alpha, wo, wi) / (4 * wo.z * wi.z);
    f = c3_add(c3_scale(f, 1 - fc), c3(fc * coat, fc * coat, fc * coat));
  }
  return f;
}
/* The probability of sampling the clearcoat's lobe, from wo, and, below it, of sampling
 * the cosine lobe: the sheen's share of wo's light, max(colour) E(n.v), and of the rest
 * the diffuse lobe's p_first (the specular lobe takes what is left). */
static float pbr_coat_prob(const bsdf *b, vec3 wo) { return b->clearcoat > 0 ? b->clearcoat * (0.25f + 0.5f * schlick_weight(wo.z)) : 0; }
static float pbr_cos_prob(const bsdf *b, vec3 wo) {
  float psh = b->sh_E ? b->sh_max * sheen_albedo(b->sh_E, wo.z) : 0;
  return psh + (1 - psh) * b->p_first;
}
static float pbr_pdf(const bsdf *b, vec3 wo, vec3 wi) {
  vec3 wm = v3_add(wo, wi);
  if (!(v3_len2(wm) > 0)) return 0;
  wm = v3_norm(wm);
  float ps = ggx_D_visible(b->alpha, wo, wm) / (4 * fabsf(v3_dot(wo, wm)));
  float pcos = pbr_cos_prob(b, wo), pdf = pcos * cosine_hemisphere_pdf(wi.z) + (1 - pcos) * ps, pc = pbr_coat_prob(b, wo);
  if (pc > 0) pdf = (1 - pc) * pdf + pc * ggx_D_visible(b->cc_alpha, wo, wm) / (4 * fabsf(v3_dot(wo, wm)));
  return pdf;
}

/* ---- rough dielectric (pbrt-v4 DielectricBxDF): the half vector of a refraction is
 * wm = normalize(wi * etap + wo), facing +z; reflection R = F, transmission T = 1 - F. */
static int rd_half(const bsdf *b, vec3 wo, vec3 wi, vec3 *wm_out, float *etap_out) {
  int reflect = wo.z * wi.z > 0;
  float etap = 1;
  if (!reflect) etap = wo.z > 0 ? b->eta : 1 / b->eta;
  vec3 wm = v3_add(v3_scale(wi, etap), wo);
  if (wi.z == 0 || wo.z == 0 || !(v3_len2(wm) > 0)) return 0;
  wm = v3_norm(wm);
  if (wm.z < 0) wm = v3_neg(wm);
  /* Discard back-facing microfacets. */
  if (v3_dot(wm, wi) * wi.z < 0 || v3_dot(wm, wo) * wo.z < 0) return 0;
  *wm_out = wm;
  *etap_out = etap;
  return 1;
}
static rgb rd_eval(const bsdf *b, vec3 wo, vec3 wi) {
  vec3 wm;
  float etap;
  if (!rd_half(b, wo, wi, &wm, &etap)) return c3(0, 0, 0);
  float F = fresnel_dielectric(v3_dot(wo, wm), b->eta);
  float D = mfa_D(b->beckmann, b->alpha, b->alpha_v, wm), G = mfa_G(b->beckmann, b->separable, b->alpha, b->alpha_v, wo, wi);
  float v;
  if (etap == 1) v = D * G * F / fabsf(4 * wi.z * wo.z);
  else {
    float denom = sqr(v3_dot(wi, wm) + v3_dot(wo, wm) / etap) * wi.z * wo.z;
    v = D * G * (1 - F) * fabsf(v3_dot(wi, wm) * v3_dot(wo, wm) / denom) / (etap * etap);
    return c3_scale(b->trans, v);
  }
  return c3(v, v, v);
}
static float rd_pdf(const bsdf *b, vec3 wo, vec3 wi) {
  vec3 wm;
  float etap;
  if (!rd_half(b, wo, wi, &wm, &etap)) return 0;
  float R = fresnel_dielectric(v3_dot(wo, wm), b->eta), T = 1 - R;
  float pdf;
  if (etap == 1) pdf = mfa_pdf_m(b->beckmann, b->alpha, b->alpha_v, wo, wm) / (4 * fabsf(v3_dot(wo, wm))) * R / (R + T);
  else {
    float denom = sqr(v3_dot(wi, wm) + v3_dot(wo, wm) / etap);
    pdf = mfa_pdf_m(b->beckmann, b->alpha, b->alpha_v, wo, wm) * fabsf(v3_dot(wi, wm)) / denom * T / (R + T);
  }
  return pdf;
}

static rgb conductor_F(const bsdf *b, float cos_i) {
  return c3_mul(b->cond_tint, b->fresnel_white ? c3(1, 1, 1) : fresnel_conductor(cos_i, b->cond_eta, b->cond_k));
}

static inline float phong_cos_alpha(vec3 wo, vec3 wi) {
  vec3 r = v3(-wo.x, -wo.y, wo.z); /* mirror direction of wo about z */
  return v3_dot(r, wi);
}

static rgb model_eval(const bsdf *b, vec3 wo, vec3 wi) {
  if (b->type == BSDF_ROUGH_DIELECTRIC) return rd_eval(b, wo, wi);
  if (b->type == BSDF_PRINCIPLED) return principled_eval(b, wo, wi); /* it may transmit */
  if (wo.z <= 0 || wi.z <= 0) return c3(0, 0, 0);
  switch (b->type) {
  case BSDF_DIFFUSE: return c3_scale(b->kd, INV_PI_F);
  case BSDF_MIRROR: return c3_scale(b->kd, INV_PI_F);
  case BSDF_PHONG: {
    float ca = phong_cos_alpha(wo, wi);
    float lobe = ca > 0 ? (b->exponent + 2) * (0.5f * INV_PI_F) * powf(ca, b->exponent) : 0;
    return c3_add(c3_scale(b->kd, INV_PI_F), c3_scale(b->ks, lobe));
  }
  case BSDF_DIELECTRIC: case BSDF_CONDUCTOR: case BSDF_ROUGH_DIELECTRIC: case BSDF_THIN_DIELECTRIC: return c3(0, 0, 0);
  case BSDF_PBR: return pbr_eval(b, wo, wi);
  case BSDF_PLASTIC: case BSDF_ROUGH_PLASTIC: return plastic_eval(b, wo, wi);
  case BSDF_PRINCIPLED: return principled_eval(b, wo, wi);
  case BSDF_ROUGH_CONDUCTOR: {
    vec3 wm = v3_norm(v3_add(wo, wi));
    float dg = mfa_D(b->beckmann, b->alpha, b->alpha_v, wm) * mfa_G(b->beckmann, b->separable, b->alpha, b->alpha_v, wo, wi) / (4 * wo.z * wi.z);
    rgb F = conductor_F(b, fabsf(v3_dot(wo, wm)));
    return c3_scale(F, dg);
  }
  }
  return c3(0, 0, 0);
}

static float model_pdf(const bsdf *b, vec3 wo, vec3 wi) {
  if (b->type == BSDF_ROUGH_DIELECTRIC) return rd_pdf(b, wo, wi);
  if (b->type == BSDF_PRINCIPLED) return principled_pdf(b, wo, wi);
  if (wo.z <= 0 || wi.z <= 0) return 0;
  switch (b->type) {
  case BSDF_DIFFUSE: return cosine_hemisphere_pdf(wi.z);
  case BSDF_MIRROR: return b->p_first * cosine_hemisphere_pdf(wi.z);
  case BSDF_PHONG:
    return b->p_first * cosine_hemisphere_pdf(wi.z) + (1 - b->p_first) * phong_lobe_pdf(phong_cos_alpha(wo, wi), b->exponent);
  case BSDF_DIELECTRIC: case BSDF_CONDUCTOR: case BSDF_ROUGH_DIELECTRIC: case BSDF_THIN_DIELECTRIC: return 0;
  case BSDF_PBR: return pbr_pdf(b, wo, wi);
  case BSDF_PLASTIC: case BSDF_ROUGH_PLASTIC: return plastic_pdf(b, wo, wi);
  case BSDF_PRINCIPLED: return principled_pdf(b, wo, wi);
  case BSDF_ROUGH_CONDUCTOR: {
    vec3 wm = v3_norm(v3_add(wo, wi));
    float p = mfa_pdf_m(b->beckmann, b->alpha, b->alpha_v, wo, wm) / (4 * fabsf(v3_dot(wo, wm)));
    return p;
  }
  }
  return 0;
}

/* The end of a non-delta sample: 1 when its pdf is positive and pdf and weight are
 * finite; a NaN or infinite one sets s->nonfinite (a zero pdf is simply no sample). */
static int sample_finite(bsdf_sample *s) {
  if (s->pdf == 0) return 0;
  if (s->pdf > 0 && isfinite(s->pdf) && c3_finite(s->weight)) return 1;
  s->nonfinite = 1;
  return 0;
}

static int model_sample(const bsdf *b, vec3 wo, float ulobe, float u1, float u2, bsdf_sample *s) {
  s->delta = 0;
  s->nonfinite = 0;
  s->eta_scale = 1;
  switch (b->type) {
  case BSDF_DIFFUSE:
  case BSDF_MIRROR:
  case BSDF_PHONG: {
    if (wo.z <= 0) return 0;
    if (b->type == BSDF_MIRROR && ulobe >= b->p_first) {
      s->wi = v3(-wo.x, -wo.y, wo.z);
      s->weight = c3_scale(b->ks, 1.0f / (1 - b->p_first));
      s->pdf = 0;
      s->delta = 1;
      return 1;
    }
    if (b->type == BSDF_PHONG && ulobe >= b->p_first) {
      vec3 r = v3(-wo.x, -wo.y, wo.z);
      frame f = frame_from_n(r);
      s->wi = frame_to_world(&f, sample_phong_lobe(u1, u2, b->exponent));
    } else {
      s->wi = sample_cosine_hemisphere(u1, u2);
    }
    if (s->wi.z <= 0) return 0; /* Phong lobe below the surface: rejected (digest 000) */
    s->pdf = model_pdf(b, wo, s->wi);
    s->weight = c3_scale(model_eval(b, wo, s->wi), s->wi.z / s->pdf);
    return sample_finite(s);
  }
  case BSDF_CONDUCTOR: {
    if (wo.z <= 0) return 0;
    s->wi = v3(-wo.x, -wo.y, wo.z);
    s->weight = conductor_F(b, wo.z);
    s->pdf = 0;
    s->delta = 1;
    return 1;
  }
  case BSDF_THIN_DIELECTRIC: {
    float R = fresnel_thin_dielectric(wo.z, b->eta);
    s->pdf = 0;
    s->delta = 1;
    s->wi = ulobe < R ? v3(-wo.x, -wo.y, wo.z) : v3_neg(wo);
    s->weight = ulobe < R ? c3(1, 1, 1) : b->trans;
    return 1;
  }
  case BSDF_DIELECTRIC: {
    float F = fresnel_dielectric(wo.z, b->eta);
    s->pdf = 0;
    s->delta = 1;
    if (ulobe < F) {
      s->wi = v3(-wo.x, -wo.y, wo.z);
      s->weight = c3(1, 1, 1);
      return 1;
    }
    vec3 n = v3(0, 0, wo.z > 0 ? 1.0f : -1.0f);
    float etap = wo.z > 0 ? b->eta : 1 / b->eta;
    vec3 wt;
    if (!refract_dir(wo, n, etap, &wt)) return 0; /* cannot happen: F = 1 under TIR */
    s->wi = wt;
    s->eta_scale = 1 / (etap * etap);
    s->weight = c3_scale(b->trans, s->eta_scale);
    return 1;
  }
  case BSDF_PBR: {
    if (wo.z <= 0) return 0;
    float pc = pbr_coat_prob(b, wo);
    if (pc > 0 && ulobe < pc) s->wi = v3_reflect(wo, ggx_sample_visible(b->cc_alpha, wo, u1, u2)); /* the clearcoat */
    else {
      if (pc > 0) ulobe = (ulobe - pc) / (1 - pc);
      if (ulobe < pbr_cos_prob(b, wo)) s->wi = sample_cosine_hemisphere(u1, u2); /* the sheen or the diffuse lobe */
      else s->wi = v3_reflect(wo, ggx_sample_visible(b->alpha, wo, u1, u2));
    }
    if (s->wi.z <= 0) return 0;
    s->pdf = pbr_pdf(b, wo, s->wi);
    s->weight = c3_scale(pbr_eval(b, wo, s->wi), s->wi.z / s->pdf);
    return sample_finite(s);
  }
  case BSDF_PLASTIC: case BSDF_ROUGH_PLASTIC:
    if (!plastic_sample(b, wo, ulobe, u1, u2, s)) return 0;
    return s->delta ? 1 : sample_finite(s);
  case BSDF_PRINCIPLED:
    return principled_sample(b, wo, ulobe, u1, u2, s) && sample_finite(s);
  case BSDF_ROUGH_CONDUCTOR: {
    if (wo.z <= 0) return 0;
    vec3 wm = mfa_sample(b->beckmann, b->alpha, b->alpha_v, wo, u1, u2);
    s->wi = v3_reflect(wo, wm);
    if (s->wi.z <= 0) return 0;
    s->pdf = model_pdf(b, wo, s->wi);
    s->weight = c3_scale(model_eval(b, wo, s->wi), s->wi.z / s->pdf);
    return sample_finite(s);
  }
  case BSDF_ROUGH_DIELECTRIC: {
    if (wo.z == 0) return 0;
    vec3 wm = mfa_sample(b->beckmann, b->alpha, b->alpha_v, wo, u1, u2);
    /* Beckmann samples normals wo cannot see: lost (GGX samples only visible ones). */
    if (b->beckmann && v3_dot(wo, wm) * wo.z <= 0) return 0;
    float R = fresnel_dielectric(v3_dot(wo, wm), b->eta), T = 1 - R;
    if (ulobe < R / (R + T)) {
      s->wi = v3_reflect(wo, wm);
      if (s->wi.z * wo.z <= 0) return 0;
    } else {
      /* Refract wo about the microfacet normal turned to wo's side; seen from inside,
       * the relative index is 1/eta. */
      int inside = v3_dot(wo, wm) < 0;
      vec3 n = inside ? v3_neg(wm) : wm;
      float etap = inside ? 1 / b->eta : b->eta;
      if (!refract_dir(wo, n, etap, &s->wi)) return 0;
      if (s->wi.z * wo.z >= 0) return 0;
      s->eta_scale = 1 / (etap * etap);
    }
    s->pdf = model_pdf(b, wo, s->wi);
    s->weight = c3_scale(model_eval(b, wo, s->wi), fabsf(s->wi.z) / s->pdf);
    return sample_finite(s);
  }
  }
  return 0;
}

rgb material_albedo(const material *m, float cos_o) {
  switch (m->type) {
  case MAT_DIFFUSE: return m->kd;
  case MAT_PHONG: case MAT_MIRROR: return c3_add(m->kd, m->ks);
  case MAT_DIELECTRIC: case MAT_THIN_DIELECTRIC: return c3(1, 1, 1);
  case MAT_CONDUCTOR: return c3_mul(m->tint, fresnel_conductor(fabsf(cos_o), m->eta, m->k));
  case MAT_PBR: return m->kd;
  case MAT_PLASTIC: return c3_add(m->kd, c3_scale(m->ks, fresnel_dielectric(fabsf(cos_o), m->ior)));
  case MAT_PRINCIPLED: return c3_add(c3_scale(m->kd, 1 - m->metallic), c3_scale(c3(1, 1, 1), 0.04f)); /* its diffuse and a dielectric's specular */
  case MAT_NULL: case MAT_BLEND: break; /* a blend: hits see one of its materials */
  }
  return c3(0, 0, 0);
}

/* ---- mapped normals (Mitsuba 3's normalmap and bumpmap) ----
 * With b->mapped the frame's normal is a mapped one and b->n0 is the surface's own shading
 * normal in that frame. A direction wi counts only on the same side of both (else f and
 * the pdf are 0), and f is multiplied by the shadowing term of Conty Estevez et al. 2019
 * ("A Microfacet-Based Shadowing Function to Solve the Bump Terminator Problem"):
 * G = 2 / (1 + sqrt(1 + a2 tan^2 theta_i)), a2 = min(0.125 tan^2 theta_n, 1), both angles
 * from n0 (theta_n the mapped normal's), on wi alone (the light's side in a camera path). */
static int map_sides_agree(const bsdf *b, vec3 wi) { return v3_dot(wi, b->n0) * wi.z > 0; }
static float map_shadowing(const bsdf *b, vec3 wi) {
  float cn = b->n0.z, ci = v3_dot(wi, b->n0);
  float tn2 = fmaxf(1 - cn * cn, 0) / (cn * cn), ti2 = fmaxf(1 - ci * ci, 0) / (ci * ci);
  float a2 = fminf(0.125f * tn2, 1);
  float g = 2 / (1 + sqrtf(1 + a2 * ti2));
  return isfinite(g) ? g : 0;
}

static rgb one_eval(const bsdf *b, vec3 wo, vec3 wi) {
  if (!b->mapped) return model_eval(b, wo, wi);
  if (!map_sides_agree(b, wi)) return c3(0, 0, 0);
  return c3_scale(model_eval(b, wo, wi), map_shadowing(b, wi));
}
static float one_pdf(const bsdf *b, vec3 wo, vec3 wi) {
  if (!b->mapped) return model_pdf(b, wo, wi);
  return map_sides_agree(b, wi) ? model_pdf(b, wo, wi) : 0;
}
static int one_sample(const bsdf *b, vec3 wo, float ulobe, float u1, float u2, bsdf_sample *s) {
  if (!model_sample(b, wo, ulobe, u1, u2, s)) return 0;
  if (!b->mapped) return 1;
  if (!map_sides_agree(b, s->wi)) return 0;
  s->weight = c3_scale(s->weight, map_shadowing(b, s->wi));
  return 1;
}

rgb bsdf_eval(const bsdf *b, vec3 wo, vec3 wi) {
  if (!b->mix) return one_eval(b, wo, wi);
  return c3_add(c3_scale(one_eval(b, wo, wi), 1 - b->mix_w), c3_scale(one_eval(b->mix, wo, wi), b->mix_w));
}

float bsdf_pdf(const bsdf *b, vec3 wo, vec3 wi) {
  if (!b->mix) return one_pdf(b, wo, wi);
  return (1 - b->mix_w) * one_pdf(b, wo, wi) + b->mix_w * one_pdf(b->mix, wo, wi);
}

int bsdf_sample_dir(const bsdf *b, vec3 wo, float ulobe, float u1, float u2, bsdf_sample *s) {
  if (!b->mix) return one_sample(b, wo, ulobe, u1, u2, s);
  float w = b->mix_w;
  const bsdf *c = b;
  if (ulobe < w) { c = b->mix; ulobe = ulobe / w; }
  else ulobe = (ulobe - w) / (1 - w);
  if (!one_sample(c, wo, fminf(ulobe, 0x1.fffffep-1f), u1, u2, s)) return 0;
  if (s->delta) return 1;
  float pdf = bsdf_pdf(b, wo, s->wi);
  rgb f = bsdf_eval(b, wo, s->wi);
  if (!(pdf > 0) || !isfinite(pdf)) return 0;
  s->pdf = pdf;
  s->weight = c3_scale(f, fabsf(s->wi.z) / pdf);
  if (!c3_finite(s->weight)) { s->nonfinite = 1; return 0; }
  return 1;
}
