/* gltf_objects.c — owns the glTF check's nodes and the objects that only name others
 * (gltf_check_internal.h): node trees, scenes, materials' texture references (and
 * KHR_texture_transform, which Assimp indexes without looking), textures, images,
 * cameras, skins, animations and KHR_lights_punctual lights; the extensions a file uses
 * and requires. */
#include "load/gltf_check_internal.h"
#include "core/error.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Children indices valid, each node the child of at most one node, no cycle, depth bounded. */
valo_status gl_check_nodes(gc *g) {
  uint32_t n = g->n[K_NODE], arr = g->arr[K_NODE];
  int64_t *parent = malloc(((size_t)n + 1) * sizeof *parent);
  uint32_t *stack = malloc(((size_t)n + 1) * sizeof *stack), *depth = malloc(((size_t)n + 1) * sizeof *depth);
  uint32_t *obj = malloc(((size_t)n + 1) * sizeof *obj);
  valo_status st = !parent || !stack || !depth || !obj ? gl_bad(g, "out of memory for %u nodes", n) : VALO_OK;
  for (uint32_t i = 0; i < n && !st; i++) parent[i] = -1;
  uint32_t i = 0;
  for (uint32_t o = arr ? N(g, arr)->child : 0; o && !st; o = N(g, o)->next, i++) {
    char ctx[48];
    snprintf(ctx, sizeof ctx, "node %u", i);
    obj[i] = o;
    if (gl_index_array(g, o, "children", n, "node", ctx) || gl_index(g, o, "mesh", g->n[K_MESH], "mesh", 0, ctx) == -2 ||
        gl_index(g, o, "camera", g->n[K_CAM], "camera", 0, ctx) == -2 || gl_index(g, o, "skin", g->n[K_SKIN], "skin", 0, ctx) == -2) {
      st = g->err->status;
      break;
    }
    static const char *vecs[] = {"matrix", "translation", "rotation", "scale"};
    static const uint32_t lens[] = {16, 3, 4, 3};
    for (int k = 0; k < 4 && !st; k++) {
      uint32_t a = json_get(&g->d, o, vecs[k]);
      if (!a) continue;
      int ok = N(g, a)->t == J_ARR && N(g, a)->n == lens[k];
      for (uint32_t c = ok ? N(g, a)->child : 0; c; c = N(g, c)->next) ok &= N(g, c)->t == J_NUM;
      if (!ok) st = gl_bad(g, "%s: \"%s\" must be an array of %u numbers", ctx, vecs[k], lens[k]);
    }
    uint32_t ext = json_get(&g->d, json_get(&g->d, o, "extensions"), "KHR_lights_punctual");
    if (!st && ext && gl_index(g, ext, "light", g->n_light, "light", 1, ctx) < 0) st = g->err->status;
    uint32_t ch = json_get(&g->d, o, "children");
    for (uint32_t c = ch ? N(g, ch)->child : 0; c && !st; c = N(g, c)->next) {
      uint32_t k = (uint32_t)N(g, c)->num;
      if (parent[k] >= 0 || k == i) st = gl_bad(g, "node %u is a child of two nodes, or of itself", k);
      else parent[k] = i;
    }
  }
  /* Every node must be reached from a root: one that is not is on a cycle. */
  uint32_t reached = 0, sp = 0;
  for (uint32_t r = 0; r < n && !st; r++) {
    if (parent[r] >= 0) continue;
    stack[sp++] = r;
    depth[r] = 1;
    while (sp && !st) {
      uint32_t k = stack[--sp];
      reached++;
      if (depth[k] > GLTF_MAX_NODE_DEPTH) st = gl_bad(g, "the node tree is more than %d deep", GLTF_MAX_NODE_DEPTH);
      uint32_t ch = json_get(&g->d, obj[k], "children");
      for (uint32_t c = ch ? N(g, ch)->child : 0; c; c = N(g, c)->next) {
        uint32_t x = (uint32_t)N(g, c)->num;
        depth[x] = depth[k] + 1;
        stack[sp++] = x;
      }
    }
  }
  if (!st && reached != n) st = gl_bad(g, "the nodes' children form a cycle");
  free(parent);
  free(obj);
  free(stack);
  free(depth);
  return st;
}

