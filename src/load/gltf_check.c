/* gltf_check.c — see gltf_check.h. Reads the file (and its buffer files) once, parses the
 * JSON strictly (gltf_json.c), then checks each kind of object against the ones it names:
 * here the .glb container, buffers, buffer views, accessors and meshes (primitive indices
 * read from the buffers themselves); the other objects in gltf_objects.c. */
#include "load/gltf_check_internal.h"
#include "core/error.h"
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

valo_status gl_bad(gc *g, const char *fmt, ...) {
  char msg[400];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return err_set(g->err, VALO_ERR_PARSE, "%s: glTF: %s", g->path, msg);
}

/* A top-level array (or one inside object o) of objects: its count, or -1 (error set). */
int64_t gl_objects(gc *g, uint32_t o, const char *key, const char *what) {
  uint32_t a = json_get(&g->d, o, key);
  if (!a) return 0;
  if (N(g, a)->t != J_ARR) return gl_bad(g, "\"%s\" must be an array", what), -1;
  for (uint32_t c = N(g, a)->child; c; c = N(g, c)->next)
    if (N(g, c)->t != J_OBJ) return gl_bad(g, "every entry of \"%s\" must be an object", what), -1;
  return N(g, a)->n;
}

valo_status gl_each(gc *g, uint32_t arr, const char *kind, valo_status (*fn)(gc *, uint32_t, uint32_t, const char *)) {
  uint32_t i = 0;
  for (uint32_t o = arr ? N(g, arr)->child : 0; o; o = N(g, o)->next, i++) {
    char ctx[64];
    snprintf(ctx, sizeof ctx, "%s %u", kind, i);
    valo_status st = fn(g, o, i, ctx);
    if (st) return st;
  }
  return VALO_OK;
}

/* Member key of object o as an unsigned integer written as one: 0 and *v = def when
 * absent (an error when required), -1 (error set) when it is not such a number or above max. */
int gl_uint(gc *g, uint32_t o, const char *key, uint64_t def, uint64_t max, int required, uint64_t *v, const char *ctx) {
  uint32_t m = json_get(&g->d, o, key);
  *v = def;
  if (!m) return required ? (gl_bad(g, "%s has no \"%s\"", ctx, key), -1) : 0;
  const jnode *n = N(g, m);
  if (n->t != J_NUM || !n->is_int || n->num < 0 || n->num > (double)max)
    return gl_bad(g, "%s: \"%s\" must be a whole number from 0 to %llu", ctx, key, (unsigned long long)max), -1;
  *v = (uint64_t)n->num;
  return 0;
}

/* Member key of o as an index of `count` objects called `of`: -1 when absent (an error
 * when required), -2 (error set) when it names none of them. */
int64_t gl_index(gc *g, uint32_t o, const char *key, uint32_t count, const char *of, int required, const char *ctx) {
  uint32_t m = json_get(&g->d, o, key);
  if (!m) return required ? (gl_bad(g, "%s has no \"%s\"", ctx, key), -2) : -1;
  const jnode *n = N(g, m);
  if (n->t != J_NUM || !n->is_int || n->num < 0 || n->num >= (double)count)
    return gl_bad(g, "%s: \"%s\" names no %s (the file has %u)", ctx, key, of, count), -2;
  return (int64_t)n->num;
}

/* Every element of array member key of o an index of `count` objects; -1 (error set) if not. */
int gl_index_array(gc *g, uint32_t o, const char *key, uint32_t count, const char *of, const char *ctx) {
  uint32_t a = json_get(&g->d, o, key);
  if (!a) return 0;
  if (N(g, a)->t != J_ARR) return gl_bad(g, "%s: \"%s\" must be an array", ctx, key), -1;
  for (uint32_t c = N(g, a)->child; c; c = N(g, c)->next)
    if (N(g, c)->t != J_NUM || !N(g, c)->is_int || N(g, c)->num < 0 || N(g, c)->num >= (double)count)
      return gl_bad(g, "%s: \"%s\" names no %s (the file has %u)", ctx, key, of, count), -1;
  return 0;
}

/* ------------------------------------------------------------------ files */

