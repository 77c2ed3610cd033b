/* load_assimp.c — owns mesh-file import through Assimp's C API (OBJ/MTL, glTF 2.0, PLY
 * and the rest Assimp reads): node transforms, triangulated faces, normals, UVs and vertex colours,
 * MTL material meanings (../shared/scenes/README.md: Kd, Ke front-sided, illum 5 mirror,
 * illum 7 glass, illum 2 Phong), a file camera, and the input checks (NaN/Inf vertices,
 * out-of-range indices, degenerate or empty meshes). OBJ, PLY and glTF are checked by
 * valo before Assimp reads them; any other format is first imported in a child process
 * (import_probe.h). An import can be kept for the file's next placement (mesh_cache). */
#include "load/load.h"
#include "core/error.h"
#include "core/memlimit.h"
#include "core/mat34.h"
#include <stdio.h>
#include <sys/stat.h>
#include <strings.h>
#include <assimp/cimport.h>
#include <assimp/scene.h>
#include <assimp/postprocess.h>
#include <assimp/material.h>
#include <assimp/ObjMaterial.h>
#include "image/texture.h"
#include "load/gltf_check.h"
#include "load/assimp_material.h"
#include "load/gltf_material.h"
#include "load/import_probe.h"
#include "load/obj_check.h"
#include "load/ply_check.h"
#include "core/grow.h"
#include <assimp/cfileio.h>
#include <assimp/GltfMaterial.h>
#include <assimp/texture.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MESH_MEMORY_FACTOR 8 /* a mesh file is counted at this many times its size (load_mesh) */

static mat34 m34_from_ai(const struct aiMatrix4x4 *t) {
  mat34 r = {{{t->a1, t->a2, t->a3, t->a4}, {t->b1, t->b2, t->b3, t->b4}, {t->c1, t->c2, t->c3, t->c4}}};
  return r;
}

static rgb ai_color(const struct aiMaterial *m, const char *key, unsigned type, unsigned idx, rgb def, int *found) {
  struct aiColor4D c;
  if (aiGetMaterialColor(m, key, type, idx, &c) == aiReturn_SUCCESS) {
    if (found) *found = 1;
    return c3(c.r, c.g, c.b);
  }
  if (found) *found = 0;
  return def;
}

/* A texture file named in a material (relative to the mesh file's folder dir, or
 * absolute; backslashes taken as slashes); its index or -1 after a warning. */
static int texture_in(scene *s, const char *dir, const char *p, int srgb) {
  char full[2048];
  if (p[0] == '/') snprintf(full, sizeof full, "%s", p);
  else snprintf(full, sizeof full, "%s%s", dir, p);
  for (char *q = full; *q; q++) if (*q == '\\') *q = '/';
  return scene_texture_file(s, full, srgb, NULL);
}

/* Loads texture slot `type` (its idx-th) of am into the scene: a file beside the mesh, or
 * an image embedded in the file ("*N"). Returns the texture index or -1. */
static int load_slot_image(scene *s, const struct aiScene *ai, const struct aiMaterial *am, enum aiTextureType type, unsigned idx,
                           const char *dir, int srgb, int *wrap_mode) {
  if (aiGetMaterialTextureCount(am, type) <= idx) return -1;
  struct aiString path;
  enum aiTextureMapMode mode[2] = {aiTextureMapMode_Wrap, aiTextureMapMode_Wrap};
  if (aiGetMaterialTexture(am, type, idx, &path, NULL, NULL, NULL, NULL, mode, NULL) != aiReturn_SUCCESS) return -1;
  if (wrap_mode) *wrap_mode = mode[0];
  const char *p = path.data;
  if (p[0] == '*') {
    long k = strtol(p + 1, NULL, 10);
    if (k < 0 || (unsigned long)k >= ai->mNumTextures) {
      log_warning("the mesh file in %s: a material names embedded image %s, which the file does not hold (the map is ignored)", dir[0] ? dir : "./", p);
      return -1;
    }
    const struct aiTexture *t = ai->mTextures[k];
    if (t->mHeight != 0) { /* raw texel arrays are not produced by the formats we read */
      log_warning("the mesh file in %s: embedded image %s is a raw texel array, which valo does not read (the map is ignored)", dir[0] ? dir : "./", p);
      return -1;
    }
    char key[1200];
    snprintf(key, sizeof key, "%s%s", dir, p);
    return scene_texture_memory(s, key, (const unsigned char *)t->pcData, t->mWidth, srgb);
  }
  return texture_in(s, dir, p, srgb);
}

/* The texture of a material slot (-1 if none or unreadable), with the slot's wrap mode
 * (glTF sampler wrapS; Assimp reports one mode per slot). */