/* ------------------------------------------------ materials and the rest */

/* Every texture reference inside material value v (a member "...Texture" holding an
 * object, core or extension; not inside "extras", which is the application's): its
 * "index" must name a texture. One on another coordinate set than the first (its
 * KHR_texture_transform's texCoord overrides its own) is warned about: valo reads set 0. */
static valo_status check_texture_refs(gc *g, uint32_t v, const char *ctx) {
  for (uint32_t c = N(g, v)->child; c; c = N(g, c)->next) {
    const char *k = N(g, c)->key;
    size_t kl = k ? strlen(k) : 0;
    if (N(g, c)->t == J_OBJ && kl >= 7 && !strcmp(k + kl - 7, "Texture")) {
      uint64_t tc;
      if (gl_index(g, c, "index", g->n[K_TEX], "texture", 1, ctx) < 0 || gl_uint(g, c, "texCoord", 0, 7, 0, &tc, ctx)) return g->err->status;
      uint32_t tt = json_get(&g->d, json_get(&g->d, c, "extensions"), "KHR_texture_transform");
      if (tt && N(g, tt)->t == J_OBJ && gl_uint(g, tt, "texCoord", tc, 7, 0, &tc, ctx)) return g->err->status;
      if (tc) log_warning("%s: %s: a texture reads texture coordinate set %llu; valo reads set 0 only", g->path, ctx, (unsigned long long)tc);
    }
    if (N(g, c)->t == J_OBJ && k && !strcmp(k, "KHR_texture_transform")) { /* Assimp indexes these without looking */
      static const char *vec2[] = {"offset", "scale"};
      for (int i = 0; i < 2; i++) {
        uint32_t a = json_get(&g->d, c, vec2[i]);
        int ok = !a || (N(g, a)->t == J_ARR && N(g, a)->n == 2 && N(g, N(g, a)->child)->t == J_NUM && N(g, N(g, N(g, a)->child)->next)->t == J_NUM);
        if (!ok) return gl_bad(g, "%s: KHR_texture_transform \"%s\" must be an array of 2 numbers", ctx, vec2[i]);
      }
      uint32_t r = json_get(&g->d, c, "rotation");
      uint64_t tc;
      if (r && N(g, r)->t != J_NUM) return gl_bad(g, "%s: KHR_texture_transform \"rotation\" must be a number", ctx);
      if (gl_uint(g, c, "texCoord", 0, 7, 0, &tc, ctx)) return g->err->status;
    }
    if ((N(g, c)->t == J_OBJ || N(g, c)->t == J_ARR) && !(k && !strcmp(k, "extras"))) {
      valo_status st = check_texture_refs(g, c, ctx);
      if (st) return st;
    }
  }
  return VALO_OK;
}

static valo_status check_texture(gc *g, uint32_t o, uint32_t i, const char *ctx) {
  (void)i;
  if (gl_index(g, o, "source", g->n[K_IMG], "image", 0, ctx) == -2 || gl_index(g, o, "sampler", g->n[K_SMP], "sampler", 0, ctx) == -2)
    return g->err->status;
  uint32_t ext = json_get(&g->d, o, "extensions");
  for (uint32_t c = ext && N(g, ext)->t == J_OBJ ? N(g, ext)->child : 0; c; c = N(g, c)->next)
    if (N(g, c)->t == J_OBJ && gl_index(g, c, "source", g->n[K_IMG], "image", 0, ctx) == -2) return g->err->status;
  return VALO_OK;
}