static int b64(int c) {
  return c >= 'A' && c <= 'Z' ? c - 'A' : c >= 'a' && c <= 'z' ? c - 'a' + 26 : c >= '0' && c <= '9' ? c - '0' + 52 : c == '+' ? 62 : c == '/' ? 63 : -1;
}

/* Base64 text (len a multiple of 4, '=' only as the last one or two) into out; its length or -1. */
static int64_t b64_decode(const char *s, size_t len, unsigned char *out) {
  if (len % 4) return -1;
  size_t o = 0;
  for (size_t i = 0; i < len; i += 4) {
    int pad = (s[i + 3] == '=') + (s[i + 2] == '=' && s[i + 3] == '=');
    if (pad && i + 4 != len) return -1;
    int v[4];
    for (int k = 0; k < 4 - pad; k++)
      if ((v[k] = b64((unsigned char)s[i + k])) < 0) return -1;
    out[o++] = (unsigned char)(v[0] << 2 | v[1] >> 4);
    if (pad < 2) out[o++] = (unsigned char)((v[1] & 15) << 4 | v[2] >> 2);
    if (pad < 1) out[o++] = (unsigned char)((v[2] & 3) << 6 | v[3]);
  }
  return (int64_t)o;
}

/* A data URI (buffer or image): "data:", a media type, ";base64," and base64 text,
 * decoded into g->decoded; its length, or -1 (error set). Assimp keeps the offsets of
 * the URI's parts in chars (signed here), so a header of 128 bytes or more would point it
 * before the string, and it decodes base64 through a table indexed by signed chars, so
 * only a short header and valid base64 pass. */
int64_t gl_data_uri(gc *g, const char *s, const char *ctx) {
  const char *comma = strchr(s, ',');
  int ok = comma && comma - s >= 12 && comma - s < 100 && !strncmp(comma - 7, ";base64", 7);
  for (const char *c = s; ok && c < comma; c++) ok = *c > 0x20 && *c < 0x7f && *c != ',';
  const char *semi = ok ? strchr(s, ';') : NULL;
  if (semi && semi > s + 5 && !memchr(s + 5, '/', (size_t)(semi - s - 5))) ok = 0; /* Assimp takes what follows a '/' */
  if (!ok) return gl_bad(g, "%s: a data URI valo reads is \"data:TYPE/SUBTYPE;base64,DATA\" with a short type", ctx), -1;
  size_t len = strlen(comma + 1);
  unsigned char *d = malloc(len / 4 * 3 + 1);
  if (!d || g->ndecoded == (int)(sizeof g->decoded / sizeof g->decoded[0])) { free(d); return gl_bad(g, "%s: out of memory, or more than 64 data URIs", ctx), -1; }
  g->decoded[g->ndecoded++] = d;
  int64_t n = b64_decode(comma + 1, len, d);
  if (n < 0) return gl_bad(g, "%s: the data URI is not valid base64", ctx), -1;
  return n;
}

/* The bytes of buffer i: the .glb's BIN chunk, a base64 data URI, or a file beside the
 * glTF (read into oc, to be served to Assimp). */
