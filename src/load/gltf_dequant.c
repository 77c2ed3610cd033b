/* gltf_dequant.c — owns rewriting the glTF Assimp reads where Assimp would misread it:
 * Draco's 32-bit indices given as 16-bit ones (gltf_draco.c), and, as floats, the vertex
 * attributes a glTF stores as integers: normalized texture coordinates (core glTF) and KHR_mesh_quantization's
 * positions, normals, tangents and texture coordinates. Assimp 5.2 copies their bytes as if
 * they were floats (positions of 1e-42, texture coordinates of NaN), so each marked
 * accessor is decoded here (its stride and sparse part applied; normalized values as glTF
 * defines them: c/255, c/65535, max(c/127, -1), max(c/32767, -1)) into a new buffer, and the
 * JSON is rewritten (cJSON) to read it there as floats: the file Assimp is served is the
 * rewritten text, or a .glb of the rewritten JSON chunk and the original BIN chunk. */
#include "load/gltf_check_internal.h"
#include "core/error.h"
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Component c of type ct at p as glTF reads it. */
static float component(const unsigned char *p, int ct, int normalized) {
  switch (ct) {
    case 5120: { double v = (int8_t)p[0]; return (float)(normalized ? fmax(v / 127.0, -1.0) : v); }
    case 5121: return (float)(normalized ? p[0] / 255.0 : p[0]);
    case 5122: { double v = (int16_t)gl_le_uint(p, 2); return (float)(normalized ? fmax(v / 32767.0, -1.0) : v); }
    case 5123: { double v = gl_le_uint(p, 2); return (float)(normalized ? v / 65535.0 : v); }
    default: { float f; memcpy(&f, p, 4); return f; }
  }
}

/* The bytes of accessor a as floats. */
static uint64_t float_bytes(const gacc *a) { return a->count * (uint64_t)a->comps * sizeof(float); }

/* Accessor a's count x comps values into out. */
static void decode(const gc *g, const gacc *a, float *out) {
  int cs = (int)(a->size / (uint64_t)a->comps);
  if (a->view >= 0) {
    const gview *v = &g->views[a->view];
    const unsigned char *base = g->bufs[v->buf].data + v->off + a->off;
    for (uint64_t e = 0; e < a->count; e++)
      for (int k = 0; k < a->comps; k++) out[e * a->comps + k] = component(base + e * a->stride + (uint64_t)k * cs, a->ctype, a->normalized);
  } else {
    memset(out, 0, a->count * a->comps * sizeof *out); /* a sparse accessor over zeros */
  }
  for (uint64_t s = 0; s < (a->sparse ? a->sparse_n : 0); s++) { /* indices checked to lie inside (check_sparse) */
    uint64_t e = gl_le_uint(a->sparse_index + s * a->sparse_isize, (uint64_t)a->sparse_isize);
    for (int k = 0; k < a->comps; k++) out[e * a->comps + k] = component(a->sparse_values + s * a->size + (uint64_t)k * cs, a->ctype, a->normalized);
  }
}

static int set_number(cJSON *o, const char *key, double v) {
  cJSON *n = cJSON_CreateNumber(v);
  if (!n) return -1;
  if (cJSON_GetObjectItemCaseSensitive(o, key)) return cJSON_ReplaceItemInObjectCaseSensitive(o, key, n) ? 0 : -1;
  return cJSON_AddItemToObject(o, key, n) ? 0 : -1;
}

/* The accessor's bounds, as the decoded values have them, where the file gave some. */
static int set_bounds(cJSON *acc, const float *v, uint64_t count, int comps) {
  for (int m = 0; m < 2; m++) {
    const char *key = m ? "max" : "min";
    if (!cJSON_GetObjectItemCaseSensitive(acc, key)) continue;
    double b[4];
    for (int k = 0; k < comps; k++) {
      b[k] = v[k];
      for (uint64_t e = 1; e < count; e++) b[k] = m ? fmax(b[k], v[e * comps + k]) : fmin(b[k], v[e * comps + k]);
    }
    cJSON *arr = cJSON_CreateDoubleArray(b, comps);
    if (!arr || !cJSON_ReplaceItemInObjectCaseSensitive(acc, key, arr)) { cJSON_Delete(arr); return -1; }
  }
  return 0;
}

/* The rewritten JSON (malloc'd, NUL-ended) pointing the marked accessors at buffer `uri`
 * of the floats in out; NULL when out of memory. */