static int load_slot(scene *s, const struct aiScene *ai, const struct aiMaterial *am, enum aiTextureType type, unsigned idx, const char *dir, int srgb,
                     int *wrap_out) {
  int wrap = aiTextureMapMode_Wrap;
  int t = load_slot_image(s, ai, am, type, idx, dir, srgb, &wrap);
  if (t >= 0) { /* the image sampled with this slot's wrap (another slot's may differ: a texture sharing its pixels) */
    tex_sampling smp = s->tex[t].smp;
    smp.wrap = wrap == aiTextureMapMode_Clamp ? TEX_CLAMP : wrap == aiTextureMapMode_Mirror ? TEX_MIRROR : TEX_REPEAT;
    t = scene_texture_sampled(s, t, &smp);
  }
  if (wrap_out) *wrap_out = wrap;
  return t;
}

static material convert_material(const struct aiMaterial *am, const obj_check *oc) {
  material m = material_default();
  struct aiString name;
  if (aiGetMaterialString(am, AI_MATKEY_NAME, &name) == aiReturn_SUCCESS) snprintf(m.name, sizeof m.name, "%s", name.data);
  int has_base = 0;
  rgb base = ai_color(am, AI_MATKEY_BASE_COLOR, c3(1, 1, 1), &has_base);
  m.kd = ai_color(am, AI_MATKEY_COLOR_DIFFUSE, m.kd, NULL);
  if (has_base) m.kd = base;
  m.ks = ai_color(am, AI_MATKEY_COLOR_SPECULAR, c3(0, 0, 0), NULL);
  m.exponent = ai_float(am, AI_MATKEY_SHININESS, 1.0f);
  m.ior = ai_float(am, AI_MATKEY_REFRACTI, 1.5f);
  m.emission = ai_color(am, AI_MATKEY_COLOR_EMISSIVE, c3(0, 0, 0), NULL);
  float strength = ai_float(am, AI_MATKEY_EMISSIVE_INTENSITY, 1.0f);
  m.emission = c3_scale(m.emission, strength);
  int illum = -1;
  unsigned int n = 1;
  if (aiGetMaterialIntegerArray(am, AI_MATKEY_OBJ_ILLUM, &illum, &n) != aiReturn_SUCCESS) illum = -1;
  if (illum == 5) m.type = MAT_MIRROR;
  else if (illum == 7) m.type = MAT_DIELECTRIC;
  else if (illum >= 2 && c3_max(m.ks) > 0) m.type = MAT_PHONG;
  else m.type = MAT_DIFFUSE;
  if (m.type == MAT_DIELECTRIC && !(m.ior > 0)) m.ior = 1.5f;
  if (m.exponent < 0 || !isfinite(m.exponent)) m.exponent = 1;
  /* MTL's PBR extension (docs/scene-format.md): Pr is the microfacet alpha (so valo's
   * roughness, whose square is alpha, is its root), Pm the metallic weight. A material
   * with either becomes the pbr model (illum 7 glass: rough glass); a metal whose Kd is
   * black takes its colour from Ks, and reflects it at every angle as MTL mirrors do
   * (illum 3 and 5 have no Fresnel term). */
  const mtl_pbr *pb = oc ? obj_check_pbr(oc, m.name) : NULL;
  if (pb && (pb->has_pr || pb->has_pm || pb->map_pr[0] || pb->map_pm[0])) {
    float alpha = pb->has_pr ? clampf(pb->pr, 0, 1) : 0.25f;
    if (m.type == MAT_DIELECTRIC) m.roughness = sqrtf(alpha);
    else {
      m.type = MAT_PBR;
      m.metallic = pb->has_pm ? clampf(pb->pm, 0, 1) : 0;
      m.roughness = sqrtf(alpha);
      if (m.metallic > 0 && c3_black(m.kd) && !c3_black(m.ks)) m.kd = m.ks;
      m.metal_flat = 1;
    }
  }
  return m; /* texture slots stay as material_default left them: none */
}

/* Some OBJ exporters put tangent-space normal maps under map_bump: such a map is
 * coloured with mean near (0.5, 0.5, 1), which a height map never is. */
static int looks_like_normal_map(const texture *t) {
  double r = 0, g = 0, b = 0, spread = 0;
  size_t n = (size_t)t->w * t->h;
  if (n == 0) return 0;
  for (size_t i = 0; i < n; i++) {
    const float *p = &t->px[4 * i];
    r += p[0]; g += p[1]; b += p[2];
    spread += fabsf(p[2] - p[0]);
  }
  r /= n; g /= n; b /= n; spread /= n;
  return b > 0.7 && fabs(r - 0.5) < 0.15 && fabs(g - 0.5) < 0.15 && spread > 0.2;
}