static valo_status read_buffer(gc *g, uint32_t i, uint32_t o) {
  char ctx[48];
  snprintf(ctx, sizeof ctx, "buffer %u", i);
  uint64_t stated;
  if (gl_uint(g, o, "byteLength", 0, (uint64_t)1 << 32, 1, &stated, ctx)) return g->err->status;
  if (stated == 0) return gl_bad(g, "%s: \"byteLength\" must be at least 1", ctx);
  uint32_t u = json_get(&g->d, o, "uri");
  gbuf *b = &g->bufs[i];
  if (!u) {
    if (!g->has_bin || i != 0) return gl_bad(g, "%s has no \"uri\" (only the first buffer of a .glb with a BIN chunk may lack one)", ctx);
    if (g->bin_len < stated) return gl_bad(g, "%s: \"byteLength\" %llu is past the end of the BIN chunk (%llu bytes)", ctx, (unsigned long long)stated, (unsigned long long)g->bin_len);
    *b = (gbuf){g->bin, stated};
    return VALO_OK;
  }
  if (N(g, u)->t != J_STR) return gl_bad(g, "%s: \"uri\" must be a string", ctx);
  const char *s = N(g, u)->str;
  if (!strncmp(s, "data:", 5)) {
    int64_t n = gl_data_uri(g, s, ctx);
    if (n < 0) return g->err->status;
    if ((uint64_t)n != stated) return gl_bad(g, "%s: the data URI holds %lld bytes, \"byteLength\" says %llu", ctx, (long long)n, (unsigned long long)stated);
    *b = (gbuf){g->decoded[g->ndecoded - 1], stated};
    return VALO_OK;
  }
  if (strstr(s, "://")) return gl_bad(g, "%s: \"uri\" %s is not a file valo can read", ctx, s);
  if (g->oc->nfiles == (int)(sizeof g->oc->files / sizeof g->oc->files[0]))
    return gl_bad(g, "%s: more than %d buffer files", ctx, (int)(sizeof g->oc->files / sizeof g->oc->files[0]) - 1);
  obj_text *t = &g->oc->files[g->oc->nfiles];
  const char *slash = strrchr(g->path, '/');
  int dl = slash ? (int)(slash - g->path + 1) : 0;
  if (snprintf(t->path, sizeof t->path, "%.*s%s", dl, g->path, s) >= (int)sizeof t->path) return gl_bad(g, "%s: \"uri\" is too long", ctx);
  size_t len = 0;
  if (!(t->text = obj_check_read_whole(t->path, &len)) && strchr(s, '%')) { /* a URI's escapes (%20): the file's own name */
    char *q = t->path + dl;
    for (const char *c = s; *c; c++) {
      unsigned v;
      if (c[0] == '%' && c[1] && c[2] && sscanf(c + 1, "%2x", &v) == 1 && v) { *q++ = (char)v; c += 2; }
      else *q++ = *c;
    }
    *q = 0;
    t->text = obj_check_read_whole(t->path, &len);
    if (t->text) snprintf(t->path, sizeof t->path, "%.*s%s", dl, g->path, s); /* served by the name Assimp asks for */
  }
  if (!t->text) return gl_bad(g, "%s: cannot read %s: %s", ctx, t->path, strerror(errno));
  t->len = len;
  g->oc->nfiles++;
  if (len < stated) return gl_bad(g, "%s: %s holds %zu bytes, \"byteLength\" says %llu", ctx, t->path, len, (unsigned long long)stated);
  *b = (gbuf){(const unsigned char *)t->text, stated};
  return VALO_OK;
}

uint32_t gl_le_uint(const unsigned char *p, uint64_t bytes) {
  uint32_t x = 0;
  for (uint64_t b = bytes; b-- > 0;) x = x << 8 | p[b];
  return x;
}

/* The first of n indices of `bytes` bytes at d that is limit or more (its value in *x), or -1. */
static int64_t first_index_past(const unsigned char *d, uint64_t n, uint64_t bytes, uint64_t limit, uint32_t *x) {
  for (uint64_t k = 0; k < n; k++)
    if ((*x = gl_le_uint(d + k * bytes, bytes)) >= limit) return (int64_t)k;
  return -1;
}

/* ---------------------------------------------------- views and accessors */

static int comp_size(int ct) { return ct == 5120 || ct == 5121 ? 1 : ct == 5122 || ct == 5123 ? 2 : ct == 5125 || ct == 5126 ? 4 : 0; }

static int type_comps(const char *s) {
  static const char *names[] = {"SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"};
  static const int comps[] = {1, 2, 3, 4, 4, 9, 16};
  for (int i = 0; i < 7; i++)
    if (!strcmp(s, names[i])) return comps[i];
  return 0;
}

static valo_status check_view(gc *g, uint32_t o, uint32_t i, const char *ctx) {
  gview *v = &g->views[i];
  int64_t b = gl_index(g, o, "buffer", g->n[K_BUF], "buffer", 1, ctx);
  if (b < 0) return g->err->status;
  v->buf = (uint32_t)b;
  if (gl_uint(g, o, "byteOffset", 0, UINT32_MAX, 0, &v->off, ctx) || gl_uint(g, o, "byteLength", 0, UINT32_MAX, 1, &v->len, ctx) ||
      gl_uint(g, o, "byteStride", 0, 252, 0, &v->stride, ctx))
    return g->err->status;
  if (json_get(&g->d, o, "byteStride") && (v->stride < 4 || v->stride % 4)) return gl_bad(g, "%s: \"byteStride\" must be a multiple of 4 from 4 to 252", ctx);
  if (v->len == 0 || v->off + v->len > g->bufs[v->buf].len)
    return gl_bad(g, "%s: bytes %llu to %llu are outside buffer %u (%llu bytes)", ctx, (unsigned long long)v->off,
               (unsigned long long)(v->off + v->len), v->buf, (unsigned long long)g->bufs[v->buf].len);
  return VALO_OK;
}

