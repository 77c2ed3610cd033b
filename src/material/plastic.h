/* plastic.h — owns Mitsuba 3's plastic and roughplastic models (its `plastic` and
 * `roughplastic` plugins, in valo's terms): a diffuse base kd under a dielectric coat of
 * relative index eta, the coat's reflection tinted by ks. With F the coat's Fresnel
 * reflectance, T(cos) its transmittance and r_i the share of the base's diffuse light
 * that the coat sends back down:
 *   smooth: f = ks F(cos_o) delta(mirror) + kd' (1 - F(cos_o)) (1 - F(cos_i)) / (pi eta^2),
 *           r_i = the diffuse Fresnel reflectance seen from inside, int 2 mu F(mu, 1/eta) dmu;
 *   rough:  f = ks F(wo.h) D G / (4 cos_o cos_i) + kd' T(cos_o) T(cos_i) / (pi eta^2),
 *           T = the coat's single-scattering transmittance (the mean over visible normals
 *           of (1 - F) G1 of the refracted direction), r_i = Mitsuba's mean of 2 mu R(mu)
 *           over the table's cosines, R the coat's reflection albedo seen from inside
 *           (F G1 of the reflected direction, total internal reflection included);
 * kd' = kd / (1 - r_i), or kd / (1 - kd r_i) when `nonlinear` (the base's own colour
 * tints the light bouncing under the coat). plastic_prepare tabulates T at PLASTIC_RES
 * cosines k / (PLASTIC_RES - 1), as Mitsuba does, by a stratified quadrature of visible
 * normals per cosine (32 x 32 from outside, 48 x 48 from inside, where F jumps at the
 * critical angle: 15 ms for a GGX coat, 60 ms for a Beckmann one);
 * r_i of the smooth coat is integrated (Mitsuba uses a fitted formula, within 0.1 % of it).
 * The specular lobe uses valo's height-correlated Smith G (Mitsuba's is separable).
 * Sampling takes the specular lobe with probability F w / (F w + (1 - F)(1 - w)) (rough:
 * 1 - T(cos_o) for F), w = mean(ks) / (mean(kd) + mean(ks)), else a cosine-weighted
 * direction, as Mitsuba does. */
#ifndef VALO_PLASTIC_H
#define VALO_PLASTIC_H
#include "material/bsdf.h"

/* Fills m->coat_t and m->coat_ri from m->ior, m->roughness and m->beckmann: every
 * MAT_PLASTIC material needs it once its coat is set (the JSON loader calls it). */
void plastic_prepare(material *m);
rgb plastic_eval(const bsdf *b, vec3 wo, vec3 wi);
float plastic_pdf(const bsdf *b, vec3 wo, vec3 wi);
/* Fills s (wi, weight, pdf, delta); 0 when no direction was made. */
int plastic_sample(const bsdf *b, vec3 wo, float ulobe, float u1, float u2, bsdf_sample *s);
/* The coat's transmittance at cos theta (the table, linearly interpolated). */
float plastic_coat_t(const bsdf *b, float cos_t);
#endif
