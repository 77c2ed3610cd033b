/* bsdf.h — owns the BSDF interface: a tagged union held by value, with eval / sample /
 * pdf dispatched by one switch each (no default: -Wswitch names a forgotten case).
 * Directions are in the local shading frame (z = shading normal), both pointing away
 * from the surface. Opaque BSDFs expect wo.z > 0 (the integrator faces the frame
 * towards wo); the dielectric uses the sign of wo.z for inside/outside. */
#ifndef VALO_BSDF_H
#define VALO_BSDF_H
#include "core/vec.h"
#include "scene/scene.h"

typedef enum bsdf_type {
  BSDF_DIFFUSE, BSDF_PHONG, BSDF_MIRROR, BSDF_DIELECTRIC, BSDF_CONDUCTOR,
  BSDF_ROUGH_CONDUCTOR, BSDF_ROUGH_DIELECTRIC, BSDF_PBR, BSDF_THIN_DIELECTRIC,
  BSDF_PLASTIC, BSDF_ROUGH_PLASTIC, /* material/plastic.h */
  BSDF_PRINCIPLED /* material/principled.h */
} bsdf_type;

typedef struct bsdf {
  bsdf_type type;
  rgb kd, ks;
  float exponent;
  float eta;          /* dielectric: interior index / exterior index */
  rgb cond_eta, cond_k, cond_tint;
  rgb trans;          /* dielectrics: the tint of what they transmit (material.transmittance) */
  int fresnel_white;  /* conductors: F = 1, the caller applies F per wavelength (--spectral) */
  float p_first;      /* probability of the first lobe (diffuse) in mixtures */
  float alpha;        /* GGX roughness (rough types); along the frame's s axis when anisotropic */
  float alpha_v;      /* rough conductor and dielectric, principled: the roughness along t (alpha when isotropic) */
  float metallic;     /* BSDF_PBR */
  rgb f0;             /* BSDF_PBR: the dielectric's Fresnel at normal and grazing incidence */
  float f90;
  int beckmann;       /* rough conductor and dielectric: the Beckmann distribution, not GGX */
  int separable;      /* rough conductor, dielectric, plastic: Smith's separable G (Mitsuba's), not the height-correlated one */
  int metal_flat;     /* BSDF_PBR: the metal reflects kd at every angle (MTL illum 3), not Schlick */
  int nonlinear;      /* plastics: material.nonlinear */
  float spec_w;       /* plastics: the specular lobe's sampling weight, mean(ks) / (mean(kd) + mean(ks)) */
  float coat_ri;       /* plastics: the coat's tables (coat_t: PLASTIC_RES values, the material's own, */
  const float *coat_t; /* which must outlive the BSDF, as sh_E) */
  float roughness, spec_tint, sheen, sheen_tint, flatness, clearcoat, cc_alpha, spec_trans; /* BSDF_PRINCIPLED (kd, metallic, alpha, eta too) */
  const float *sh_E;  /* BSDF_PBR with a sheen (material/sheen.h): the material's albedo table, else NULL
                         (it points into the material given to bsdf_from_material, which must outlive it) */
  rgb sh_color;       /* and its colour, alpha and max(colour) */
  float sh_alpha, sh_max;
  int mapped;         /* the frame's normal is a normal or bump map's under Mitsuba's conventions
                         (material.map_tangents 0): set by shading_frame, with */
  vec3 n0;            /* the surface's own shading normal in the frame (bsdf.c, "mapped normals") */
  struct bsdf *mix;   /* a blend's second BSDF (shading.h, bsdf_at_blend), else NULL: this BSDF is then */
  float mix_w;        /* (1 - mix_w) this one's model + mix_w mix's, in eval, pdf and sampling */
} bsdf;

typedef struct bsdf_sample {
  vec3 wi;
  rgb weight;         /* f * |cos| / pdf */
  float pdf;          /* solid-angle pdf (of the whole mixture); 0 for a delta lobe */
  int delta;          /* sampled a specular (Dirac) lobe */
  float eta_scale;    /* radiance scale across refraction (1 otherwise) */
  int nonfinite;      /* set when no sample was made because its pdf or weight was NaN
                         or infinite (valo_stats counts these: VALO_LOSS_BSDF_NONFINITE) */
} bsdf_sample;

bsdf bsdf_from_material(const material *m);
/* With b->mix, each of the three below is that of the blend (1 - w) f_b + w f_mix: eval
 * and pdf the weighted sums; sampling picks one of the two with its weight (from ulobe,
 * rescaled for the lobe choice that follows), and a non-delta direction gets the blend's
 * pdf and f |cos| / pdf (a delta lobe keeps its own weight: the pick's probability
 * cancels). So next-event estimation sees both, as Mitsuba's blendbsdf. */
/* Non-delta part of f(wo, wi); with b->mapped, 0 where wi lies on different sides of the
 * mapped and the surface's own normal, else times the shadowing term for mapped normals
 * (the pdf and the samples likewise). */
rgb bsdf_eval(const bsdf *b, vec3 wo, vec3 wi);
/* Density of bsdf_sample producing wi through a non-delta lobe. */
float bsdf_pdf(const bsdf *b, vec3 wo, vec3 wi);
/* Samples wi; returns 0 when no direction was produced (the path ends). */
int bsdf_sample_dir(const bsdf *b, vec3 wo, float ulobe, float u1, float u2, bsdf_sample *s);
/* 1 if the BSDF has any non-delta lobe (so light sampling can help). */
int bsdf_has_smooth(const bsdf *b);
/* The colour a denoiser calls albedo: kd + ks for opaque models, the Fresnel
 * reflectance at cos_o for conductors, white for glass. */
rgb material_albedo(const material *m, float cos_o);
/* 1 if the BSDF's roughness differs along the frame's s and t (so the frame follows the
 * surface's u direction). */
static inline int bsdf_anisotropic(const bsdf *b) {
  return (b->type == BSDF_ROUGH_CONDUCTOR || b->type == BSDF_ROUGH_DIELECTRIC || b->type == BSDF_PRINCIPLED) && b->alpha != b->alpha_v;
}
/* 1 if the BSDF transmits (so the shading frame must not be flipped to wo). */
static inline int bsdf_transmits(const bsdf *b) {
  return b->type == BSDF_DIELECTRIC || b->type == BSDF_ROUGH_DIELECTRIC || b->type == BSDF_THIN_DIELECTRIC ||
         (b->type == BSDF_PRINCIPLED && b->spec_trans > 0);
}
#endif