static valo_status check_image(gc *g, uint32_t o, uint32_t i, const char *ctx) {
  (void)i;
  uint32_t u = json_get(&g->d, o, "uri");
  if (u && N(g, u)->t != J_STR) return gl_bad(g, "%s: \"uri\" must be a string", ctx);
  if (u && !strncmp(N(g, u)->str, "data:", 5)) {
    if (gl_data_uri(g, N(g, u)->str, ctx) < 0) return g->err->status;
    free(g->decoded[--g->ndecoded]); /* only checked: Assimp decodes the image itself */
  }
  uint32_t mt = json_get(&g->d, o, "mimeType");
  /* Assimp reads through a null pointer when the type has no '/' */
  if (json_get(&g->d, o, "bufferView") && (!mt || N(g, mt)->t != J_STR || !strchr(N(g, mt)->str, '/')))
    return gl_bad(g, "%s: an image in a buffer view needs a \"mimeType\" such as image/png", ctx);
  return gl_index(g, o, "bufferView", g->n[K_VIEW], "buffer view", 0, ctx) == -2 ? g->err->status : VALO_OK;
}

static valo_status check_camera(gc *g, uint32_t o, uint32_t i, const char *ctx) {
  (void)i;
  uint32_t t = json_get(&g->d, o, "type");
  const char *type = t && N(g, t)->t == J_STR ? N(g, t)->str : "";
  if (strcmp(type, "perspective") && strcmp(type, "orthographic")) return gl_bad(g, "%s: \"type\" must be perspective or orthographic", ctx);
  uint32_t p = json_get(&g->d, o, type);
  if (!p || N(g, p)->t != J_OBJ) return gl_bad(g, "%s has no \"%s\" object", ctx, type);
  for (uint32_t c = N(g, p)->child; c; c = N(g, c)->next)
    if (N(g, c)->t != J_NUM && strcmp(N(g, c)->key, "extensions") && strcmp(N(g, c)->key, "extras")) return gl_bad(g, "%s: \"%s\" must be a number", ctx, N(g, c)->key);
  /* the view's size: Assimp takes an orthographic camera with xmag 0 for a perspective one */
  static const char *const mags[] = {"xmag", "ymag"};
  for (int k = 0; k < 2 && !strcmp(type, "orthographic"); k++) {
    uint32_t m = json_get(&g->d, p, mags[k]);
    if (!m || !(N(g, m)->num != 0) || !isfinite(N(g, m)->num)) return gl_bad(g, "%s: \"%s\" must be a number other than 0", ctx, mags[k]);
  }
  return VALO_OK;
}

static valo_status check_skin(gc *g, uint32_t o, uint32_t i, const char *ctx) {
  (void)i;
  uint32_t j = json_get(&g->d, o, "joints");
  if (!j || N(g, j)->t != J_ARR || N(g, j)->n == 0) return gl_bad(g, "%s: \"joints\" must be a non-empty array", ctx);
  if (gl_index_array(g, o, "joints", g->n[K_NODE], "node", ctx) || gl_index(g, o, "skeleton", g->n[K_NODE], "node", 0, ctx) == -2) return g->err->status;
  /* optional in glTF, but Assimp 5.2 reads through a null pointer without it */
  int64_t m = gl_accessor_ref(g, o, "inverseBindMatrices", 0, ctx);
  if (m == -2) return g->err->status;
  if (m == -1) {
    g->drop_skins = 1;
    return VALO_OK;
  }
  if ((g->accs[m].comps != 16 || g->accs[m].ctype != 5126 || g->accs[m].count < N(g, j)->n))
    return gl_bad(g, "%s: \"inverseBindMatrices\" must be MAT4 floats, one per joint", ctx);
  return VALO_OK;
}