static char *rewrite(const gc *g, cJSON *root, const float *out, uint64_t total, const char *uri) {
  cJSON *bufs = cJSON_GetObjectItemCaseSensitive(root, "buffers"), *accs = cJSON_GetObjectItemCaseSensitive(root, "accessors");
  cJSON *views = cJSON_GetObjectItemCaseSensitive(root, "bufferViews");
  if (!views && !(views = cJSON_AddArrayToObject(root, "bufferViews"))) return NULL;
  int nb = cJSON_GetArraySize(bufs), nv = cJSON_GetArraySize(views);
  uint64_t off = 0;
  for (uint32_t i = 0; i < g->n[K_ACC]; i++) {
    if (g->deq[i] == 2) { /* Draco's 32-bit indices, as 16-bit ones (gltf_draco.c) */
      cJSON *acc = cJSON_GetArrayItem(accs, (int)i);
      if (!acc || set_number(acc, "componentType", 5123)) return NULL;
    }
    if (g->deq[i] != 1) continue;
    const gacc *a = &g->accs[i];
    uint64_t bytes = float_bytes(a);
    cJSON *acc = cJSON_GetArrayItem(accs, (int)i), *view = cJSON_CreateObject();
    if (!acc || !view || !cJSON_AddItemToArray(views, view)) { cJSON_Delete(view); return NULL; }
    if (set_number(view, "buffer", nb) || set_number(view, "byteOffset", (double)off) || set_number(view, "byteLength", (double)bytes) ||
        set_number(acc, "componentType", 5126) || set_number(acc, "bufferView", nv++) || set_bounds(acc, out + off / 4, a->count, a->comps))
      return NULL;
    cJSON_DeleteItemFromObjectCaseSensitive(acc, "byteOffset");
    cJSON_DeleteItemFromObjectCaseSensitive(acc, "normalized");
    cJSON_DeleteItemFromObjectCaseSensitive(acc, "sparse");
    off += bytes;
  }
  if (!total) return cJSON_PrintUnformatted(root);
  cJSON *buf = cJSON_CreateObject();
  if (!buf || !cJSON_AddItemToArray(bufs, buf)) { cJSON_Delete(buf); return NULL; }
  if (set_number(buf, "byteLength", (double)total) || !cJSON_AddStringToObject(buf, "uri", uri)) return NULL;
  return cJSON_PrintUnformatted(root);
}

/* A .glb of json and the BIN chunk (when the file has one): malloc'd, *len bytes. */
static unsigned char *glb(const gc *g, const char *json, size_t *len) {
  size_t jl = strlen(json), jp = (jl + 3) & ~(size_t)3, bl = g->has_bin ? (size_t)g->bin_len : 0, bp = (bl + 3) & ~(size_t)3;
  size_t n = 12 + 8 + jp + (g->has_bin ? 8 + bp : 0);
  if (n > UINT32_MAX) return NULL;
  unsigned char *b = calloc(n, 1);
  if (!b) return NULL;
  uint32_t w[5] = {0x46546C67u, 2, (uint32_t)n, (uint32_t)jp, GLB_JSON};
  memcpy(b, w, sizeof w); /* little-endian, as valo's targets are */
  memcpy(b + 20, json, jl);
  memset(b + 20 + jl, ' ', jp - jl);
  if (g->has_bin) {
    uint32_t c[2] = {(uint32_t)bp, GLB_BIN};
    memcpy(b + 20 + jp, c, sizeof c);
    memcpy(b + 28 + jp, g->bin, bl);
  }
  *len = n;
  return b;
}

valo_status gl_dequantize(gc *g, const char *json, size_t json_len, int binary) {
  obj_check *oc = g->oc;
  uint64_t total = 0;
  for (uint32_t i = 0; i < g->n[K_ACC]; i++)
    if (g->deq[i] == 1) total += float_bytes(&g->accs[i]);
  if (total && oc->nfiles == (int)(sizeof oc->files / sizeof oc->files[0]))
    return gl_bad(g, "integer vertex attributes need a buffer of floats, and the file has the most buffer files valo reads");
  if (total > UINT32_MAX) return gl_bad(g, "its integer vertex attributes are more than 4 GiB as floats");
  float *out = malloc(total ? total : 1);
  if (!out) return gl_bad(g, "out of memory");
  uint64_t off = 0;
  for (uint32_t i = 0; i < g->n[K_ACC]; i++)
    if (g->deq[i] == 1) { decode(g, &g->accs[i], out + off / 4); off += float_bytes(&g->accs[i]); }
  /* the new buffer's name: beside the file, where no file it serves already is (a slot
   * is free when there are floats: checked above) */
  obj_text *t = total ? &oc->files[oc->nfiles] : NULL;
  const char *slash = strrchr(g->path, '/');
  int dl = slash ? (int)(slash - g->path + 1) : 0;
  char uri[64] = "";
  for (int k = 0; t; k++) {
    snprintf(uri, sizeof uri, "valo-dequantized-%d.bin", k);
    snprintf(t->path, sizeof t->path, "%.*s%s", dl, g->path, uri);
    int taken = 0;
    for (int f = 0; f < oc->nfiles; f++) taken |= !strcmp(oc->files[f].path, t->path);
    if (!taken) break;
  }
  cJSON *root = cJSON_ParseWithLength(json, json_len);
  char *text = root ? rewrite(g, root, out, total, uri) : NULL;
  cJSON_Delete(root);
  size_t len = text ? strlen(text) : 0;
  if (text && binary) {
    unsigned char *b = glb(g, text, &len);
    free(text);
    text = (char *)b;
  }
  if (!text) { free(out); return gl_bad(g, "out of memory"); }
  free(oc->files[0].text); /* g->bin pointed into it: used above, not after */
  oc->files[0].text = text;
  oc->files[0].len = len;
  if (!t) { free(out); return VALO_OK; }
  t->text = (char *)out;
  t->len = total;
  oc->nfiles++;
  return VALO_OK;
}