static void convert_textures(scene *s, const struct aiScene *ai, const struct aiMaterial *am, material *m, const char *dir, int gltf,
                             const obj_check *oc) {
  int wrap = 0;
  const mtl_pbr *pb = oc ? obj_check_pbr(oc, m->name) : NULL;
  if (pb && pb->map_pr[0]) m->tex_rough = texture_in(s, dir, pb->map_pr, 0);
  m->rough_is_alpha = 1;
  if (pb && pb->map_pm[0]) m->tex_metal = texture_in(s, dir, pb->map_pm, 0);
  m->tex_kd = load_slot(s, ai, am, aiTextureType_BASE_COLOR, 0, dir, 1, &wrap);
  if (m->tex_kd < 0) m->tex_kd = load_slot(s, ai, am, aiTextureType_DIFFUSE, 0, dir, 1, &wrap);
  m->tex_ks = load_slot(s, ai, am, aiTextureType_SPECULAR, 0, dir, 1, NULL);
  m->tex_ns = load_slot(s, ai, am, aiTextureType_SHININESS, 0, dir, 0, NULL);
  m->tex_normal = load_slot(s, ai, am, aiTextureType_NORMALS, 0, dir, 0, NULL);
  m->map_tangents = 1; /* maps in the mesh's tangents with their handedness, as glTF and most tools */
  /* MTL bump / map_bump (Assimp's HEIGHT slot) with its -bm multiplier. */
  int height = load_slot(s, ai, am, aiTextureType_HEIGHT, 0, dir, 0, NULL);
  if (height >= 0) {
    if (m->tex_normal < 0 && looks_like_normal_map(&s->tex[height])) m->tex_normal = height;
    else {
      m->tex_bump = height;
      float bm = 1;
      unsigned int one = 1;
      if (aiGetMaterialFloatArray(am, AI_MATKEY_OBJ_BUMPMULT_HEIGHT(0), &bm, &one) == aiReturn_SUCCESS && isfinite(bm)) m->bump_scale = bm;
    }
  }
  m->tex_ke = load_slot(s, ai, am, aiTextureType_EMISSIVE, 0, dir, 1, NULL);
  if (m->tex_ke >= 0 && c3_black(m->emission)) m->emission = c3(1, 1, 1);
  /* Cutout: an opacity map (MTL map_d), or glTF alphaMode MASK on the base colour; BLEND: below. */
  /* glTF 2.0 metallic-roughness (docs/scene-format.md): MAT_PBR with the factors (glTF
   * defaults 1 and 1) times the metallic-roughness texture (G roughness, B metallic),
   * which Assimp 5.2 files under METALNESS or, for older files, UNKNOWN. */
  if (gltf) {
    m->type = MAT_PBR;
    m->metallic = clampf(ai_float(am, AI_MATKEY_METALLIC_FACTOR, 1), 0, 1);
    m->roughness = clampf(ai_float(am, AI_MATKEY_ROUGHNESS_FACTOR, 1), 0, 1);
    m->tex_mr = load_slot(s, ai, am, aiTextureType_METALNESS, 0, dir, 0, NULL);
    if (m->tex_mr < 0) m->tex_mr = load_slot(s, ai, am, aiTextureType_UNKNOWN, 0, dir, 0, NULL);
    m->tex_kd = gltf_transformed(s, am, aiGetMaterialTextureCount(am, aiTextureType_BASE_COLOR) ? aiTextureType_BASE_COLOR : aiTextureType_DIFFUSE, m->tex_kd);
    m->tex_mr = gltf_transformed(s, am, aiGetMaterialTextureCount(am, aiTextureType_METALNESS) ? aiTextureType_METALNESS : aiTextureType_UNKNOWN, m->tex_mr);
    m->tex_normal = gltf_transformed(s, am, aiTextureType_NORMALS, m->tex_normal);
    m->tex_ke = gltf_transformed(s, am, aiTextureType_EMISSIVE, m->tex_ke);
  }
  int opacity = load_slot(s, ai, am, aiTextureType_OPACITY, 0, dir, 0, NULL);
  if (opacity >= 0) { m->tex_alpha = opacity; m->alpha_channel = s->tex[opacity].has_alpha; }
  struct aiString mode;
  if (aiGetMaterialString(am, AI_MATKEY_GLTF_ALPHAMODE, &mode) != aiReturn_SUCCESS || !strcmp(mode.data, "OPAQUE")) return;
  int kd_alpha = m->tex_kd >= 0 && s->tex[m->tex_kd].has_alpha;
  if (!strcmp(mode.data, "BLEND") && c3_black(m->emission)) {
    /* BLEND: the base colour's alpha (factor times texture) as stochastic opacity, the
     * fraction of light a surface stops, as Cycles renders a blended glTF material */
    struct aiColor4D bc;
    if (aiGetMaterialColor(am, AI_MATKEY_BASE_COLOR, &bc) == aiReturn_SUCCESS && bc.a >= 0 && bc.a < 1) m->opacity = bc.a;
    if (kd_alpha) { m->tex_alpha = m->tex_kd; m->alpha_channel = 1; m->alpha_stochastic = 1; }
  } else if (kd_alpha) {
    m->tex_alpha = m->tex_kd;
    m->alpha_channel = 1;
    m->alpha_cutoff = ai_float(am, AI_MATKEY_GLTF_ALPHACUTOFF, 0.5f);
  }
}