static valo_status check_animation(gc *g, uint32_t o, uint32_t i, const char *ctx) {
  (void)i;
  int64_t ns = gl_objects(g, o, "samplers", "samplers"), nc = gl_objects(g, o, "channels", "channels");
  if (ns < 0 || nc < 0) return g->err->status;
  uint32_t sa = json_get(&g->d, o, "samplers"), ca = json_get(&g->d, o, "channels");
  for (uint32_t s = sa ? N(g, sa)->child : 0; s; s = N(g, s)->next) {
    int64_t in = gl_accessor_ref(g, s, "input", 1, ctx), out = in < 0 ? -2 : gl_accessor_ref(g, s, "output", 1, ctx);
    if (out < 0) return g->err->status;
    uint32_t ip = json_get(&g->d, s, "interpolation");
    int cubic = ip && N(g, ip)->t == J_STR && !strcmp(N(g, ip)->str, "CUBICSPLINE");
    if (g->accs[in].comps != 1 || g->accs[in].ctype != 5126) return gl_bad(g, "%s: a sampler's input must be float scalars", ctx);
    if (g->accs[out].count < g->accs[in].count * (cubic ? 3 : 1)) return gl_bad(g, "%s: a sampler has fewer outputs than its inputs ask for", ctx);
  }
  for (uint32_t c = ca ? N(g, ca)->child : 0; c; c = N(g, c)->next) {
    uint32_t t = json_get(&g->d, c, "target");
    if (gl_index(g, c, "sampler", (uint32_t)ns, "sampler of the animation", 1, ctx) < 0) return g->err->status;
    if (!t || N(g, t)->t != J_OBJ) return gl_bad(g, "%s: a channel has no \"target\" object", ctx);
    if (gl_index(g, t, "node", g->n[K_NODE], "node", 0, ctx) == -2) return g->err->status;
  }
  return VALO_OK;
}

static valo_status check_light(gc *g, uint32_t o, uint32_t i, const char *ctx) {
  (void)i;
  uint32_t t = json_get(&g->d, o, "type");
  const char *type = t && N(g, t)->t == J_STR ? N(g, t)->str : "";
  if (strcmp(type, "point") && strcmp(type, "spot") && strcmp(type, "directional")) return gl_bad(g, "%s: \"type\" must be point, spot or directional", ctx);
  return VALO_OK;
}

static valo_status check_scene(gc *g, uint32_t o, uint32_t i, const char *ctx) {
  (void)i;
  return gl_index_array(g, o, "nodes", g->n[K_NODE], "node", ctx) ? g->err->status : VALO_OK;
}

/* Member `key` of v when it is a number, else def. */
static double num_or(gc *g, uint32_t v, const char *key, double def) {
  uint32_t x = json_get(&g->d, v, key);
  return x && N(g, x)->t == J_NUM ? N(g, x)->num : def;
}
static double elem_or(gc *g, uint32_t v, const char *key, int k, double def) {
  uint32_t a = json_get(&g->d, v, key);
  uint32_t x = a && N(g, a)->t == J_ARR ? N(g, a)->child : 0;
  for (int j = 0; j < k && x; j++) x = N(g, x)->next;
  return x && N(g, x)->t == J_NUM ? N(g, x)->num : def;
}

/* Material i's signature and its KHR_materials_specular factors (its textures are not
 * read: a warning says so), for the loader (obj_check.h, gltf_mat). */
static valo_status record_material(gc *g, uint32_t o, uint32_t i, const char *ctx) {
  if (!g->oc->gmat) {
    if (!(g->oc->gmat = calloc((size_t)g->n[K_MAT] + 1, sizeof *g->oc->gmat))) return gl_bad(g, "out of memory");
    g->oc->ngmat = g->n[K_MAT];
  }
  gltf_mat *m = &g->oc->gmat[i];
  uint32_t nm = json_get(&g->d, o, "name"), pbr = json_get(&g->d, o, "pbrMetallicRoughness");
  snprintf(m->name, sizeof m->name, "%s", nm && N(g, nm)->t == J_STR ? N(g, nm)->str : "");
  for (int k = 0; k < 4; k++) m->base[k] = (float)elem_or(g, pbr, "baseColorFactor", k, 1);
  m->metallic = (float)num_or(g, pbr, "metallicFactor", 1);
  m->roughness = (float)num_or(g, pbr, "roughnessFactor", 1);
  for (int k = 0; k < 3; k++) m->emissive[k] = (float)elem_or(g, o, "emissiveFactor", k, 0);
  uint32_t sp = json_get(&g->d, json_get(&g->d, o, "extensions"), "KHR_materials_specular");
  m->specular[0] = (float)num_or(g, sp, "specularFactor", 1);
  for (int k = 0; k < 3; k++) m->specular[1 + k] = (float)elem_or(g, sp, "specularColorFactor", k, 1);
  for (int k = 0; k < 4; k++)
    if (!(m->specular[k] >= 0 && m->specular[k] < 1e6)) return gl_bad(g, "%s: KHR_materials_specular factors must be numbers from 0", ctx);
  if (sp && (json_get(&g->d, sp, "specularTexture") || json_get(&g->d, sp, "specularColorTexture")))
    log_warning("%s: %s: KHR_materials_specular's textures are not read (its factors are)", g->path, ctx);
  return VALO_OK;
}