/* An accessor's sparse part: count, index and value views that hold them, indices inside
 * the accessor (Assimp writes each value at its index: a count past the data overflowed
 * its heap). */
static valo_status check_sparse(gc *g, uint32_t sp, gacc *a, const char *acc_ctx) {
  char ctx[80];
  snprintf(ctx, sizeof ctx, "%s sparse", acc_ctx);
  uint32_t ix = json_get(&g->d, sp, "indices"), vx = json_get(&g->d, sp, "values");
  if (N(g, sp)->t != J_OBJ || !ix || N(g, ix)->t != J_OBJ || !vx || N(g, vx)->t != J_OBJ)
    return gl_bad(g, "%s must be an object with \"indices\" and \"values\" objects", ctx);
  uint64_t n, ct, ioff, voff;
  int64_t iv = gl_index(g, ix, "bufferView", g->n[K_VIEW], "buffer view", 1, ctx);
  int64_t vv = iv < 0 ? -2 : gl_index(g, vx, "bufferView", g->n[K_VIEW], "buffer view", 1, ctx);
  if (vv < 0 || gl_uint(g, sp, "count", 0, a->count, 1, &n, ctx) || gl_uint(g, ix, "componentType", 0, 6000, 1, &ct, ctx) ||
      gl_uint(g, ix, "byteOffset", 0, UINT32_MAX, 0, &ioff, ctx) || gl_uint(g, vx, "byteOffset", 0, UINT32_MAX, 0, &voff, ctx))
    return g->err->status;
  if (n == 0) return gl_bad(g, "%s: \"count\" must be at least 1", ctx);
  if (ct != 5121 && ct != 5123 && ct != 5125) return gl_bad(g, "%s: indices must be unsigned bytes, shorts or ints", ctx);
  uint64_t cs = (uint64_t)comp_size((int)ct);
  const gview *v = &g->views[iv], *w = &g->views[vv];
  if ((v->stride && v->stride != cs) || (w->stride && w->stride != a->size)) return gl_bad(g, "%s: its buffer views must not have a stride", ctx);
  if (ioff + n * cs > v->len || voff + n * a->size > w->len)
    return gl_bad(g, "%s: %llu elements do not fit in buffer views %lld and %lld", ctx, (unsigned long long)n, (long long)iv, (long long)vv);
  uint32_t x;
  int64_t k = first_index_past(g->bufs[v->buf].data + v->off + ioff, n, cs, a->count, &x);
  if (k >= 0) return gl_bad(g, "%s: index %lld is %u, past the accessor's %llu elements", ctx, (long long)k, x, (unsigned long long)a->count);
  a->sparse_values = g->bufs[w->buf].data + w->off + voff;
  a->sparse_index = g->bufs[v->buf].data + v->off + ioff;
  a->sparse_isize = (int)cs;
  a->sparse_n = n;
  return VALO_OK;
}