typedef struct load_ctx {
  scene *s;
  const char *path;
  const struct aiScene *ai;
  uint32_t mat_base;
  uint32_t override_mat;
  uint64_t added, degenerate;
  valo_error *err;
  int gltf;          /* a .gltf/.glb file: its cameras and materials need glTF meanings */
  int flat;          /* LOAD_MESH_FLAT: the file's vertex normals are not used */
  int smooth;        /* LOAD_MESH_SMOOTH: normals computed where the file has none */
  valo_options *file; /* the render settings the file asks for (a camera's film aspect) */
  int flip_v;        /* LOAD_MESH_FLIP_V: v' = 1 - v */
  int32_t *mat_medium; /* glTF: per file material, the medium its volume bounds (-1: none), or NULL */
} load_ctx;

_Static_assert(sizeof(struct aiVector3D) == 3 * sizeof(float), "Assimp's vectors are read as 3 floats");
_Static_assert(sizeof(struct aiColor4D) == 4 * sizeof(float), "Assimp's colours are read as 4 floats");
static valo_status add_mesh(load_ctx *c, const struct aiMesh *mesh, const mat34 *xf) {
  scene *s = c->s;
  if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) return VALO_OK;
  uint32_t mat = c->override_mat != UINT32_MAX ? c->override_mat : c->mat_base + mesh->mMaterialIndex;
  if (mat >= s->nmats) return err_set(c->err, VALO_ERR_INVALID, "%s: mesh '%s' names material %u that does not exist", c->path, mesh->mName.data, mesh->mMaterialIndex);
  if (scene_reserve(s, mesh->mNumVertices, mesh->mNumFaces)) return err_set(c->err, VALO_ERR_NOMEM, "%s: out of memory", c->path);
  /* glTF TANGENT (xyz, w): Assimp gives the tangent and the bitangent w (n x t); the
   * scene's tangent array is made when the first file gives one */
  int has_tan = c->gltf && mesh->mTangents && mesh->mBitangents && mesh->mNormals;
  if (has_tan && !s->tan_file && !(s->tan_file = calloc((size_t)s->cap_verts * 4, sizeof(float))))
    return err_set(c->err, VALO_ERR_NOMEM, "%s: out of memory", c->path);
  /* The triangles (points and lines skipped), their indices checked in the file's numbering. */
  uint32_t *idx = malloc((size_t)mesh->mNumFaces * 3 * sizeof *idx + 1), nt = 0;
  if (!idx) return err_set(c->err, VALO_ERR_NOMEM, "%s: out of memory", c->path);
  for (unsigned f = 0; f < mesh->mNumFaces; f++) {
    const struct aiFace *face = &mesh->mFaces[f];
    if (face->mNumIndices != 3) continue;
    for (int k = 0; k < 3; k++) {
      if (face->mIndices[k] >= mesh->mNumVertices) {
        free(idx);
        return err_set(c->err, VALO_ERR_INVALID, "%s: mesh '%s' face %u has a vertex index out of range (mesh has %u vertices)",
                       c->path, mesh->mName.data, f, mesh->mNumVertices);
      }
      idx[3 * nt + k] = face->mIndices[k];
    }
    nt++;
  }
  char where[1400];
  snprintf(where, sizeof where, "%s: mesh '%s'", c->path, mesh->mName.data);
  const struct aiVector3D *uv = mesh->mTextureCoords[0];
  mesh_data md = {where, mesh->mNumVertices, nt, (const float *)mesh->mVertices, (const float *)mesh->mNormals,
                  uv ? &uv->x : NULL, sizeof *uv / sizeof(float), idx, c->flat, c->smooth,
                  mesh->mColors[0] ? &mesh->mColors[0]->r : NULL, sizeof(struct aiColor4D) / sizeof(float)};
  uint32_t base = s->nverts;
  uint32_t first = s->ntris;
  valo_status st = scene_add_mesh(s, &md, &xf->m[0][0], mat, &c->added, &c->degenerate, c->err);
  free(idx);
  int32_t med = c->mat_medium && c->override_mat == UINT32_MAX && mesh->mMaterialIndex < c->ai->mNumMaterials ? c->mat_medium[mesh->mMaterialIndex] : -1;
  if (st == VALO_OK && med >= 0 && s->ntris > first && scene_add_shape_media(s, first, med, MEDIUM_NONE)) /* a glTF volume: absorbing inside */
    return err_set(c->err, VALO_ERR_NOMEM, "%s: out of memory", c->path);
  for (uint32_t v = base; st == VALO_OK && uv && c->flip_v && v < s->nverts; v++) s->uv[2 * (size_t)v + 1] = 1 - s->uv[2 * (size_t)v + 1];
  for (unsigned v = 0; st == VALO_OK && has_tan && v < mesh->mNumVertices; v++) {
    vec3 n = s->nrm[base + v];
    float *tf = &s->tan_file[4 * (size_t)(base + v)];
    if (!(v3_len2(n) > 0)) continue;
    vec3 t = m34_vector(xf, v3(mesh->mTangents[v].x, mesh->mTangents[v].y, mesh->mTangents[v].z));
    vec3 bt = m34_vector(xf, v3(mesh->mBitangents[v].x, mesh->mBitangents[v].y, mesh->mBitangents[v].z));
    if (v3_finite(t) && v3_finite(bt) && v3_len2(t) > 0) {
      tf[0] = t.x; tf[1] = t.y; tf[2] = t.z;
      tf[3] = (v3_dot(v3_cross(n, t), bt) < 0) != (c->flip_v != 0) ? -1.0f : 1.0f; /* v turned: dp/dv turns */
    }
  }
  return st;
}

