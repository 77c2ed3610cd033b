/* plastic.c — see plastic.h. */
#include "material/plastic.h"
#include "material/fresnel.h"
#include "material/microfacet.h"
#include "core/sampling.h"

#define COAT_N_OUT 32 /* stratified visible-normal samples per axis, per cos theta, from outside */
#define COAT_N_IN 48  /* from inside: r_i within 0.002 of its value at 256 x 256 (roughness 0.1 to 0.9, index 1.49), 1 / (1 - r_i) within 0.43 % */

static float mf_G1(int beck, float a, vec3 w) { return beck ? 1 / (1 + beckmann_lambda(a, w)) : ggx_G1(a, w); }

/* What the coat's rough interface (relative index eta) does with light arriving from
 * cos theta mu, as Mitsuba defines it for its plastic: the mean over visible normals of
 * F G1(reflected direction) (reflect = 1) or (1 - F) G1(refracted direction), the weights
 * f |cos| / pdf of single scattering under the separable Smith G = G1(in) G1(out). */
static double coat_scatter(int beck, float a, float eta, float mu, int reflect, int n) {
  vec3 wo = v3(sqrtf(fmaxf(0.0f, 1 - mu * mu)), 0, mu);
  double sum = 0;
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      vec3 wm = mf_sample(beck, a, wo, (i + 0.5f) / n, (j + 0.5f) / n), wi;
      float c = v3_dot(wo, wm), F = fresnel_dielectric(c, eta);
      if (!(c > 0)) continue;
      if (reflect) {
        wi = v3_reflect(wo, wm);
        if (wi.z > 0) sum += (double)F * mf_G1(beck, a, wi);
      } else if (F < 1 && refract_dir(wo, wm, eta, &wi) && wi.z < 0) {
        sum += (double)(1 - F) * mf_G1(beck, a, wi);
      }
    }
  return sum / ((double)n * n);
}

static int plastic_rough(const material *m) { return m->roughness * m->roughness >= 1e-3f; }

void plastic_prepare(material *m) {
  float eta = m->ior, a = m->roughness * m->roughness;
  int rough = plastic_rough(m);
  double ri = 0;
  for (int k = 0; k < PLASTIC_RES; k++) {
    float mu = fmaxf(1e-6f, (float)k / (PLASTIC_RES - 1));
    m->coat_t[k] = (float)(rough ? coat_scatter(m->beckmann, a, eta, mu, 0, COAT_N_OUT) : 1 - fresnel_dielectric(mu, eta));
    /* Mitsuba's sum for r_i: the mean of 2 mu R(mu) over these cosines */
    if (rough) ri += 2.0 * mu * coat_scatter(m->beckmann, a, 1 / eta, mu, 1, COAT_N_IN) / PLASTIC_RES;
  }
  if (!rough) /* int_0^1 2 mu F(mu, 1/eta) dmu by the midpoint rule */
    for (int k = 0; k < 4096; k++) {
      float mu = (k + 0.5f) / 4096;
      ri += 2.0 * mu * fresnel_dielectric(mu, 1 / eta) / 4096;
    }
  m->coat_ri = (float)ri;
}

float plastic_coat_t(const bsdf *b, float cos_t) {
  float x = clampf(cos_t, 0, 1) * (PLASTIC_RES - 1);
  int i = (int)x;
  if (i > PLASTIC_RES - 2) i = PLASTIC_RES - 2;
  float w = x - (float)i;
  return (1 - w) * b->coat_t[i] + w * b->coat_t[i + 1];
}

/* kd' of plastic.h, per channel */
static rgb base_albedo(const bsdf *b) {
  rgb d = b->kd;
  float ri = b->coat_ri;
  return b->nonlinear ? c3(d.r / (1 - d.r * ri), d.g / (1 - d.g * ri), d.b / (1 - d.b * ri)) : c3_scale(d, 1 / (1 - ri));
}

/* The specular lobe's probability; *coat is the coat's share of wo's light (F or 1 - T). */
static float spec_prob(const bsdf *b, vec3 wo, float *coat) {
  float f = *coat = b->type == BSDF_PLASTIC ? fresnel_dielectric(wo.z, b->eta) : 1 - plastic_coat_t(b, wo.z);
  float ps = f * b->spec_w, pd = (1 - f) * (1 - b->spec_w);
  return ps + pd > 0 ? ps / (ps + pd) : 0;
}

rgb plastic_eval(const bsdf *b, vec3 wo, vec3 wi) {
  if (wo.z <= 0 || wi.z <= 0) return c3(0, 0, 0);
  float inv_eta2 = 1 / (b->eta * b->eta), to, ti;
  if (b->type == BSDF_PLASTIC) {
    to = 1 - fresnel_dielectric(wo.z, b->eta);
    ti = 1 - fresnel_dielectric(wi.z, b->eta);
  } else {
    to = plastic_coat_t(b, wo.z);
    ti = plastic_coat_t(b, wi.z);
  }
  rgb f = c3_scale(base_albedo(b), to * ti * inv_eta2 * INV_PI_F);
  if (b->type == BSDF_ROUGH_PLASTIC) {
    vec3 wm = v3_norm(v3_add(wo, wi));
    float s = fresnel_dielectric(v3_dot(wo, wm), b->eta) * mf_D(b->beckmann, b->alpha, wm) *
              mf_G(b->beckmann, b->separable, b->alpha, wo, wi) / (4 * wo.z * wi.z);
    f = c3_add(f, c3_scale(b->ks, s));
  }
  return f;
}

float plastic_pdf(const bsdf *b, vec3 wo, vec3 wi) {
  if (wo.z <= 0 || wi.z <= 0) return 0;
  float coat, ps = spec_prob(b, wo, &coat), p = (1 - ps) * cosine_hemisphere_pdf(wi.z);
  if (b->type == BSDF_ROUGH_PLASTIC) {
    vec3 wm = v3_norm(v3_add(wo, wi));
    p += ps * mf_pdf_m(b->beckmann, b->alpha, wo, wm) / (4 * fabsf(v3_dot(wo, wm)));
  }
  return p;
}

int plastic_sample(const bsdf *b, vec3 wo, float ulobe, float u1, float u2, bsdf_sample *s) {
  if (wo.z <= 0) return 0;
  float coat, ps = spec_prob(b, wo, &coat);
  if (ulobe < ps) {
    if (b->type == BSDF_PLASTIC) {
      s->wi = v3(-wo.x, -wo.y, wo.z);
      s->weight = c3_scale(b->ks, coat / ps); /* coat = F(cos_o) here */
      s->pdf = 0;
      s->delta = 1;
      return 1;
    }
    s->wi = v3_reflect(wo, mf_sample(b->beckmann, b->alpha, wo, u1, u2));
  } else {
    s->wi = sample_cosine_hemisphere(u1, u2);
  }
  if (s->wi.z <= 0) return 0;
  s->pdf = plastic_pdf(b, wo, s->wi);
  s->weight = c3_scale(plastic_eval(b, wo, s->wi), s->wi.z / s->pdf);
  return 1;
}