static valo_status check_accessor(gc *g, uint32_t o, uint32_t i, const char *ctx) {
  gacc *a = &g->accs[i];
  uint64_t ct;
  if (gl_uint(g, o, "componentType", 0, 6000, 1, &ct, ctx) || gl_uint(g, o, "count", 0, UINT32_MAX, 1, &a->count, ctx) ||
      gl_uint(g, o, "byteOffset", 0, UINT32_MAX, 0, &a->off, ctx))
    return g->err->status;
  a->ctype = (int)ct;
  uint32_t t = json_get(&g->d, o, "type");
  a->comps = t && N(g, t)->t == J_STR ? type_comps(N(g, t)->str) : 0;
  if (!comp_size(a->ctype)) return gl_bad(g, "%s: \"componentType\" %d is not one of glTF's", ctx, a->ctype);
  if (!a->comps) return gl_bad(g, "%s: \"type\" must be SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4", ctx);
  if (a->count == 0) return gl_bad(g, "%s: \"count\" must be at least 1", ctx);
  uint32_t sp = json_get(&g->d, o, "sparse"), nz = json_get(&g->d, o, "normalized");
  a->sparse = sp != 0;
  a->normalized = nz && N(g, nz)->t == J_TRUE;
  a->size = (uint64_t)comp_size(a->ctype) * (uint64_t)a->comps;
  a->view = gl_index(g, o, "bufferView", g->n[K_VIEW], "buffer view", 0, ctx);
  if (a->view == -2) return g->err->status;
  if (a->view < 0 && !sp) {
    if (g->draco[i]) return VALO_OK; /* Assimp fills it from the Draco data */
    return gl_bad(g, "%s has no \"bufferView\" and is not sparse (Assimp reads no accessor of zeros)", ctx);
  }
  if (sp) {
    valo_status st = check_sparse(g, sp, a, ctx);
    if (st || a->view < 0) return st;
  }
  const gview *v = &g->views[a->view];
  a->stride = v->stride ? v->stride : a->size;
  if (a->stride < a->size) return gl_bad(g, "%s: its elements (%llu bytes) are longer than buffer view %lld's stride", ctx, (unsigned long long)a->size, (long long)a->view);
  if (a->off + a->stride * (a->count - 1) + a->size > v->len)
    return gl_bad(g, "%s: %llu elements from byte %llu do not fit in buffer view %lld (%llu bytes)", ctx, (unsigned long long)a->count,
               (unsigned long long)a->off, (long long)a->view, (unsigned long long)v->len);
  return VALO_OK;
}

/* Accessor member key of o: its index, -1 when absent, -2 (error set) when wrong. */
int64_t gl_accessor_ref(gc *g, uint32_t o, const char *key, int required, const char *ctx) {
  return gl_index(g, o, key, g->n[K_ACC], "accessor", required, ctx);
}

/* ------------------------------------------------------------------ meshes */

/* A vertex attribute Assimp turns into positions, normals, tangents or texture
 * coordinates: floats, or the integers glTF (normalized texture coordinates) and
 * KHR_mesh_quantization allow, which are marked to be given to Assimp as floats. */
static valo_status check_vertex_attribute(gc *g, const char *name, int64_t i, int draco, const char *ctx) {
  static const struct { const char *name; int comps; unsigned ints, normalized_ints; } rules[] = {
      /* bit k of a mask: componentType 5120 + k allowed (byte, unsigned byte, short, unsigned short) */
      {"POSITION", 3, 0xf, 0xf}, {"NORMAL", 3, 0, 0x5}, {"TANGENT", 4, 0, 0x5}, {"TEXCOORD_", 2, 0xf, 0xf}};
  for (size_t r = 0; r < sizeof rules / sizeof rules[0]; r++) {
    size_t nl = strlen(rules[r].name);
    if (rules[r].name[nl - 1] == '_' ? strncmp(name, rules[r].name, nl) : strcmp(name, rules[r].name)) continue;
    const gacc *a = &g->accs[i];
    int k = a->ctype - 5120;
    unsigned mask = a->normalized ? rules[r].normalized_ints : rules[r].ints;
    if (a->comps != rules[r].comps || (a->ctype != 5126 && !(k >= 0 && k < 4 && ((mask >> k) & 1))))
      return gl_bad(g, "%s: %s must be %d-component floats%s", ctx, name, rules[r].comps,
                    r == 0 || r == 3 ? ", or bytes or shorts (normalized or not)" : ", or normalized bytes or shorts");
    if (a->ctype != 5126 && draco) return gl_bad(g, "%s: a Draco-compressed %s of integers is not read (floats are)", ctx, name);
    if (a->ctype != 5126 && !g->deq[i]) { g->deq[i] = 1; g->ndeq++; }
    return VALO_OK;
  }
  return VALO_OK;
}

