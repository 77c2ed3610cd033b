/* gltf_material.c — owns the glTF material meanings valo reads beyond the core
 * metallic-roughness model (load_assimp.c): KHR_texture_transform on a texture, COLOR_0
 * (and a PLY's colours) as vertex colours, KHR_materials_ior and KHR_materials_specular
 * as the pbr model's Fresnel, KHR_materials_clearcoat as its coat, KHR_materials_sheen
 * as its sheen, KHR_materials_transmission with KHR_materials_volume. The
 * glTF BSDF is
 *   mix(metal, fresnel_mix(ior, mix(diffuse, specular BTDF, t), specular BRDF), metallic)
 * so with w = t (1 - metallic) it is exactly the blend of valo's pbr material at metallic
 * m' = metallic / (1 - w) with weight 1 - w and a glass with weight w: a dielectric of the
 * same ior and roughness when the volume extension gives a thickness (the mesh bounds the
 * glass, and its attenuation becomes an absorbing medium inside it), a thin dielectric
 * otherwise (glTF's thin-walled default), its transmission tinted by the base colour
 * factor. */
#include "load/gltf_material.h"
#include "load/assimp_material.h"
#include "core/error.h"
#include "image/texture.h"
#include "material/sheen.h"
#include "core/grow.h"
#include <assimp/material.h>
#include <assimp/scene.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TRY_ST(x) do { valo_status st_ = (x); if (st_) return st_; } while (0)

/* KHR_materials_volume's absorption: a medium of sigma_a = -ln(attenuationColor) /
 * attenuationDistance (no scattering), appended to s; -1 when the glass is clear. */
static valo_status volume_medium(scene *s, const struct aiMaterial *am, const char *where, int32_t *med, valo_error *err) {
  *med = -1;
  float dist = ai_float(am, AI_MATKEY_VOLUME_ATTENUATION_DISTANCE, INFINITY);
  struct aiColor4D ac;
  if (!(dist > 0) || !isfinite(dist) || aiGetMaterialColor(am, AI_MATKEY_VOLUME_ATTENUATION_COLOR, &ac) != aiReturn_SUCCESS) return VALO_OK;
  float c[3] = {ac.r, ac.g, ac.b}, sa[3];
  int any = 0;
  for (int k = 0; k < 3; k++) {
    float x = isfinite(c[k]) ? clampf(c[k], 1e-6f, 1) : 1;
    sa[k] = -logf(x) / dist;
    any |= sa[k] > 0;
  }
  if (!any) return VALO_OK;
  medium md;
  memset(&md, 0, sizeof md);
  md.sigma_a = c3(sa[0], sa[1], sa[2]);
  snprintf(md.name, sizeof md.name, "%.50s (volume)", where);
  medium *q = grow_for(s->media, s->nmedia, sizeof *q);
  if (!q) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  s->media = q;
  q[s->nmedia] = md;
  *med = (int32_t)s->nmedia++;
  return VALO_OK;
}

