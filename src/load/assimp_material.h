/* assimp_material.h — owns reading a number from an Assimp material, for the loaders that
 * give its properties valo's meanings (load_assimp.c, gltf_material.c). */
#ifndef VALO_ASSIMP_MATERIAL_H
#define VALO_ASSIMP_MATERIAL_H
#include <assimp/material.h>

/* The material's one-number property key (type, idx: Assimp's texture slot), else def. */
static inline float ai_float(const struct aiMaterial *m, const char *key, unsigned type, unsigned idx, float def) {
  ai_real v;
  unsigned int n = 1;
  if (aiGetMaterialFloatArray(m, key, type, idx, &v, &n) == aiReturn_SUCCESS && n == 1) return (float)v;
  return def;
}
#endif
