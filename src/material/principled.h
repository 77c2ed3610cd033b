/* principled.h — owns Mitsuba 3's `principled` BSDF in valo's terms (Burley's Disney
 * BSDF as Mitsuba defines it): with v the viewer (valo's wo), l the
 * light (wi), h = normalize(v + l), base colour c, metallic m, spec_tint st and
 *   specular:  F(v.h) D(h) G1(v) G1(l) / (4 cos_v cos_l), GGX of alpha = max(1e-3,
 *              roughness^2), separable Smith G1, F = (1 - m)(1 - st) F_dielectric(eta)
 *              + m Schlick(c) + (1 - m) st Schlick(c / lum(c) R0(eta));
 *   diffuse:   (1 - m) c / pi ((1 - Fv/2)(1 - Fl/2) + retro), Fx = (1 - cos_x)^5,
 *              retro = Rr (Fl + Fv + Fl Fv (Rr - 1)), Rr = 2 roughness (h.l)^2, blended
 *              towards Hanrahan-Krueger's flat response 1.25 (Fss (1 / (cos_l + cos_v)
 *              - 1/2) + 1/2) by `flatness`;
 *   sheen:     sheen (1 - m) (1 - h.l)^5 lerp(1, c / lum(c), sheen_tint) (no 1/pi, as
 *              Mitsuba's), where the diffuse lobe is;
 *   clearcoat: clearcoat / 4 Schlick(0.04) D_GTR1(h) G1(v) G1(l) of alpha 0.25 (no
 *              1 / (4 cos_v cos_l), as Mitsuba's), GTR1 of alpha lerp(0.1, 0.001, gloss);
 *   transmission (weight t = spec_trans): sqrt(c) (1 - m) t times a rough dielectric's
 *              BTDF (radiance; the same D and separable G); the opaque lobes above are
 *              weighted by (1 - t) (diffuse) and seen from outside only; from inside the
 *              surface is a rough dielectric of reflectance (1 - m) t F.
 * eta is the interior / exterior index (JSON "ior"; Mitsuba's `specular` s gives
 * eta = 2 / (1 - sqrt(0.08 s)) - 1). `anisotropic` a stretches the specular and transmissive
 * lobes' GGX as Mitsuba does: alpha / aspect along the surface's u direction, alpha *
 * aspect across it, aspect = sqrt(1 - 0.9 a) (both at least 0.001).
 * Sampling, as Mitsuba's: a cosine-weighted direction, GTR1 normals or GGX visible
 * normals with probabilities in proportion to (1 - m)(1 - t), clearcoat / 4 and 1; a
 * visible normal of Fresnel term F reflects with probability 1 - (1 - m) t (1 - F), else
 * refracts (from inside: F and 1 - F). */
#ifndef VALO_PRINCIPLED_H
#define VALO_PRINCIPLED_H
#include "material/bsdf.h"

rgb principled_eval(const bsdf *b, vec3 wo, vec3 wi);
float principled_pdf(const bsdf *b, vec3 wo, vec3 wi);
/* Fills s (wi, weight, pdf); 0 when no direction was made. */
int principled_sample(const bsdf *b, vec3 wo, float ulobe, float u1, float u2, bsdf_sample *s);
#endif