static valo_status walk(load_ctx *c, const struct aiNode *node, const mat34 *parent) {
  mat34 local = m34_from_ai(&node->mTransformation);
  mat34 xf = m34_mul(parent, &local);
  for (unsigned i = 0; i < node->mNumMeshes; i++) {
    if (node->mMeshes[i] >= c->ai->mNumMeshes)
      return err_set(c->err, VALO_ERR_INVALID, "%s: node '%s' names mesh %u that does not exist", c->path, node->mName.data, node->mMeshes[i]);
    valo_status st = add_mesh(c, c->ai->mMeshes[node->mMeshes[i]], &xf);
    if (st) return st;
  }
  for (unsigned i = 0; i < node->mNumChildren; i++) {
    valo_status st = walk(c, node->mChildren[i], &xf);
    if (st) return st;
  }
  return VALO_OK;
}

static const struct aiNode *find_node(const struct aiNode *n, const char *name, mat34 *acc, const mat34 *parent) {
  mat34 local = m34_from_ai(&n->mTransformation);
  mat34 xf = m34_mul(parent, &local);
  if (!strcmp(n->mName.data, name)) { *acc = xf; return n; }
  for (unsigned i = 0; i < n->mNumChildren; i++) {
    const struct aiNode *r = find_node(n->mChildren[i], name, acc, &xf);
    if (r) return r;
  }
  return NULL;
}

static void take_file_camera(load_ctx *c, const mat34 *xf) {
  const struct aiCamera *cam = c->ai->mCameras[0];
  mat34 node_xf = m34_identity(), id = m34_identity();
  if (!find_node(c->ai->mRootNode, cam->mName.data, &node_xf, &id)) node_xf = m34_identity();
  mat34 full = m34_mul(xf, &node_xf);
  /* Assimp's glTF 2 importer (5.2) departs from aiCamera's definition twice: it copies
   * the node's translation into mPosition although the node transform already holds it,
   * and it stores yfov * aspectRatio in mHorizontalFOV (not half the horizontal angle). */
  int gltf = c->gltf;
  vec3 local = gltf ? v3(0, 0, 0) : v3(cam->mPosition.x, cam->mPosition.y, cam->mPosition.z);
  vec3 pos = m34_point(&full, local);
  vec3 look = m34_vector(&full, v3(cam->mLookAt.x, cam->mLookAt.y, cam->mLookAt.z));
  vec3 up = m34_vector(&full, v3(cam->mUp.x, cam->mUp.y, cam->mUp.z));
  if (!v3_finite(pos) || !(v3_len2(look) > 0) || !(v3_len2(up) > 0) || !(v3_len2(v3_cross(look, up)) > 0)) {
    log_warning("%s: camera '%s' has a non-finite position or a zero or parallel view and up vector: it is ignored and the view "
                "is framed automatically", c->path, cam->mName.data);
    return;
  }
  float aspect = cam->mAspect > 0 ? cam->mAspect : 1.0f;
  float vfov = 0.8f, height = 0;
  if (cam->mOrthographicWidth != 0) {
    /* Orthographic (glTF's xmag and ymag: mOrthographicWidth = xmag, mAspect = xmag / ymag):
     * the height 2 ymag, scaled as the node's transform scales the up vector. */
    height = 2.0f * fabsf(cam->mOrthographicWidth) / aspect * v3_len(up) / v3_len(v3(cam->mUp.x, cam->mUp.y, cam->mUp.z));
    if (!(height > 0 && height < 1e30f)) {
      log_warning("%s: orthographic camera '%s' has no usable size (half width %g): it is ignored and the view is framed "
                  "automatically", c->path, cam->mName.data, (double)cam->mOrthographicWidth);
      return;
    }
  } else {
    if (gltf) vfov = cam->mHorizontalFOV > 0 ? cam->mHorizontalFOV / (cam->mAspect > 0 ? cam->mAspect : 1.0f) : 0.8f;
    else vfov = 2.0f * atanf(tanf(cam->mHorizontalFOV > 0 ? cam->mHorizontalFOV : 0.5f) / aspect);
    if (!(cam->mHorizontalFOV > 0) || !(vfov > 1e-4f && vfov < 3.1f)) {
      log_warning("%s: camera '%s' has no usable field of view (%g): %.1f degrees (vertical) is used", c->path, cam->mName.data,
                  (double)cam->mHorizontalFOV, 0.8 * 180 / M_PI);
      vfov = 0.8f;
    }
  }
  c->s->cam.ortho_height = height;
  c->s->cam.pos = pos;
  c->s->cam.look_at = v3_add(pos, v3_norm(look));
  c->s->cam.up = v3_norm(up);
  c->s->cam.fov_deg = vfov * 180.0f / PI_F;
  c->s->cam.aperture_radius = 0;
  c->s->cam.focus_distance = -1; /* glTF/Assimp cameras have none: autofocus (render/session.c) */
  c->s->has_camera = 1;
  if (cam->mAspect > 0 && c->file && c->file->width == VALO_UNSET) {
    c->file->height = 256;
    c->file->width = (int)lroundf(256 * cam->mAspect);
  }
}

