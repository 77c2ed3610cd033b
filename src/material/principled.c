/* principled.c — see principled.h. */
#include "material/principled.h"
#include "material/fresnel.h"
#include "material/microfacet.h"
#include "core/sampling.h"

/* (1 - cos)^5 */
static float schlick_w(float c) {
  float m = clampf(1 - c, 0, 1);
  return m * m * m * m * m;
}

/* Schlick's approximation of reflectance r0 at cos_i (of the microfacet); past the
 * critical side (eta < 1 seen from outside) at the refracted cosine, as Mitsuba's. */
static float schlick(float r0, float cos_i, float eta) {
  float eta_it = cos_i >= 0 ? eta : 1 / eta;
  if (eta_it > 1) return r0 + (1 - r0) * schlick_w(fabsf(cos_i));
  float c2 = 1 - (1 - cos_i * cos_i) * eta_it * eta_it; /* eta_ti = 1 / eta_it */
  return r0 + (1 - r0) * schlick_w(safe_sqrt(c2));
}

/* Mitsuba's luminance of a linear sRGB colour */
static float lum_of(rgb c) { return 0.212671f * c.r + 0.715160f * c.g + 0.072169f * c.b; }

static rgb tint_of(rgb c) {
  float l = lum_of(c);
  return l > 0 ? c3_scale(c, 1 / l) : c3(1, 1, 1);
}

/* GTR1 (Burley's clearcoat distribution), normalised over projected area */
static float gtr1_D(float a, float cos_h) {
  float a2 = a * a, r = (a2 - 1) / (PI_F * logf(a2) * (1 + (a2 - 1) * cos_h * cos_h));
  return r * cos_h > 1e-20f ? r : 0;
}

/* GGX's separable-Smith G1 of alpha a, 0 where w sees the back of the normal m */
static float g1_sep(float a, vec3 w, vec3 m) { return v3_dot(w, m) * w.z <= 0 ? 0 : (w.z >= 1 ? 1 : ggx_G1(a, w)); }

rgb principled_eval(const bsdf *b, vec3 wo, vec3 wi) {
  if (wo.z <= 0 || wi.z <= 0) return c3(0, 0, 0);
  vec3 h = v3_norm(v3_add(wo, wi));
  float vh = v3_dot(wo, h), lh = v3_dot(wi, h);
  if (!(vh > 0 && lh > 0)) return c3(0, 0, 0);
  rgb c = b->kd, f = c3(0, 0, 0);
  float m = b->metallic, st = b->spec_tint;
  /* specular */
  float fd = fresnel_dielectric(vh, b->eta);
  rgb F = c3_scale(c3(1, 1, 1), (1 - m) * (1 - st) * fd);
  if (m > 0) F = c3_add(F, c3_scale(c3(schlick(c.r, vh, b->eta), schlick(c.g, vh, b->eta), schlick(c.b, vh, b->eta)), m));
  if (st > 0) {
    float r0 = (b->eta - 1) / (b->eta + 1);
    rgb t = c3_scale(tint_of(c), r0 * r0);
    F = c3_add(F, c3_scale(c3(schlick(t.r, vh, b->eta), schlick(t.g, vh, b->eta), schlick(t.b, vh, b->eta)), (1 - m) * st));
  }
  float dg = ggx_D(b->alpha, h) * g1_sep(b->alpha, wo, h) * g1_sep(b->alpha, wi, h) / (4 * wo.z * wi.z);
  f = c3_add(f, c3_scale(F, dg));
  /* clearcoat */
  if (b->clearcoat > 0) {
    float Fcc = schlick(0.04f, vh, b->eta);
    float g = g1_sep(0.25f, wo, h) * g1_sep(0.25f, wi, h);
    f = c3_add(f, c3_scale(c3(1, 1, 1), 0.25f * b->clearcoat * Fcc * gtr1_D(b->cc_alpha, h.z) * g));
  }
  /* diffuse, retro-reflection, flatness, sheen */
  float brdf = 1 - m;
  if (brdf > 0) {
    float Fl = schlick_w(wi.z), Fv = schlick_w(wo.z);
    float f_diff = (1 - 0.5f * Fv) * (1 - 0.5f * Fl);
    float Rr = 2 * b->roughness * lh * lh;
    float d = f_diff + Rr * (Fl + Fv + Fl * Fv * (Rr - 1));
    if (b->flatness > 0) {
      float fss90 = Rr / 2, fss = (1 + (fss90 - 1) * Fl) * (1 + (fss90 - 1) * Fv);
      float f_ss = 1.25f * (fss * (1 / (wi.z + wo.z) - 0.5f) + 0.5f);
      d += (f_ss - d) * b->flatness;
    }
    f = c3_add(f, c3_scale(c, brdf * INV_PI_F * d));
    if (b->sheen > 0) {
      rgb t = tint_of(c), cs = c3(1 + (t.r - 1) * b->sheen_tint, 1 + (t.g - 1) * b->sheen_tint, 1 + (t.b - 1) * b->sheen_tint);
      f = c3_add(f, c3_scale(cs, b->sheen * brdf * schlick_w(lh)));
    }
  }
  return f;
}

/* the lobes' sampling probabilities: diffuse, specular, clearcoat */
static void lobe_probs(const bsdf *b, float p[3]) {
  p[0] = 1 - b->metallic;
  p[1] = 1;
  p[2] = 0.25f * b->clearcoat;
  float s = p[0] + p[1] + p[2];
  for (int k = 0; k < 3; k++) p[k] /= s;
}

float principled_pdf(const bsdf *b, vec3 wo, vec3 wi) {
  if (wo.z <= 0 || wi.z <= 0) return 0;
  float p[3];
  lobe_probs(b, p);
  vec3 h = v3_norm(v3_add(wo, wi));
  float vh = v3_dot(wo, h);
  if (!(vh > 0)) return 0;
  float pdf = p[0] * cosine_hemisphere_pdf(wi.z) + p[1] * ggx_D_visible(b->alpha, wo, h) / (4 * vh);
  if (p[2] > 0) pdf += p[2] * gtr1_D(b->cc_alpha, h.z) * h.z / (4 * vh);
  return pdf;
}

int principled_sample(const bsdf *b, vec3 wo, float ulobe, float u1, float u2, bsdf_sample *s) {
  if (wo.z <= 0) return 0;
  float p[3];
  lobe_probs(b, p);
  if (ulobe < p[0]) {
    s->wi = sample_cosine_hemisphere(u1, u2);
  } else if (ulobe < p[0] + p[1]) {
    s->wi = v3_reflect(wo, ggx_sample_visible(b->alpha, wo, u1, u2));
  } else { /* GTR1 normals: cos^2 = (1 - a^(2 (1 - u))) / (1 - a^2) */
    float a2 = b->cc_alpha * b->cc_alpha, c2 = (1 - powf(a2, 1 - u2)) / (1 - a2);
    float ct = safe_sqrt(c2), st = safe_sqrt(1 - c2), phi = 2 * PI_F * u1;
    s->wi = v3_reflect(wo, v3(st * cosf(phi), st * sinf(phi), ct));
  }
  if (s->wi.z <= 0) return 0;
  s->pdf = principled_pdf(b, wo, s->wi);
  if (!(s->pdf > 0)) return 0;
  s->weight = c3_scale(principled_eval(b, wo, s->wi), s->wi.z / s->pdf);
  return 1;
}
