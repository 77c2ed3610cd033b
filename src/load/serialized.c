/* serialized.c — see serialized.h. The format (Mitsuba 3's serialized.cpp documents it):
 * uint16 0x041C, uint16 version 3 or 4, then a zlib stream holding uint32 flags, (version
 * 4) a NUL-terminated name, uint64 vertex and triangle counts, positions, normals, texture
 * coordinates and colours (float, or double with flag 0x2000; each present by its flag),
 * and uint32 indices; little endian. The file ends with each shape's offset (uint64 in
 * version 4, uint32 in 3) and uint32 the number of shapes. The zlib decoder is stb_image's
 * (libstb). */
#include "load/serialized.h"
#include "core/error.h"
#include "core/memlimit.h"
#include <errno.h>
#include <limits.h>
#include <stb_image.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the serialized reader reads little-endian data as it is"
#endif

enum { SER_NORMALS = 0x1, SER_UVS = 0x2, SER_COLORS = 0x8, SER_FACE_NORMALS = 0x10, SER_DOUBLE = 0x2000 };
#define SER_MAGIC 0x041C
#define SER_PEEK (256u << 10) /* the first decode's buffer: the header, or a whole small shape */
#define SER_NAME_MAX 1024

typedef struct ser_file {
  const char *path;
  unsigned char *b;
  size_t len;
  int version;
  uint32_t count;
  size_t table; /* where the offset table starts: every shape's stream ends before it */
  uint64_t *end; /* each shape's stream ends where the next shape in the file starts */
} ser_file;

static uint32_t rd32(const unsigned char *p) { uint32_t v; memcpy(&v, p, 4); return v; }
static uint64_t rd64(const unsigned char *p) { uint64_t v; memcpy(&v, p, 8); return v; }

static uint64_t ser_offset(const ser_file *f, uint32_t i) {
  size_t at = f->table + (f->version == 4 ? 8 : 4) * (size_t)i;
  return f->version == 4 ? rd64(f->b + at) : rd32(f->b + at);
}

typedef struct { uint64_t off; uint32_t i; } ser_entry;
static int entry_cmp(const void *a, const void *b) {
  const ser_entry *x = a, *y = b;
  return x->off != y->off ? (x->off > y->off) - (x->off < y->off) : (x->i > y->i) - (x->i < y->i);
}

/* f->end from the table sorted by offset. Two entries at one offset are refused: a file
 * lists each shape once, and a table that repeats one would have it decoded again for
 * every entry (a small file expanding without end). Every shape's data thus lies in a part
 * of the file of its own, and all of them together decode to at most deflate's ratio
 * (1032) times the file's size. */