/* KHR_lights_punctual (and other formats' lights) as Assimp gives them: colour x
 * intensity, position and direction in the frame of the node that shares the light's
 * name. Photometric glTF units are taken as radiometric (candela as W/sr, lux as W/m^2). */
static valo_status take_file_lights(load_ctx *c, const mat34 *xf) {
  for (unsigned i = 0; i < c->ai->mNumLights; i++) {
    const struct aiLight *al = c->ai->mLights[i];
    mat34 node_xf = m34_identity(), id = m34_identity();
    if (!find_node(c->ai->mRootNode, al->mName.data, &node_xf, &id)) node_xf = m34_identity();
    mat34 full = m34_mul(xf, &node_xf);
    light l;
    memset(&l, 0, sizeof l);
    l.L = c3(al->mColorDiffuse.r, al->mColorDiffuse.g, al->mColorDiffuse.b);
    l.p = m34_point(&full, v3(al->mPosition.x, al->mPosition.y, al->mPosition.z));
    l.dir = v3_norm(m34_vector(&full, v3(al->mDirection.x, al->mDirection.y, al->mDirection.z)));
    switch (al->mType) {
    case aiLightSource_POINT: l.type = LIGHT_POINT; break;
    case aiLightSource_SPOT:
      l.type = LIGHT_SPOT;
      l.cos_outer = cosf(clampf(al->mAngleOuterCone, 1e-4f, PI_F));
      l.cos_inner = cosf(clampf(al->mAngleInnerCone, 0, al->mAngleOuterCone));
      break;
    case aiLightSource_DIRECTIONAL: l.type = LIGHT_DIRECTIONAL; break;
    case aiLightSource_UNDEFINED: case aiLightSource_AMBIENT: case aiLightSource_AREA: case _aiLightSource_Force32Bit:
    default:
      log_warning("%s: light '%s' of an unsupported kind is ignored", c->path, al->mName.data);
      continue;
    }
    if (!v3_finite(l.p) || !c3_finite(l.L) || ((l.type != LIGHT_POINT) && !(v3_len2(l.dir) > 0))) {
      log_warning("%s: light '%s' has a bad position or direction and is ignored", c->path, al->mName.data);
      continue;
    }
    if (scene_add_light(c->s, &l)) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  }
  return VALO_OK;
}

/* One mesh file as Assimp imported it, with valo's checked text of it (OBJ, glTF, PLY). */
typedef struct imported {
  char *path;
  int flags; /* the LOAD_MESH_ flags that change the import (LOAD_MESH_SMOOTH) */
  const struct aiScene *ai;
  obj_check oc;
  int obj, gltf, ply, placed;
} imported;
struct mesh_cache { imported *e; int n; };

static void imported_free(imported *im) {
  if (im->ai) aiReleaseImport(im->ai);
  obj_check_free(&im->oc);
  free(im->path);
}

void mesh_cache_free(mesh_cache *mc) {
  if (!mc) return;
  for (int i = 0; i < mc->n; i++) imported_free(&mc->e[i]);
  free(mc->e);
  free(mc);
}

