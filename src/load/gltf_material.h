/* gltf_material.h — owns the glTF material extensions read on top of Assimp's import
 * (gltf_material.c says how). */
#ifndef VALO_GLTF_MATERIAL_H
#define VALO_GLTF_MATERIAL_H
#include "scene/scene.h"
struct aiMaterial;

/* KHR_materials_transmission (with _ior and _volume) on the glTF material m, already the
 * pbr model with its maps: m becomes a glass, or a blend of m and a glass whose two parts
 * are appended to s (tex_trans: the transmission texture, -1 for none). where names the
 * material in warnings (what is not read). */
valo_status gltf_transmission(scene *s, const struct aiMaterial *am, int tex_trans, const char *where, material *m, valo_error *err);
#endif