static valo_status check_primitive(gc *g, uint32_t p, const char *ctx) {
  uint32_t at = json_get(&g->d, p, "attributes");
  if (!at || N(g, at)->t != J_OBJ) return gl_bad(g, "%s has no \"attributes\" object", ctx);
  int64_t pos = gl_accessor_ref(g, at, "POSITION", 1, ctx);
  if (pos < 0) return g->err->status;
  const gacc *pa = &g->accs[pos];
  int draco = json_get(&g->d, json_get(&g->d, p, "extensions"), "KHR_draco_mesh_compression") != 0;
  for (uint32_t c = N(g, at)->child; c; c = N(g, c)->next) {
    int64_t a = gl_accessor_ref(g, at, N(g, c)->key, 1, ctx);
    if (a < 0) return g->err->status;
    if (g->accs[a].count != pa->count) return gl_bad(g, "%s: attribute %s has %llu elements, POSITION %llu", ctx, N(g, c)->key,
                                                 (unsigned long long)g->accs[a].count, (unsigned long long)pa->count);
    if (check_vertex_attribute(g, N(g, c)->key, a, draco, ctx)) return g->err->status;
    if (g->accs[a].comps > 4) return gl_bad(g, "%s: attribute %s must be a scalar or a vector", ctx, N(g, c)->key);
  }
  uint64_t mode;
  if (gl_uint(g, p, "mode", 4, 6, 0, &mode, ctx)) return g->err->status;
  if (gl_index(g, p, "material", g->n[K_MAT], "material", 0, ctx) == -2) return g->err->status;
  uint32_t tg = json_get(&g->d, p, "targets");
  if (tg) {
    if (N(g, tg)->t != J_ARR) return gl_bad(g, "%s: \"targets\" must be an array", ctx);
    for (uint32_t t = N(g, tg)->child; t; t = N(g, t)->next) {
      if (N(g, t)->t != J_OBJ) return gl_bad(g, "%s: every morph target must be an object", ctx);
      for (uint32_t c = N(g, t)->child; c; c = N(g, c)->next) {
        int64_t a = gl_accessor_ref(g, t, N(g, c)->key, 1, ctx);
        if (a < 0) return g->err->status;
        if (g->accs[a].count != pa->count || g->accs[a].comps != 3 || g->accs[a].ctype != 5126)
          return gl_bad(g, "%s: morph target attribute %s must be %llu VEC3 floats", ctx, N(g, c)->key, (unsigned long long)pa->count);
      }
    }
  }
  int64_t ix = gl_accessor_ref(g, p, "indices", 0, ctx);
  if (ix == -2) return g->err->status;
  /* Assimp counts a strip's or a loop's elements as vertices minus 2 or 1, in unsigned arithmetic */
  static const uint64_t least[7] = {1, 2, 2, 2, 3, 3, 3};
  uint64_t nv = ix >= 0 ? g->accs[ix].count : pa->count;
  if (nv < least[mode]) return gl_bad(g, "%s: %llu vertices are too few for its mode %llu", ctx, (unsigned long long)nv, (unsigned long long)mode);
  if (ix >= 0 && draco && gl_draco_indices(g, ix, pa->count, ctx)) return g->err->status;
  if (ix >= 0) { /* every index must name a vertex */
    const gacc *a = &g->accs[ix];
    if (a->comps != 1 || (a->ctype != 5121 && a->ctype != 5123 && a->ctype != 5125))
      return gl_bad(g, "%s: \"indices\" must be an accessor of unsigned byte, short or int scalars", ctx);
    uint32_t x;
    if (a->view >= 0) { /* the indices, or a sparse accessor's base, which its values replace in part */
      const gview *v = &g->views[a->view];
      if (a->stride != a->size) return gl_bad(g, "%s: the indices' buffer view %lld must not have a stride", ctx, (long long)a->view);
      int64_t k = first_index_past(g->bufs[v->buf].data + v->off + a->off, a->count, a->size, pa->count, &x);
      if (k >= 0) return gl_bad(g, "%s: index %lld is %u, past the %llu vertices", ctx, (long long)k, x, (unsigned long long)pa->count);
    }
    int64_t k = a->sparse ? first_index_past(a->sparse_values, a->sparse_n, a->size, pa->count, &x) : -1;
    if (k >= 0) return gl_bad(g, "%s: sparse index value %lld is %u, past the %llu vertices", ctx, (long long)k, x, (unsigned long long)pa->count);
  }
  return VALO_OK;
}