/* Checks and imports path (everything before the triangles are placed). */
static valo_status import_file(const char *path, int mesh_flags, imported *im, valo_error *err) {
  memset(im, 0, sizeof *im);
  /* Loading and building peak at a multiple of the file's size (MESH_MEMORY_FACTOR; 7-11
   * measured on the bunny, the dragon and Sponza: docs/guide.md, "Limits"); a file that would not fit
   * is refused before it is read. */
  struct stat sb;
  if (stat(path, &sb) == 0 && sb.st_size > 0) {
    char what[96];
    snprintf(what, sizeof what, "reading a mesh file of %.1f MiB", (double)sb.st_size / 1048576.0);
    valo_status mst = mem_check((uint64_t)sb.st_size * MESH_MEMORY_FACTOR, path, what, err);
    if (mst) return mst;
  }
  /* A PLY (by its magic, whatever its name) is checked by valo first: Assimp aborts the
   * process on faces that disagree with the header (ply_check.h), and reads a PLY of
   * triangle strips as one bogus polygon without an error. */
  char *ply_fixed = NULL;
  size_t ply_fixed_len = 0;
  valo_status pst = ply_check_file(path, &ply_fixed, &ply_fixed_len, err);
  if (pst) return pst;
  unsigned flags = aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_ValidateDataStructure;
  /* Normals computed from the faces need the vertices the faces share: an OBJ's corners
   * are separate vertices to Assimp until joined. */
  if (mesh_flags & LOAD_MESH_SMOOTH) flags |= aiProcess_JoinIdenticalVertices;
  const char *ext = strrchr(path, '.');
  /* OBJ files are read by valo first (obj_check.c): checks with line numbers, repairs,
   * the MTL PBR extension; Assimp then parses the repaired text. */
  im->obj = ext && !strcasecmp(ext, ".obj");
  im->gltf = ext && (!strcasecmp(ext, ".gltf") || !strcasecmp(ext, ".glb"));
  im->ply = ext && !strcasecmp(ext, ".ply");
  obj_check *oc = &im->oc;
  struct aiFileIO io;
  if (im->obj) {
    valo_status cst = obj_check_read(path, oc, err);
    if (cst) return cst;
    obj_check_fileio(oc, &io);
  } else if (im->gltf) { /* checked by valo first (gltf_check.h); the file and its buffers served as read */
    valo_status gst = gltf_check_file(path, !strcasecmp(ext, ".glb"), oc, err);
    if (gst) return gst;
    obj_check_fileio(oc, &io);
  } else if (ply_fixed) { /* the PLY as Assimp must read it, served like a repaired OBJ */
    snprintf(oc->files[0].path, sizeof oc->files[0].path, "%s", path);
    oc->files[0].text = ply_fixed;
    oc->files[0].len = ply_fixed_len;
    oc->nfiles = 1;
    obj_check_fileio(oc, &io);
  }
  int checked = im->obj || im->gltf || ply_fixed;
  if (!checked) { /* any other format: tried in a child process first (import_probe.h) */
    valo_status ist = import_probe(path, flags, err);
    if (ist) return ist;
  }
  im->ai = checked ? aiImportFileEx(path, flags, &io) : aiImportFile(path, flags);
  if (!im->ai) {
    const char *msg = aiGetErrorString();
    obj_check_free(oc);
    return err_set(err, VALO_ERR_PARSE, "%s: not a mesh file valo can read (%s) (the importer said: %s)", path,
                   ext ? ext + 1 : "no extension", msg && *msg ? msg : "unknown format");
  }
  im->flags = mesh_flags & LOAD_MESH_SMOOTH;
  return VALO_OK;
}

/* Places an imported file's triangles (and its materials, camera and lights) in s. */
static valo_status place_with(load_ctx *cp, imported *im, const char *path, const float *xf12, uint32_t override_mat, int mesh_flags);
static valo_status place(scene *s, imported *im, const char *path, const float *xf12, uint32_t override_mat, int mesh_flags, valo_options *file,
                         valo_error *err) {
  load_ctx c = {s, path, im->ai, s->nmats, override_mat, 0, 0, err, im->gltf, (mesh_flags & LOAD_MESH_FLAT) != 0, (mesh_flags & LOAD_MESH_SMOOTH) != 0, file,
                 (mesh_flags & LOAD_MESH_FLIP_V) != 0, NULL};
  if (override_mat == UINT32_MAX && c.gltf) {
    if (!(c.mat_medium = malloc((im->ai->mNumMaterials + 1) * sizeof *c.mat_medium))) return err_set(err, VALO_ERR_NOMEM, "out of memory");
    for (unsigned i = 0; i <= im->ai->mNumMaterials; i++) c.mat_medium[i] = -1;
  }
  valo_status st = place_with(&c, im, path, xf12, override_mat, mesh_flags);
  free(c.mat_medium);
  return st;
}

