/* gltf_material.h — owns the glTF material meanings read on top of Assimp's import
 * (gltf_material.c says how). */
#ifndef VALO_GLTF_MATERIAL_H
#define VALO_GLTF_MATERIAL_H
#include "scene/scene.h"
#include "load/obj_check.h"
struct aiMaterial;
struct aiScene;

/* Texture t of glTF material am's slot of Assimp texture type `type` as its
 * KHR_texture_transform samples it (Assimp keeps it per slot): a texture sharing t's
 * pixels; t itself when there is none (or t < 0). */
int gltf_transformed(scene *s, const struct aiMaterial *am, int type, int t);
/* The same for the idx-th texture of that slot type (KHR_materials_clearcoat's second,
 * its roughness, say). */
int gltf_slot_transformed(scene *s, const struct aiMaterial *am, int type, unsigned idx, int t);
/* The materials (from mat_base, the file's first) of ai's meshes that have vertex colours
 * take vertex_colors, a blend's two parts too: glTF's COLOR_0 multiplies the base colour,
 * and a PLY (no materials: Assimp's default one) is seen in its colours. */
void mesh_vertex_colors(scene *s, const struct aiScene *ai, uint32_t mat_base);

/* glTF's dielectric Fresnel on the pbr material m made from Assimp's am: F0 from
 * KHR_materials_ior (m->ior; 0.04 at 1.5), times KHR_materials_specular's colour (at
 * most 1) and factor; F90 the factor. Assimp does not read that extension: gltf_check
 * records it in oc with each material's signature, by which am's is found (where names
 * the material in a warning when that is ambiguous). */
void gltf_specular(const obj_check *oc, const struct aiMaterial *am, const char *where, material *m);
/* KHR_materials_transmission (with _ior and _volume) on the glTF material m, already the
 * pbr model with its maps: m becomes a glass, or a blend of m and a glass whose two parts
 * are appended to s (tex_trans: the transmission texture, -1 for none); *med is the
 * absorbing medium appended to s for the volume's attenuation (inside the meshes of this
 * material), or -1. where names the material in warnings (what is not read). */
valo_status gltf_transmission(scene *s, const struct aiMaterial *am, int tex_trans, const char *where, material *m, int32_t *med, valo_error *err);
#endif
