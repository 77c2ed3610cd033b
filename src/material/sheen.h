/* sheen.h — owns the glTF sheen layer (KHR_materials_sheen) of the pbr model: Conty
 * Estevez and Kulla's "Charlie" fibre distribution D(h) = (2 + 1/a) sin(h)^(1/a) / (2 pi)
 * with their visibility 1 / ((1 + L(n.v) + L(n.l)) 4 n.v n.l), a = the sheen roughness
 * clamped to [0.07, 1] (1/a past 14 overflows nothing, as glTF's sample viewer clamps), and
 * the layer's directional albedo E(cos) that scales the base below it (glTF's albedo
 * scaling: f = colour D V + f_base min(1 - max(colour) E(n.v), 1 - max(colour) E(n.l))). */
#ifndef VALO_SHEEN_H
#define VALO_SHEEN_H
#include "scene/scene.h"

/* The sheen alpha of a roughness (clamped to [0.07, 1]). */
float sheen_alpha(float roughness);
/* D(h) V(o, i) for cosines cos_o, cos_i > 0 and cos_h of the half vector. */
float sheen_eval(float alpha, float cos_o, float cos_i, float cos_h);
/* Fills m->sheen_E from m->sheen_roughness (every MAT_PBR material with a sheen colour
 * needs it; both loaders call it): E integrated over the hemisphere (midpoint rule,
 * 64 x 128 directions per cosine). */
void sheen_prepare(material *m);
/* E(cos) from the table, linearly interpolated. */
float sheen_albedo(const float *E, float cos_t);
#endif
