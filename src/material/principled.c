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

static rgb tint_of(rgb c) {
  float l = c3_lum_mitsuba(c);
  return l > 0 ? c3_scale(c, 1 / l) : c3(1, 1, 1);
}

/* GTR1 (Burley's clearcoat distribution), normalised over projected area */
static float gtr1_D(float a, float cos_h) {
  float a2 = a * a, r = (a2 - 1) / (PI_F * logf(a2) * (1 + (a2 - 1) * cos_h * cos_h));
  return r * cos_h > 1e-20f ? r : 0;
}

/* GGX's separable-Smith G1 of alphas (ax, ay), 0 where w sees the back of the normal m */
static float g1_sep(float ax, float ay, vec3 w, vec3 m) {
  if (v3_dot(w, m) * w.z <= 0) return 0;
  if (fabsf(w.z) >= 1) return 1;
  return ax == ay ? ggx_G1(ax, w) : 1 / (1 + mfa_lambda(0, ax, ay, w));
}

/* The weights of the opaque lobes (1 - m)(1 - t) and of the transmissive one (1 - m) t. */
static float w_brdf(const bsdf *b) { return (1 - b->metallic) * (1 - b->spec_trans); }
static float w_bsdf(const bsdf *b) { return (1 - b->metallic) * b->spec_trans; }

/* The half vector of (wo, wi) facing +z, and the relative index across it (1 for a
 * reflection); 0 when they cannot be joined by a microfacet of that side. */
static int half_of(const bsdf *b, vec3 wo, vec3 wi, vec3 *h, float *etap) {
  int reflect = wo.z * wi.z > 0;
  *etap = reflect ? 1 : (wo.z > 0 ? b->eta : 1 / b->eta);
  vec3 m = v3_add(wo, v3_scale(wi, *etap));
  if (wo.z == 0 || wi.z == 0 || !(v3_len2(m) > 0)) return 0;
  m = v3_norm(m);
  if (m.z < 0) m = v3_neg(m);
  float s = wo.z > 0 ? 1.0f : -1.0f; /* the microfacet turned to wo's side */
  if (!(v3_dot(wo, m) * s > 0)) return 0;
  if (reflect ? !(v3_dot(wi, m) * s > 0) : !(v3_dot(wi, m) * s < 0)) return 0;
  *h = m;
  return 1;
}

rgb principled_eval(const bsdf *b, vec3 wo, vec3 wi) {
  vec3 h;
  float etap;
  if (!half_of(b, wo, wi, &h, &etap)) return c3(0, 0, 0);
  int front = wo.z > 0;
  float vh = v3_dot(wo, h), lh = v3_dot(wi, h);
  float fd = fresnel_dielectric(vh, b->eta);
  float D = mfa_D(0, b->alpha, b->alpha_v, h), G = g1_sep(b->alpha, b->alpha_v, wo, h) * g1_sep(b->alpha, b->alpha_v, wi, h);
  rgb c = b->kd, f = c3(0, 0, 0);
  if (etap != 1) { /* transmission: sqrt(c) (1 - m) t times a rough dielectric's (radiance) */
    if (!(w_bsdf(b) > 0) || !(fd < 1)) return f;
    float den = vh + etap * lh;
    float v = w_bsdf(b) * (1 - fd) * D * G * fabsf(vh * lh) / (den * den * fabsf(wo.z * wi.z));
    return c3(sqrtf(c.r) * v, sqrtf(c.g) * v, sqrtf(c.b) * v);
  }
  float m = b->metallic, st = b->spec_tint;
  /* specular: from inside, only the dielectric's own Fresnel, weighted by (1 - m) t */
  rgb F;
  if (!front) {
    F = c3_scale(c3(1, 1, 1), w_bsdf(b) * fd);
  } else {
    F = c3_scale(c3(1, 1, 1), (1 - m) * (1 - st) * fd);
    if (m > 0) F = c3_add(F, c3_scale(c3(schlick(c.r, vh, b->eta), schlick(c.g, vh, b->eta), schlick(c.b, vh, b->eta)), m));
    if (st > 0) {
      float r0 = (b->eta - 1) / (b->eta + 1);
      rgb t = c3_scale(tint_of(c), r0 * r0);
      F = c3_add(F, c3_scale(c3(schlick(t.r, vh, b->eta), schlick(t.g, vh, b->eta), schlick(t.b, vh, b->eta)), (1 - m) * st));
    }
  }
  f = c3_add(f, c3_scale(F, D * G / fabsf(4 * wo.z * wi.z)));
  if (!front) return f;
  /* clearcoat */
  if (b->clearcoat > 0) {
    float Fcc = schlick(0.04f, vh, b->eta);
    float g = g1_sep(0.25f, 0.25f, wo, h) * g1_sep(0.25f, 0.25f, wi, h);
    f = c3_add(f, c3_scale(c3(1, 1, 1), 0.25f * b->clearcoat * Fcc * gtr1_D(b->cc_alpha, h.z) * g));
  }
  /* diffuse, retro-reflection, flatness, sheen */
  float brdf = w_brdf(b);
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
      f = c3_add(f, c3_scale(cs, b->sheen * (1 - m) * schlick_w(lh)));
    }
  }
  return f;
}