static valo_status check_mesh(gc *g, uint32_t m, uint32_t i, const char *mesh_ctx) {
  int64_t np = gl_objects(g, m, "primitives", "primitives");
  if (np < 0) return g->err->status;
  if (np == 0) return gl_bad(g, "%s has no primitives", mesh_ctx);
  uint32_t pr = json_get(&g->d, m, "primitives");
  uint32_t k = 0;
  for (uint32_t p = N(g, pr)->child; p; p = N(g, p)->next, k++) {
    char ctx[64];
    snprintf(ctx, sizeof ctx, "mesh %u primitive %u", i, k);
    valo_status st = check_primitive(g, p, ctx);
    if (st) return st;
  }
  return VALO_OK;
}


/* ---------------------------------------------------------------- the file */

/* A .glb: its header and chunks; the JSON chunk's text and the BIN chunk's bytes. */
static valo_status glb_chunks(gc *g, const unsigned char *b, size_t len, const char **json, size_t *json_len) {
  uint32_t w[5];
  if (len < 20) return gl_bad(g, "a .glb shorter than its header");
  for (int i = 0; i < 5; i++) w[i] = gl_le_uint(b + 4 * i, 4);
  if (memcmp(b, "glTF", 4)) return gl_bad(g, "a .glb must start with \"glTF\"");
  if (w[1] != 2) return gl_bad(g, "binary glTF version %u is not read (valo reads version 2)", w[1]);
  if (w[2] != len) return gl_bad(g, "the header gives the length %u, the file has %zu bytes", w[2], len);
  if (w[4] != GLB_JSON || w[3] == 0 || w[3] > len - 20) return gl_bad(g, "the first chunk must be JSON and fit in the file");
  *json = (const char *)b + 20;
  *json_len = w[3];
  size_t at = 20 + (size_t)w[3];
  at += (4 - at % 4) % 4;
  if (at + 8 <= len) {
    uint32_t cl = gl_le_uint(b + at, 4), ct = gl_le_uint(b + at + 4, 4);
    if (ct != GLB_BIN || cl > len - at - 8) return gl_bad(g, "the second chunk must be BIN and fit in the file");
    g->bin = b + at + 8;
    g->bin_len = cl;
    g->has_bin = 1;
  } else if (at < len) return gl_bad(g, "%zu bytes after the JSON chunk are not a chunk", len - at);
  return VALO_OK;
}

/* valo renders meshes in their bind pose and reads no skin, so when a skin lacks
 * inverseBindMatrices (valid glTF, on which Assimp 5.2 crashes) the text given to Assimp
 * names none: the top-level "skins" and each node's "skin" are renamed in place ("_kins",
 * "_kin"), which keeps the JSON valid and its length, and Assimp ignores unknown names. */
static void hide_skins(gc *g) {
  for (uint32_t c = N(g, 1)->child; c; c = N(g, c)->next) /* every "skins", should a name repeat */
    if (!strcmp(N(g, c)->key, "skins")) ((char *)N(g, c)->key_at)[1] = '_';
  for (uint32_t o = g->arr[K_NODE] ? N(g, g->arr[K_NODE])->child : 0; o; o = N(g, o)->next)
    for (uint32_t c = N(g, o)->child; c; c = N(g, c)->next)
      if (!strcmp(N(g, c)->key, "skin")) ((char *)N(g, c)->key_at)[1] = '_';
}