static valo_status ser_ends(ser_file *f, valo_error *err) {
  ser_entry *e = malloc((size_t)f->count * sizeof *e);
  f->end = malloc((size_t)f->count * sizeof *f->end);
  if (!e || !f->end) { free(e); return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", f->path); }
  for (uint32_t i = 0; i < f->count; i++) e[i] = (ser_entry){ser_offset(f, i), i};
  qsort(e, f->count, sizeof *e, entry_cmp);
  valo_status st = VALO_OK;
  for (uint32_t k = 0; k < f->count && !st; k++) {
    if (k + 1 < f->count && e[k + 1].off == e[k].off)
      st = err_set(err, VALO_ERR_PARSE, "%s: its table of shapes is damaged: shapes %u and %u both start at offset %llu (each shape is listed once)",
                   f->path, e[k].i, e[k + 1].i, (unsigned long long)e[k].off);
    f->end[e[k].i] = k + 1 < f->count && e[k + 1].off < f->table ? e[k + 1].off : f->table;
  }
  free(e);
  return st;
}

static valo_status ser_open(ser_file *f, const char *path, valo_error *err) {
  memset(f, 0, sizeof *f);
  f->path = path;
  FILE *fp = fopen(path, "rb");
  if (!fp) return err_set(err, VALO_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
  long n = fseek(fp, 0, SEEK_END) == 0 ? ftell(fp) : -1;
  if (n < 0 || fseek(fp, 0, SEEK_SET)) { fclose(fp); return err_set(err, VALO_ERR_IO, "%s: cannot read", path); }
  char what[96];
  snprintf(what, sizeof what, "reading a serialized mesh file of %.1f MiB", (double)n / 1048576.0);
  valo_status st = mem_check((uint64_t)n, path, what, err);
  if (st) { fclose(fp); return st; }
  f->len = (size_t)n;
  f->b = malloc(f->len + 1);
  if (!f->b) { fclose(fp); return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", path); }
  size_t got = fread(f->b, 1, f->len, fp);
  fclose(fp);
  if (got != f->len) return err_set(err, VALO_ERR_IO, "%s: read error", path);
  if (f->len < 8 || f->b[0] + 256 * f->b[1] != SER_MAGIC)
    return err_set(err, VALO_ERR_PARSE, "%s: not a Mitsuba serialized mesh file (it does not start with 0x041C)", path);
  f->version = f->b[2] + 256 * f->b[3];
  if (f->version != 3 && f->version != 4)
    return err_set(err, VALO_ERR_PARSE, "%s: serialized format version %d (valo reads versions 3 and 4)", path, f->version);
  f->count = rd32(f->b + f->len - 4);
  size_t entry = f->version == 4 ? 8 : 4;
  if (f->count == 0 || f->count > (f->len - 8) / entry)
    return err_set(err, VALO_ERR_PARSE, "%s: its table of shapes is damaged (it claims %u shapes in %zu bytes)", path, f->count, f->len);
  f->table = f->len - 4 - entry * f->count;
  return ser_ends(f, err);
}

/* Decompresses shape i into *out (*out_len bytes), checked against the size its header
 * claims. The header is read from a first decode into a bounded buffer, so a stream never
 * expands past what its counts need (nor past deflate's ratio of 1032). */
static valo_status ser_inflate(const ser_file *f, uint32_t i, unsigned char **out, size_t *out_len, valo_error *err) {
  *out = NULL;
  uint64_t off = ser_offset(f, i);
  if (off >= f->table || f->end[i] - off <= 4 || f->b[off] + 256 * f->b[off + 1] != SER_MAGIC || f->b[off + 2] + 256 * f->b[off + 3] != f->version)
    return err_set(err, VALO_ERR_PARSE, "%s: shape %u: its offset (%llu) does not lead to a shape's header", f->path, i, (unsigned long long)off);
  const char *z = (const char *)f->b + off + 4;
  size_t zlen = f->end[i] - off - 4;
  if (zlen > INT_MAX) zlen = INT_MAX;
  /* The header, from a bounded first decode (zeroed: stb leaves its failure reason as it
   * was on a few paths). */
  valo_status st = VALO_OK;
  unsigned char *buf = calloc(1, SER_PEEK);
  if (!buf) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  int n = stbi_zlib_decode_buffer((char *)buf, SER_PEEK, z, (int)zlen);
  const char *why = stbi_failure_reason();
  int partial = n < 0 && why && !strcmp(why, "output buffer limit"); /* at least SER_PEEK - 65535 bytes decoded */
  size_t have = n >= 0 ? (size_t)n : partial ? SER_PEEK - 65535 : 0, p = 4;
  uint64_t need = 0;
  if (n < 0 && !partial) {
    st = err_set(err, VALO_ERR_PARSE, "%s: shape %u: its compressed data is damaged (%s)", f->path, i, why ? why : "zlib");
    goto done;
  }
  if (have < 4 + 16) {
    st = err_set(err, VALO_ERR_PARSE, "%s: shape %u: its data ends inside its header", f->path, i);
    goto done;
  }
  if (f->version == 4) {
    while (p < have && p < SER_NAME_MAX && buf[p]) p++;
    if (p >= have || buf[p]) {
      st = err_set(err, VALO_ERR_PARSE, "%s: shape %u: its name is not ended within %d bytes", f->path, i, SER_NAME_MAX);
      goto done;
    }
    p++;
  }
  if (p + 16 > have) {
    st = err_set(err, VALO_ERR_PARSE, "%s: shape %u: its data ends inside its header", f->path, i);
    goto done;
  }
  uint32_t flags = rd32(buf);
  uint64_t nv = rd64(buf + p), nt = rd64(buf + p + 8);
  if (nv > UINT32_MAX || nt > UINT32_MAX) {
    st = err_set(err, VALO_ERR_PARSE, "%s: shape %u: %llu vertices and %llu triangles (valo reads up to 2^32 - 1 of each)", f->path, i,
                 (unsigned long long)nv, (unsigned long long)nt);
    goto done;
  }
  uint64_t fsz = flags & SER_DOUBLE ? 8 : 4;
  uint64_t per_vertex = 3 + (flags & SER_NORMALS ? 3 : 0) + (flags & SER_UVS ? 2 : 0) + (flags & SER_COLORS ? 3 : 0);
  need = p + 16 + nv * per_vertex * fsz + nt * 12;
  if (need > 1032 * (uint64_t)zlen + 64) {
    st = err_set(err, VALO_ERR_PARSE, "%s: shape %u: its header claims %llu bytes, more than its %zu compressed bytes can hold", f->path, i,
                 (unsigned long long)need, zlen);
    goto done;
  }
  if ((st = mem_check(need, f->path, "a serialized shape's data", err))) goto done;
  if (n < 0 || (size_t)n != need) { /* decode again into exactly the size the header claims */
    free(buf);
    if (!(buf = malloc(need + 1))) return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", f->path);
    n = stbi_zlib_decode_buffer((char *)buf, (int)(need + 1), z, (int)zlen);
    why = stbi_failure_reason();
    if (n >= 0 && (size_t)n < need)
      st = err_set(err, VALO_ERR_PARSE, "%s: shape %u: its data ends early (%d of %llu bytes)", f->path, i, n, (unsigned long long)need);
    else if ((n >= 0 && (size_t)n > need) || (n < 0 && why && !strcmp(why, "output buffer limit")))
      st = err_set(err, VALO_ERR_PARSE, "%s: shape %u: it holds more data than its header says (%llu bytes)", f->path, i, (unsigned long long)need);
    else if (n < 0)
      st = err_set(err, VALO_ERR_PARSE, "%s: shape %u: its compressed data is damaged (%s)", f->path, i, why ? why : "zlib");
  }
done:
  if (st) { free(buf); return st; }
  *out = buf;
  *out_len = need;
  return VALO_OK;
}

/* n values of fsz bytes from *p as floats; advances *p. */
static float *take_floats(const unsigned char **p, uint64_t n, uint64_t fsz) {
  float *v = malloc(n * sizeof(float) + 1);
  if (!v) return NULL;
  for (uint64_t k = 0; k < n; k++) {
    if (fsz == 8) { double d; memcpy(&d, *p + 8 * k, 8); v[k] = (float)d; }
    else memcpy(&v[k], *p + 4 * k, 4);
  }
  *p += n * fsz;
  return v;
}

static valo_status ser_shape(scene *s, const ser_file *f, uint32_t i, const float *xf, uint32_t mat, int mesh_flags, valo_error *err) {
  unsigned char *buf;
  size_t len;
  valo_status st = ser_inflate(f, i, &buf, &len, err);
  if (st) return st;
  uint32_t flags = rd32(buf);
  const unsigned char *p = buf + 4;
  char where[1400];
  if (f->version == 4 && *p) snprintf(where, sizeof where, "%s: shape %u '%.200s'", f->path, i, (const char *)p);
  else snprintf(where, sizeof where, "%s: shape %u", f->path, i);
  if (f->version == 4) p += strlen((const char *)p) + 1;
  uint32_t nv = (uint32_t)rd64(p), nt = (uint32_t)rd64(p + 8);
  p += 16;
  uint64_t fsz = flags & SER_DOUBLE ? 8 : 4;
  float *pos = take_floats(&p, 3 * (uint64_t)nv, fsz);
  float *nrm = flags & SER_NORMALS ? take_floats(&p, 3 * (uint64_t)nv, fsz) : NULL;
  float *uv = flags & SER_UVS ? take_floats(&p, 2 * (uint64_t)nv, fsz) : NULL;
  if (flags & SER_COLORS) p += 3 * (uint64_t)nv * fsz; /* vertex colours: not used (as in Mitsuba 3) */
  uint32_t *idx = malloc(12 * (size_t)nt + 1);
  if (!pos || (flags & SER_NORMALS && !nrm) || (flags & SER_UVS && !uv) || !idx) {
    st = err_set(err, VALO_ERR_NOMEM, "%s: out of memory", where);
  } else {
    memcpy(idx, p, 12 * (size_t)nt);
    for (uint32_t v = 0; uv && v < nv; v++) uv[2 * v + 1] = 1 - uv[2 * v + 1]; /* Mitsuba's v runs down the image */
    uint64_t added = 0, degenerate = 0;
    mesh_data md = {where, nv, nt, pos, nrm, uv, 2, idx, (mesh_flags & LOAD_MESH_FLAT) || (flags & SER_FACE_NORMALS), (mesh_flags & LOAD_MESH_SMOOTH) != 0, NULL, 0};
    st = scene_add_mesh(s, &md, xf, mat, &added, &degenerate, err);
    if (!st && !added) st = err_set(err, VALO_ERR_INVALID, "%s: no usable triangles (%llu degenerate)", where, (unsigned long long)degenerate);
    if (!st && degenerate) log_warning("%s: skipped %llu degenerate (zero-area) triangles", where, (unsigned long long)degenerate);
  }
  free(pos); free(nrm); free(uv); free(idx); free(buf);
  return st;
}

uint32_t serialized_count(const char *path, valo_error *err) {
  ser_file f;
  valo_status st = ser_open(&f, path, err);
  free(f.b);
  free(f.end);
  return st ? 0 : f.count;
}

valo_status load_serialized(scene *s, const char *path, int shape_index, const float *xf, uint32_t mat, int mesh_flags, valo_error *err) {
  ser_file f;
  valo_status st = ser_open(&f, path, err);
  if (!st && shape_index >= 0 && (uint32_t)shape_index >= f.count)
    st = err_set(err, VALO_ERR_INVALID, "%s: shape_index %d, but the file holds %u shapes (0 to %u)", path, shape_index, f.count, f.count - 1);
  if (!st && mat == UINT32_MAX) {
    material d = material_default();
    if ((mat = scene_add_material(s, &d)) == UINT32_MAX) st = err_set(err, VALO_ERR_NOMEM, "out of memory");
  }
  for (uint32_t i = shape_index < 0 ? 0 : (uint32_t)shape_index; !st && i < (shape_index < 0 ? f.count : (uint32_t)shape_index + 1); i++)
    st = ser_shape(s, &f, i, xf, mat, mesh_flags, err);
  free(f.b);
  free(f.end);
  return st;
}
