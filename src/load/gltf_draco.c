/* gltf_draco.c — owns glTF's KHR_draco_mesh_compression as valo hands it to Assimp, which
 * decodes it with Draco: the extension's objects checked, the accessors it feeds allowed
 * to hold no data of their own, and Assimp 5.2's loss of 32-bit Draco indices (it fills
 * its index buffer, then returns before installing it: "Invalid accessor without data")
 * avoided by giving Assimp those indices as unsigned shorts where every index fits (at
 * most 65 536 vertices; a larger such primitive is refused, naming why). */
#include "load/gltf_check_internal.h"
#include <stdio.h>
#include <string.h>

static valo_status mark_primitive(gc *g, uint32_t p, const char *ctx) {
  uint32_t ext = json_get(&g->d, json_get(&g->d, p, "extensions"), "KHR_draco_mesh_compression");
  if (!ext) return VALO_OK;
  uint32_t at = json_get(&g->d, p, "attributes"), da = json_get(&g->d, ext, "attributes");
  if (N(g, ext)->t != J_OBJ || !da || N(g, da)->t != J_OBJ || !at || N(g, at)->t != J_OBJ)
    return gl_bad(g, "%s: KHR_draco_mesh_compression must be an object with \"attributes\"", ctx);
  if (gl_index(g, ext, "bufferView", g->n[K_VIEW], "buffer view", 1, ctx) < 0) return g->err->status;
  for (uint32_t c = N(g, da)->child; c; c = N(g, c)->next) {
    if (N(g, c)->t != J_NUM || !N(g, c)->is_int || N(g, c)->num < 0 || N(g, c)->num > 65535)
      return gl_bad(g, "%s: KHR_draco_mesh_compression attribute %s must be a Draco attribute id", ctx, N(g, c)->key);
    int64_t a = gl_accessor_ref(g, at, N(g, c)->key, 0, ctx);
    if (a == -2) return g->err->status;
    if (a < 0) return gl_bad(g, "%s: KHR_draco_mesh_compression compresses %s, which the primitive's attributes lack", ctx, N(g, c)->key);
    g->draco[a] = 1;
  }
  int64_t ix = gl_accessor_ref(g, p, "indices", 0, ctx);
  if (ix == -2) return g->err->status;
  if (ix >= 0) g->draco[ix] = 1;
  return VALO_OK;
}

valo_status gl_draco_mark(gc *g) {
  uint32_t i = 0;
  for (uint32_t m = g->arr[K_MESH] ? N(g, g->arr[K_MESH])->child : 0; m; m = N(g, m)->next, i++) {
    uint32_t pr = json_get(&g->d, m, "primitives"), k = 0;
    for (uint32_t p = pr && N(g, pr)->t == J_ARR ? N(g, pr)->child : 0; p; p = N(g, p)->next, k++) {
      char ctx[64];
      snprintf(ctx, sizeof ctx, "mesh %u primitive %u", i, k);
      if (N(g, p)->t == J_OBJ && mark_primitive(g, p, ctx)) return g->err->status;
    }
  }
  return VALO_OK;
}

valo_status gl_draco_indices(gc *g, int64_t ix, uint64_t nverts, const char *ctx) {
  const gacc *a = &g->accs[ix];
  if (a->ctype != 5125 || a->view >= 0) return VALO_OK; /* 8- and 16-bit indices Assimp installs; a view's it reads there */
  if (nverts > 65536)
    return gl_bad(g, "%s: a Draco-compressed primitive of %llu vertices with 32-bit indices is not read (Assimp 5.2 loses such indices; "
                     "at most 65 536 vertices are given to it as 16-bit ones)", ctx, (unsigned long long)nverts);
  if (!g->deq[ix]) { g->deq[ix] = 2; g->ndeq++; }
  return VALO_OK;
}