valo_status gltf_transmission(scene *s, const struct aiMaterial *am, int tex_trans, const char *where, material *m, int32_t *med, valo_error *err) {
  *med = -1;
  float t = ai_float(am, AI_MATKEY_TRANSMISSION_FACTOR, 0);
  if (!(t > 0)) return VALO_OK;
  if (t > 1) t = 1;
  if (!c3_black(m->emission)) {
    log_warning("%s: an emitting material's transmission is not read (it renders opaque)", where);
    return VALO_OK;
  }
  material glass = *m;
  float thick = ai_float(am, AI_MATKEY_VOLUME_THICKNESS_FACTOR, 0);
  glass.type = thick > 0 ? MAT_DIELECTRIC : MAT_THIN_DIELECTRIC;
  glass.transmittance = m->kd;
  glass.kd = c3(0, 0, 0);
  glass.metallic = 0;
  glass.tex_kd = -1;
  if (m->tex_kd >= 0) log_warning("%s: its base colour texture does not tint the light it transmits (its base colour factor does)", where);
  if (glass.type == MAT_THIN_DIELECTRIC && m->roughness > 0.0316f)
    log_warning("%s: thin-walled transmission (no KHR_materials_volume thickness) is rendered smooth, not at roughness %g", where, (double)m->roughness);
  if (glass.type == MAT_DIELECTRIC) TRY_ST(volume_medium(s, am, where, med, err));
  float w = t * (1 - clampf(m->metallic, 0, 1));
  if (w >= 1 && tex_trans < 0) { /* all glass, with the material's maps and opacity */
    *m = glass;
    return VALO_OK;
  }
  material opaque = *m, blend = material_default();
  opaque.metallic = w < 1 ? clampf(m->metallic / (1 - w), 0, 1) : 1;
  material *parts[2] = {&opaque, &glass};
  for (int k = 0; k < 2; k++) { /* the blend carries the maps that move the surface and its opacity; its parts neither */
    parts[k]->tex_normal = parts[k]->tex_bump = parts[k]->tex_alpha = -1;
    parts[k]->opacity = 1;
    parts[k]->alpha_stochastic = 0;
  }
  snprintf(opaque.name, sizeof opaque.name, "%.50s (opaque)", m->name);
  snprintf(glass.name, sizeof glass.name, "%.50s (glass)", m->name);
  uint32_t a = scene_add_material(s, &opaque), b = a == UINT32_MAX ? a : scene_add_material(s, &glass);
  if (b == UINT32_MAX) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  blend.type = MAT_BLEND;
  blend.blend[0] = (int)a;
  blend.blend[1] = (int)b;
  blend.weight = w;
  blend.tex_weight = tex_trans; /* glTF's transmission texture: its red channel times the factor */
  blend.tex_normal = m->tex_normal; blend.tex_bump = m->tex_bump; blend.bump_scale = m->bump_scale;
  blend.map_tangents = m->map_tangents;
  blend.tex_alpha = m->tex_alpha; blend.alpha_channel = m->alpha_channel; blend.alpha_cutoff = m->alpha_cutoff;
  blend.opacity = m->opacity; blend.alpha_stochastic = m->alpha_stochastic;
  memcpy(blend.name, m->name, sizeof blend.name);
  *m = blend;
  return VALO_OK;
}

int gltf_transformed(scene *s, const struct aiMaterial *am, int type, int t) { return gltf_slot_transformed(s, am, type, 0, t); }

int gltf_slot_transformed(scene *s, const struct aiMaterial *am, int type, unsigned idx, int t) {
  struct aiUVTransform x;
  unsigned int n = sizeof x / sizeof(ai_real);
  if (t < 0 || aiGetMaterialFloatArray(am, _AI_MATKEY_UVTRANSFORM_BASE, (unsigned)type, idx, (ai_real *)&x, &n) != aiReturn_SUCCESS ||
      n != sizeof x / sizeof(ai_real))
    return t;
  /* Assimp 5.2 stores glTF's transform turned about the image's centre, v turned over:
   * scale as given, rotation -r, and a translation it derives from the offset; undone here */
  double sx = x.mScaling.x, sy = x.mScaling.y, r = -x.mRotation, c = cos(r), sn = sin(r);
  double ox = x.mTranslation.x - 0.5 * sx * (-c + sn + 1), oy = 1 - sy + 0.5 * sy * (sn + c - 1) - x.mTranslation.y;
  /* glTF's uv' = offset + R (scale uv), R = [c s; -s c] in its v-down space (counter-clockwise
   * as the extension's own example and three.js read it), in valo's v-up coordinates: F M F */
  double a = c * sx, b = sn * sy, d = -sn * sx, e = c * sy;
  tex_sampling smp = s->tex[t].smp;
  smp.has_uvm = 1;
  const float uvm[6] = {(float)a, (float)-b, (float)(b + ox), (float)-d, (float)e, (float)(1 - e - oy)};
  memcpy(smp.uvm, uvm, sizeof smp.uvm);
  return scene_texture_sampled(s, t, &smp);
}

void mesh_vertex_colors(scene *s, const struct aiScene *ai, uint32_t mat_base) {
  for (unsigned i = 0; i < ai->mNumMeshes; i++)
    if (ai->mMeshes[i]->mColors[0] && ai->mMeshes[i]->mMaterialIndex < ai->mNumMaterials) {
      material *mt = &s->mats[mat_base + ai->mMeshes[i]->mMaterialIndex];
      mt->vertex_colors = 1;
      if (mt->type == MAT_BLEND) s->mats[mt->blend[0]].vertex_colors = s->mats[mt->blend[1]].vertex_colors = 1; /* hits see its parts */
    }
}