static valo_status place_with(load_ctx *cp, imported *im, const char *path, const float *xf12, uint32_t override_mat, int mesh_flags) {
  load_ctx c = *cp; /* (mat_medium freed by place) */
  scene *s = c.s;
  valo_error *err = c.err;
  const struct aiScene *ai = im->ai;
  valo_status st = VALO_OK;
  if (override_mat == UINT32_MAX) {
    for (unsigned i = 0; i < ai->mNumMaterials; i++)
      if (scene_add_material(s, &(material){0}) == UINT32_MAX) return err_set(err, VALO_ERR_NOMEM, "out of memory");
    char dir[1024] = "";
    const char *slash = strrchr(path, '/');
    if (slash) snprintf(dir, sizeof dir, "%.*s/", (int)(slash - path), path);
    for (unsigned i = 0; i < ai->mNumMaterials; i++) {
      const obj_check *oc = im->obj || im->gltf ? &im->oc : NULL;
      material m = convert_material(ai->mMaterials[i], oc);
      snprintf(s->tex_user, sizeof s->tex_user, "%s: material '%s'", path, m.name);
      convert_textures(s, ai, ai->mMaterials[i], &m, dir, c.gltf, oc);
      if (c.gltf) { /* KHR_materials_ior and _specular; _transmission: a glass, or a blend with one (gltf_material.c) */
        gltf_specular(oc, ai->mMaterials[i], s->tex_user, &m);
        for (unsigned k = 0; k < 2; k++) /* KHR_materials_clearcoat's textures: the coat's weight (R), its roughness (G) */
          *(k ? &m.tex_ccr : &m.tex_cc) = gltf_slot_transformed(s, ai->mMaterials[i], aiTextureType_CLEARCOAT, k, load_slot(s, ai, ai->mMaterials[i], aiTextureType_CLEARCOAT, k, dir, 0, NULL));
        m.tex_sheen = gltf_transformed(s, ai->mMaterials[i], aiTextureType_SHEEN, load_slot(s, ai, ai->mMaterials[i], aiTextureType_SHEEN, 0, dir, 1, NULL));
        int tt = gltf_transformed(s, ai->mMaterials[i], aiTextureType_TRANSMISSION, load_slot(s, ai, ai->mMaterials[i], aiTextureType_TRANSMISSION, 0, dir, 0, NULL));
        st = gltf_transmission(s, ai->mMaterials[i], tt, s->tex_user, &m, &c.mat_medium[i], err);
        if (st) return st;
      }
      s->tex_user[0] = 0;
      s->mats[c.mat_base + i] = m;
      if (s->tex_fatal.status) {
        if (err) *err = s->tex_fatal;
        return s->tex_fatal.status;
      }
    }
    if (c.gltf || im->ply) mesh_vertex_colors(s, ai, c.mat_base);
    if (ai->mNumMaterials == 0) {
      material d = material_default();
      c.override_mat = scene_add_material(s, &d);
      if (c.override_mat == UINT32_MAX) return err_set(err, VALO_ERR_NOMEM, "out of memory");
    }
  }
  mat34 x = m34_from(xf12);
  if (!ai->mRootNode) return err_set(err, VALO_ERR_PARSE, "%s: the file has no scene graph", path);
  st = walk(&c, ai->mRootNode, &x);
  if (st) return st;
  if (c.added == 0)
    return err_set(err, VALO_ERR_INVALID, "%s: no usable triangles (%llu degenerate); is it a point cloud, a tristrip or empty?", path,
                   (unsigned long long)c.degenerate);
  if (c.degenerate && !im->placed)
    log_warning("%s: skipped %llu degenerate (zero-area) triangles", path, (unsigned long long)c.degenerate);
  im->placed = 1;
  if ((mesh_flags & LOAD_MESH_CAMERA) && ai->mNumCameras > 0) take_file_camera(&c, &x);
  return take_file_lights(&c, &x);
}

valo_status load_mesh_cached(scene *s, const char *path, const float *xf12, uint32_t override_mat, int mesh_flags, valo_options *file,
                             mesh_cache **cache, valo_error *err) {
  if (cache) {
    mesh_cache *mc = *cache;
    for (int i = 0; mc && i < mc->n; i++)
      if (mc->e[i].flags == (mesh_flags & LOAD_MESH_SMOOTH) && !strcmp(mc->e[i].path, path))
        return place(s, &mc->e[i], path, xf12, override_mat, mesh_flags, file, err);
  }
  imported im;
  valo_status st = import_file(path, mesh_flags, &im, err);
  if (st) return st;
  if (cache) {
    /* kept for the file's next placement (a failed keep only costs a second import) */
    mesh_cache *mc = *cache ? *cache : calloc(1, sizeof *mc);
    imported *e = mc ? grow_for(mc->e, (size_t)mc->n, sizeof *e) : NULL;
    if (mc) *cache = mc;
    if (e) {
      mc->e = e;
      if ((im.path = strdup(path))) {
        e[mc->n] = im;
        return place(s, &e[mc->n++], path, xf12, override_mat, mesh_flags, file, err);
      }
    }
  }
  st = place(s, &im, path, xf12, override_mat, mesh_flags, file, err);
  imported_free(&im);
  return st;
}

valo_status load_mesh(scene *s, const char *path, const float *xf12, uint32_t override_mat, int mesh_flags, valo_options *file,
                      valo_error *err) {
  return load_mesh_cached(s, path, xf12, override_mat, mesh_flags, file, NULL, err);
}