/* The lobes' sampling probabilities from wo's side: diffuse, clearcoat, specular (which
 * then reflects or transmits by the microfacet's Fresnel term); from inside, only the
 * specular lobe. */
static void lobe_probs(const bsdf *b, int front, float p[3]) {
  p[0] = front ? w_brdf(b) : 0;
  p[1] = front ? 0.25f * b->clearcoat : 0;
  p[2] = 1;
  float s = p[0] + p[1] + p[2];
  for (int k = 0; k < 3; k++) p[k] /= s;
}

/* The share of the specular lobe's samples at microfacet F that reflect. */
static float reflect_share(const bsdf *b, int front, float F) {
  float t = w_bsdf(b);
  if (!front) return t > 0 ? F : 1;
  return 1 - t * (1 - F);
}

float principled_pdf(const bsdf *b, vec3 wo, vec3 wi) {
  vec3 h;
  float etap;
  if (!half_of(b, wo, wi, &h, &etap)) return 0;
  int front = wo.z > 0;
  if (!front && !(w_bsdf(b) > 0)) return 0;
  float p[3];
  lobe_probs(b, front, p);
  vec3 v = front ? wo : v3_neg(wo); /* visible normals are sampled from wo's side */
  float vh = v3_dot(wo, h), pm = mfa_pdf_m(0, b->alpha, b->alpha_v, v, h);
  float rs = reflect_share(b, front, fresnel_dielectric(vh, b->eta));
  if (etap != 1) {
    float den = vh + etap * v3_dot(wi, h);
    return p[2] * (1 - rs) * pm * etap * etap * fabsf(v3_dot(wi, h)) / (den * den);
  }
  float pdf = p[2] * rs * pm / (4 * fabsf(vh));
  if (!front) return pdf;
  pdf += p[0] * cosine_hemisphere_pdf(wi.z);
  if (p[1] > 0) pdf += p[1] * gtr1_D(b->cc_alpha, h.z) * h.z / (4 * vh);
  return pdf;
}

int principled_sample(const bsdf *b, vec3 wo, float ulobe, float u1, float u2, bsdf_sample *s) {
  if (wo.z == 0) return 0;
  int front = wo.z > 0;
  if (!front && !(w_bsdf(b) > 0)) return 0;
  float p[3];
  lobe_probs(b, front, p);
  if (ulobe < p[0]) {
    s->wi = sample_cosine_hemisphere(u1, u2);
  } else if (ulobe < p[0] + p[1]) { /* GTR1 normals: cos^2 = (1 - a^(2 (1 - u))) / (1 - a^2) */
    float a2 = b->cc_alpha * b->cc_alpha, c2 = (1 - powf(a2, 1 - u2)) / (1 - a2);
    float ct = safe_sqrt(c2), st = safe_sqrt(1 - c2), phi = 2 * PI_F * u1;
    s->wi = v3_reflect(wo, v3(st * cosf(phi), st * sinf(phi), ct));
    if (s->wi.z <= 0) return 0; /* the reflection lobes are counted only above */
  } else {
    vec3 v = front ? wo : v3_neg(wo);
    vec3 m = mfa_sample(0, b->alpha, b->alpha_v, v, u1, u2); /* facing v */
    float ur = (ulobe - p[0] - p[1]) / p[2];
    if (ur < reflect_share(b, front, fresnel_dielectric(v3_dot(wo, m), b->eta))) {
      s->wi = v3_reflect(wo, m);
      if (s->wi.z * wo.z <= 0) return 0;
    } else {
      float etap = front ? b->eta : 1 / b->eta;
      if (!refract_dir(wo, front ? m : v3_neg(m), etap, &s->wi) || s->wi.z * wo.z >= 0) return 0;
      s->eta_scale = 1 / (etap * etap);
    }
  }
  s->pdf = principled_pdf(b, wo, s->wi);
  if (!(s->pdf > 0)) return 0;
  s->weight = c3_scale(principled_eval(b, wo, s->wi), fabsf(s->wi.z) / s->pdf);
  return 1;
}