static valo_status check_json(gc *g, const char *text, size_t len) {
  size_t line;
  char msg[200];
  if (json_parse(&g->d, text, len, &line, msg, sizeof msg)) return err_set(g->err, VALO_ERR_PARSE, "%s:%zu: glTF: %s", g->path, line, msg);
  if (N(g, 1)->t != J_OBJ) return gl_bad(g, "the document must be a JSON object");
  uint32_t v = json_get(&g->d, json_get(&g->d, 1, "asset"), "version");
  if (!v || N(g, v)->t != J_STR) return gl_bad(g, "no \"asset\": {\"version\": ...}");
  if (N(g, v)->str[0] != '2') return gl_bad(g, "version %s is not read (valo reads glTF 2.0)", N(g, v)->str);
  static const char *kinds[K_KINDS] = {"buffers", "bufferViews", "accessors", "meshes", "nodes", "scenes", "materials",
                                "textures", "images", "samplers", "cameras", "skins", "animations"};
  for (int k = 0; k < K_KINDS; k++) {
    int64_t n = gl_objects(g, 1, kinds[k], kinds[k]);
    if (n < 0) return g->err->status;
    g->n[k] = (uint32_t)n;
    g->arr[k] = json_get(&g->d, 1, kinds[k]);
  }
  uint32_t lext = json_get(&g->d, json_get(&g->d, 1, "extensions"), "KHR_lights_punctual");
  int64_t nl = gl_objects(g, lext, "lights", "KHR_lights_punctual lights");
  if (nl < 0) return g->err->status;
  g->n_light = (uint32_t)nl;
  g->lights = json_get(&g->d, lext, "lights");
  g->bufs = calloc((size_t)g->n[K_BUF] + 1, sizeof *g->bufs);
  g->views = calloc((size_t)g->n[K_VIEW] + 1, sizeof *g->views);
  g->accs = calloc((size_t)g->n[K_ACC] + 1, sizeof *g->accs);
  g->deq = calloc((size_t)g->n[K_ACC] + 1, 1);
  g->draco = calloc((size_t)g->n[K_ACC] + 1, 1);
  if (!g->bufs || !g->views || !g->accs || !g->deq || !g->draco) return gl_bad(g, "out of memory");
  uint32_t i = 0;
  for (uint32_t o = g->arr[K_BUF] ? N(g, g->arr[K_BUF])->child : 0; o; o = N(g, o)->next, i++) {
    valo_status st = read_buffer(g, i, o);
    if (st) return st;
  }
  valo_status st = gl_each(g, g->arr[K_VIEW], "buffer view", check_view);
  if (!st) st = gl_draco_mark(g);
  if (!st) st = gl_each(g, g->arr[K_ACC], "accessor", check_accessor);
  if (!st) st = gl_each(g, g->arr[K_MESH], "mesh", check_mesh);
  if (!st) st = gl_check_nodes(g);
  if (!st) st = gl_check_objects(g);
  if (!st && gl_index(g, 1, "scene", g->n[K_SCENE], "scene", 0, "the document") == -2) st = g->err->status;
  if (!st && g->drop_skins) hide_skins(g);
  return st;
}

valo_status gltf_check_file(const char *path, int binary, obj_check *oc, valo_error *err) {
  memset(oc, 0, sizeof *oc);
  gc g;
  memset(&g, 0, sizeof g);
  g.path = path;
  g.err = err;
  g.oc = oc;
  size_t len = 0;
  unsigned char *data = (unsigned char *)obj_check_read_whole(path, &len);
  if (!data) return err_set(err, VALO_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
  snprintf(oc->files[0].path, sizeof oc->files[0].path, "%s", path);
  oc->files[0].text = (char *)data;
  oc->files[0].len = len;
  oc->nfiles = 1;
  const char *json = (const char *)data;
  size_t json_len = len;
  valo_status st = VALO_OK;
  if (binary) st = glb_chunks(&g, data, len, &json, &json_len);
  else if (len >= 4 && !memcmp(data, "glTF", 4)) st = gl_bad(&g, "a binary glTF named .gltf (rename it .glb)");
  else if (len >= 3 && !memcmp(data, "\xef\xbb\xbf", 3)) { /* a UTF-8 byte-order mark: Assimp reads nothing after one */
    memmove(data, data + 3, len - 2); /* with the terminating NUL */
    oc->files[0].len = json_len = len - 3;
  }
  if (!st) st = check_json(&g, json, json_len);
  if (!st && g.ndeq) st = gl_dequantize(&g, json, json_len, binary);
  json_free(&g.d);
  free(g.bufs);
  free(g.views);
  free(g.accs);
  free(g.deq);
  free(g.draco);
  for (int i = 0; i < g.ndecoded; i++) free(g.decoded[i]);
  if (st) obj_check_free(oc);
  return st;
}