static valo_status check_material(gc *g, uint32_t o, uint32_t i, const char *ctx) {
  valo_status st = check_texture_refs(g, o, ctx);
  return st ? st : record_material(g, o, i, ctx);
}

/* The extensions valo reads (Assimp imports them and valo uses what it imports;
 * KHR_mesh_quantization's integers valo turns into floats for Assimp, gltf_dequant.c). A file
 * that requires any other is refused, as the glTF specification asks of a loader; one
 * that only uses others is read with a warning naming them. */
static const char *const read_extensions[] = {"KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_transmission",
                                              "KHR_materials_ior", "KHR_materials_volume", "KHR_texture_transform", "KHR_materials_specular",
                                              "KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_mesh_quantization", "KHR_draco_mesh_compression", NULL};
static int is_read(const char *name) {
  for (int i = 0; read_extensions[i]; i++)
    if (!strcmp(name, read_extensions[i])) return 1;
  return 0;
}
static valo_status check_extensions(gc *g) {
  char unread[512] = "";
  for (int req = 1; req >= 0; req--) {
    const char *key = req ? "extensionsRequired" : "extensionsUsed";
    uint32_t a = json_get(&g->d, 1, key);
    if (!a) continue;
    if (N(g, a)->t != J_ARR) return gl_bad(g, "\"%s\" must be an array of names", key);
    for (uint32_t c = N(g, a)->child; c; c = N(g, c)->next) {
      if (N(g, c)->t != J_STR) return gl_bad(g, "\"%s\" must be an array of names", key);
      const char *name = N(g, c)->str;
      if (is_read(name)) continue;
      if (req) {
        char all[512] = "";
        for (int i = 0; read_extensions[i]; i++)
          snprintf(all + strlen(all), sizeof all - strlen(all), "%s%s", i == 0 ? "" : read_extensions[i + 1] ? ", " : " and ", read_extensions[i]);
        return gl_bad(g, "requires the extension %s, which valo does not read (it reads %s)", name, all);
      }
      if (strlen(unread) + strlen(name) + 3 < sizeof unread) snprintf(unread + strlen(unread), sizeof unread - strlen(unread), "%s%s", unread[0] ? ", " : "", name);
    }
  }
  if (unread[0]) log_warning("%s: uses %s, which valo does not read: it renders without them", g->path, unread);
  return VALO_OK;
}

valo_status gl_check_objects(gc *g) {
  valo_status st = check_extensions(g);
  if (!st) st = gl_each(g, g->arr[K_SCENE], "scene", check_scene);
  if (!st) st = gl_each(g, g->arr[K_MAT], "material", check_material);
  if (!st) st = gl_each(g, g->arr[K_TEX], "texture", check_texture);
  if (!st) st = gl_each(g, g->arr[K_IMG], "image", check_image);
  if (!st) st = gl_each(g, g->arr[K_CAM], "camera", check_camera);
  if (!st) st = gl_each(g, g->arr[K_SKIN], "skin", check_skin);
  if (!st) st = gl_each(g, g->arr[K_ANIM], "animation", check_animation);
  if (!st) st = gl_each(g, g->lights, "light", check_light);
  return st;
}