/* The glTF material Assimp's material am was made from, by its signature (obj_check.h):
 * its KHR_materials_specular values, or NULL when none matches or the ones that match
 * disagree on them. */
static const float *specular_of(const obj_check *oc, const struct aiMaterial *am, const char *where) {
  if (!oc || !oc->gmat) return NULL;
  struct aiString nm;
  if (aiGetMaterialString(am, AI_MATKEY_NAME, &nm) != aiReturn_SUCCESS) nm.data[0] = 0;
  struct aiColor4D base = {1, 1, 1, 1}, em = {0, 0, 0, 1};
  aiGetMaterialColor(am, AI_MATKEY_BASE_COLOR, &base);
  aiGetMaterialColor(am, AI_MATKEY_COLOR_EMISSIVE, &em);
  float sig[9] = {base.r, base.g, base.b, base.a, ai_float(am, AI_MATKEY_METALLIC_FACTOR, 1), ai_float(am, AI_MATKEY_ROUGHNESS_FACTOR, 1), em.r, em.g, em.b};
  const float *found = NULL;
  int ambiguous = 0;
  for (uint32_t i = 0; i < oc->ngmat; i++) {
    const gltf_mat *g = &oc->gmat[i];
    const float gs[9] = {g->base[0], g->base[1], g->base[2], g->base[3], g->metallic, g->roughness, g->emissive[0], g->emissive[1], g->emissive[2]};
    int same = !strcmp(g->name, nm.data);
    for (int k = 0; k < 9 && same; k++) same = fabsf(gs[k] - sig[k]) <= 1e-6f * fmaxf(1, fabsf(gs[k]));
    if (!same) continue;
    if (found && memcmp(found, g->specular, sizeof g->specular)) ambiguous = 1;
    found = g->specular;
  }
  if (ambiguous) log_warning("%s: glTF materials alike in all Assimp reads differ in KHR_materials_specular: it is not read for them", where);
  return ambiguous ? NULL : found;
}

void gltf_specular(const obj_check *oc, const struct aiMaterial *am, const char *where, material *m) {
  if (!(m->ior >= 1 && m->ior <= 10)) {
    log_warning("%s: KHR_materials_ior %g is read as 1.5 (valo takes 1 to 10)", where, (double)m->ior);
    m->ior = 1.5f;
  }
  const float *sp = specular_of(oc, am, where);
  material_pbr_specular(m, m->ior, sp ? sp[0] : 1, sp ? c3(sp[1], sp[2], sp[3]) : c3(1, 1, 1));
  /* KHR_materials_clearcoat, which Assimp reads: its factors, and its textures but the
   * normal map (load_assimp.c reads them) */
  m->clearcoat = clampf(ai_float(am, AI_MATKEY_CLEARCOAT_FACTOR, 0), 0, 1);
  m->clearcoat_roughness = clampf(ai_float(am, AI_MATKEY_CLEARCOAT_ROUGHNESS_FACTOR, 0), 0, 1);
  if (m->clearcoat > 0 && (aiGetMaterialTextureCount(am, aiTextureType_CLEARCOAT) > 2))
    log_warning("%s: KHR_materials_clearcoat's normal texture is not read (the coat follows the base's normal)", where);
  /* KHR_materials_sheen, which Assimp reads: its factors and its colour texture (load_assimp.c);
   * its roughness texture is not read (the sheen's albedo table is made for one roughness) */
  struct aiColor4D sc;
  if (aiGetMaterialColor(am, AI_MATKEY_SHEEN_COLOR_FACTOR, &sc) == aiReturn_SUCCESS)
    m->sheen_color = c3(clampf(sc.r, 0, 1), clampf(sc.g, 0, 1), clampf(sc.b, 0, 1));
  m->sheen_roughness = clampf(ai_float(am, AI_MATKEY_SHEEN_ROUGHNESS_FACTOR, 0), 0, 1);
  if (c3_max(m->sheen_color) > 0) {
    sheen_prepare(m);
    if (aiGetMaterialTextureCount(am, aiTextureType_SHEEN) > 1) log_warning("%s: KHR_materials_sheen's roughness texture is not read (its factor is)", where);
  }
}
