/* ply_check.c — see ply_check.h. One pass over the header, one over the body; nothing is
 * kept but the element layout. The body walk is bounded by the file's size, so a header
 * that claims billions of elements is refused before anything is read. */
#include "load/ply_check.h"
#include "core/error.h"
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define PLY_MAX_ELEMENTS 32
#define PLY_MAX_PROPS 64
#define PLY_MAX_HEADER (1 << 20)
#define PLY_MAX_FACE_VERTICES 1024 /* a face list longer than this is not a mesh face */

typedef enum { T_BAD, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 } ply_type;
typedef enum { F_ASCII, F_LE, F_BE } ply_format;

typedef struct ply_prop {
  char name[64];
  ply_type type;       /* the scalar's type, or the list's item type */
  ply_type count_type; /* T_BAD for a scalar */
} ply_prop;

typedef struct ply_elem {
  char name[64];
  uint64_t count;
  ply_prop props[PLY_MAX_PROPS];
  int nprops;
} ply_elem;

typedef struct ply_reader {
  const char *path;
  const unsigned char *data, *p, *end;
  ply_format fmt;
  size_t line; /* ASCII: the 1-based line of p */
  valo_error *err;
} ply_reader;

static ply_type type_of(const char *s) {
  static const struct { const char *name; ply_type t; } names[] = {
      {"char", T_I8},    {"int8", T_I8},      {"uchar", T_U8},   {"uint8", T_U8},    {"short", T_I16},
      {"int16", T_I16},  {"ushort", T_U16},   {"uint16", T_U16}, {"int", T_I32},     {"int32", T_I32},
      {"uint", T_U32},   {"uint32", T_U32},   {"float", T_F32},  {"float32", T_F32}, {"double", T_F64},
      {"float64", T_F64}};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
    if (!strcmp(s, names[i].name)) return names[i].t;
  return T_BAD;
}
static size_t type_size(ply_type t) {
  switch (t) {
  case T_I8: case T_U8: return 1;
  case T_I16: case T_U16: return 2;
  case T_I32: case T_U32: case T_F32: return 4;
  case T_F64: return 8;
  case T_BAD: return 0;
  }
  return 0;
}
static int type_is_int(ply_type t) { return t != T_F32 && t != T_F64 && t != T_BAD; }
static void int_range(ply_type t, double *lo, double *hi) {
  switch (t) {
  case T_I8: *lo = INT8_MIN; *hi = INT8_MAX; break;
  case T_U8: *lo = 0; *hi = UINT8_MAX; break;
  case T_I16: *lo = INT16_MIN; *hi = INT16_MAX; break;
  case T_U16: *lo = 0; *hi = UINT16_MAX; break;
  case T_I32: *lo = INT32_MIN; *hi = INT32_MAX; break;
  case T_U32: case T_F32: case T_F64: case T_BAD: *lo = 0; *hi = UINT32_MAX; break;
  }
}

int ply_is_ply(const unsigned char *d, size_t len) {
  return len >= 4 && d[0] == 'p' && d[1] == 'l' && d[2] == 'y' && (d[3] == '\n' || d[3] == '\r');
}

/* Reads one binary scalar of type t as a double (integers exactly). */
static int bin_read(ply_reader *r, ply_type t, double *out) {
  size_t n = type_size(t);
  if ((size_t)(r->end - r->p) < n) return 0;
  unsigned char b[8];
  for (size_t i = 0; i < n; i++) b[i] = r->p[r->fmt == F_BE ? n - 1 - i : i]; /* to little-endian */
  r->p += n;
  uint64_t u = 0;
  for (size_t i = 0; i < n; i++) u |= (uint64_t)b[i] << (8 * i);
  switch (t) {
  case T_I8: *out = (int8_t)u; break;
  case T_U8: *out = (uint8_t)u; break;
  case T_I16: *out = (int16_t)u; break;
  case T_U16: *out = (uint16_t)u; break;
  case T_I32: *out = (int32_t)u; break;
  case T_U32: *out = (uint32_t)u; break;
  case T_F32: { uint32_t w = (uint32_t)u; float f; memcpy(&f, &w, 4); *out = f; break; }
  case T_F64: { double d; memcpy(&d, &u, 8); *out = d; break; }
  case T_BAD: return 0;
  }
  return 1;
}

/* ASCII: skips blanks within the line; 0 at a line end or the end of the file. */
static int ascii_token(ply_reader *r, const unsigned char **tok, size_t *len) {
  while (r->p < r->end && (*r->p == ' ' || *r->p == '\t')) r->p++;
  if (r->p >= r->end || *r->p == '\n' || *r->p == '\r') return 0;
  *tok = r->p;
  while (r->p < r->end && !isspace(*r->p)) r->p++;
  *len = (size_t)(r->p - *tok);
  return 1;
}
/* The number forms both valo and Assimp's ASCII PLY reader read whole and alike: digits
 * for unsigned types, a sign and digits for signed ones, and for reals a sign, digits with
 * an optional point and exponent, or nan / inf / infinity. Anything else Assimp would read
 * in part ("+3" as an unsigned count is 0 there) and then read the rest of the line as
 * further values, handing on faces that disagree with valo's check. */
static size_t digits(const unsigned char *s, size_t i, size_t n) {
  while (i < n && s[i] >= '0' && s[i] <= '9') i++;
  return i;
}
static int ascii_form_ok(const unsigned char *s, size_t n, ply_type t) {
  size_t i = 0;
  int sign = n && (s[0] == '-' || s[0] == '+');
  if (t == T_U8 || t == T_U16 || t == T_U32) return n && digits(s, 0, n) == n;
  if (type_is_int(t)) return n > (size_t)sign && digits(s, (size_t)sign, n) == n;
  i = (size_t)sign;
  size_t rest = n - i;
  if ((rest == 3 && (!strncasecmp((const char *)s + i, "nan", 3) || !strncasecmp((const char *)s + i, "inf", 3))) ||
      (rest == 8 && !strncasecmp((const char *)s + i, "infinity", 8)))
    return 1;
  size_t a = digits(s, i, n), b = a;
  if (b < n && s[b] == '.') b = digits(s, b + 1, n);
  if (a == i && b <= a + 1) return 0; /* no digit before or after the point */
  if (b < n && (s[b] == 'e' || s[b] == 'E')) {
    size_t e = b + 1 + (b + 1 < n && (s[b + 1] == '-' || s[b + 1] == '+'));
    b = digits(s, e, n);
    if (b == e) return 0;
  }
  return b == n;
}
static int ascii_read(ply_reader *r, ply_type t, double *out) {
  const unsigned char *tok;
  size_t len;
  if (!ascii_token(r, &tok, &len) || len > 63 || !ascii_form_ok(tok, len, t)) return 0;
  char buf[64];
  memcpy(buf, tok, len);
  buf[len] = 0;
  char *e;
  errno = 0;
  if (type_is_int(t)) {
    long long v = strtoll(buf, &e, 10);
    double lo = 0, hi = 0;
    int_range(t, &lo, &hi);
    if (*e || errno || (double)v < lo || (double)v > hi) return 0; /* Assimp would wrap it */
    *out = (double)v;
  } else {
    double v = strtod(buf, &e);
    if (*e) return 0;
    *out = v;
  }
  return 1;
}
/* ASCII: the rest of the line must be blank; moves to the next line. */
static int ascii_end_line(ply_reader *r) {
  while (r->p < r->end && (*r->p == ' ' || *r->p == '\t')) r->p++;
  if (r->p < r->end && *r->p == '\r') r->p++;
  if (r->p < r->end && *r->p == '\n') { r->p++; r->line++; return 1; }
  return r->p >= r->end; /* the last line may lack its newline */
}
static int ascii_line_blank(const ply_reader *r) {
  const unsigned char *q = r->p;
  while (q < r->end && (*q == ' ' || *q == '\t' || *q == '\r')) q++;
  return q >= r->end || *q == '\n';
}
static void ascii_skip_blank_lines(ply_reader *r) {
  for (;;) {
    const unsigned char *q = r->p;
    while (q < r->end && (*q == ' ' || *q == '\t' || *q == '\r')) q++;
    if (q < r->end && *q == '\n') { r->p = q + 1; r->line++; continue; }
    if (q >= r->end) r->p = q;
    return;
  }
}

static int in_range(ply_type t, double v) {
  switch (t) {
  case T_I8: return v >= INT8_MIN && v <= INT8_MAX;
  case T_U8: return v >= 0 && v <= UINT8_MAX;
  case T_I16: return v >= INT16_MIN && v <= INT16_MAX;
  case T_U16: return v >= 0 && v <= UINT16_MAX;
  case T_I32: return v >= INT32_MIN && v <= INT32_MAX;
  case T_U32: return v >= 0 && v <= UINT32_MAX;
  case T_F32: case T_F64: return 1;
  case T_BAD: return 0;
  }
  return 0;
}

static valo_status bad_at(ply_reader *r, const char *what, const ply_elem *e, uint64_t i) {
  if (r->fmt == F_ASCII)
    return err_set(r->err, VALO_ERR_PARSE, "%s:%zu: %s (element '%s' %llu of %llu)", r->path, r->line, what, e->name,
                   (unsigned long long)i + 1, (unsigned long long)e->count);
  return err_set(r->err, VALO_ERR_PARSE, "%s: %s (element '%s' %llu of %llu, byte %llu)", r->path, what, e->name,
                 (unsigned long long)i + 1, (unsigned long long)e->count, (unsigned long long)(r->p - r->data));
}

/* The element names Assimp's PLY reader knows (as whole words, case and all). It reads any
 * other element ("vertices", "range_grid") as having no instances, and so would read its
 * data as the next element's. */
static int is_vertex_elem(const char *n) { return !strcmp(n, "vertex"); }
static int is_face_elem(const char *n) { return !strcmp(n, "face"); }
static int assimp_counts_elem(const char *n) { return is_vertex_elem(n) || is_face_elem(n) || !strcmp(n, "edge") || !strcmp(n, "material"); }
static int is_index_list(const char *n) { return !strcmp(n, "vertex_indices") || !strcmp(n, "vertex_index"); }

static valo_status check_body(ply_reader *r, const ply_elem *el, int nel, uint64_t nverts) {
  for (int k = 0; k < nel; k++) {
    const ply_elem *e = &el[k];
    int face = is_face_elem(e->name);
    for (uint64_t i = 0; i < e->count; i++) {
      /* Assimp reads each line as one element, so a blank line would shift every one after
       * it (and a face short of its indices aborts the process) */
      if (r->fmt == F_ASCII && r->p < r->end && ascii_line_blank(r)) {
        const unsigned char *q = r->p;
        size_t line = r->line;
        ascii_skip_blank_lines(r);
        if (r->p < r->end) { r->p = q; r->line = line; return bad_at(r, "a blank line in the data", e, i); }
      }
      if (r->p >= r->end) {
        if (r->fmt == F_ASCII)
          return err_set(r->err, VALO_ERR_PARSE, "%s:%zu: the file ends after %llu of %llu '%s' elements", r->path, r->line,
                         (unsigned long long)i, (unsigned long long)e->count, e->name);
        return err_set(r->err, VALO_ERR_PARSE, "%s: the file ends after %llu of %llu '%s' elements", r->path,
                       (unsigned long long)i, (unsigned long long)e->count, e->name);
      }
      for (int j = 0; j < e->nprops; j++) {
        const ply_prop *p = &e->props[j];
        double v;
        int ok;
        if (p->count_type == T_BAD) {
          ok = r->fmt == F_ASCII ? ascii_read(r, p->type, &v) : bin_read(r, p->type, &v);
          if (!ok || !in_range(p->type, v)) {
            char what[160];
            snprintf(what, sizeof what, "property '%s' is missing or not a number of its type", p->name);
            return bad_at(r, what, e, i);
          }
          continue;
        }
        ok = r->fmt == F_ASCII ? ascii_read(r, p->count_type, &v) : bin_read(r, p->count_type, &v);
        if (!ok || !in_range(p->count_type, v) || v < 0) {
          char what[160];
          snprintf(what, sizeof what, "list '%s' has no valid length", p->name);
          return bad_at(r, what, e, i);
        }
        uint64_t n = (uint64_t)v;
        int indices = face && is_index_list(p->name);
        if (indices && (n < 3 || n > PLY_MAX_FACE_VERTICES)) {
          char what[160];
          snprintf(what, sizeof what, "a face lists %llu vertices (a face needs 3 to %d)", (unsigned long long)n,
                   PLY_MAX_FACE_VERTICES);
          return bad_at(r, what, e, i);
        }
        if (r->fmt != F_ASCII && n * type_size(p->type) > (uint64_t)(r->end - r->p)) {
          char what[160];
          snprintf(what, sizeof what, "list '%s' of %llu items runs past the end of the file", p->name, (unsigned long long)n);
          return bad_at(r, what, e, i);
        }
        for (uint64_t m = 0; m < n; m++) {
          ok = r->fmt == F_ASCII ? ascii_read(r, p->type, &v) : bin_read(r, p->type, &v);
          if (!ok || !in_range(p->type, v)) {
            char what[160];
            snprintf(what, sizeof what, "list '%s' item %llu of %llu is missing or not a number of its type", p->name,
                     (unsigned long long)m + 1, (unsigned long long)n);
            return bad_at(r, what, e, i);
          }
          if (indices && (v < 0 || v >= (double)nverts)) {
            char what[160];
            snprintf(what, sizeof what, "vertex index %.0f is out of range (the file has %llu vertices)", v,
                     (unsigned long long)nverts);
            return bad_at(r, what, e, i);
          }
        }
      }
      if (r->fmt == F_ASCII && !ascii_end_line(r))
        return bad_at(r, "more values on the line than the header declares", e, i);
    }
  }
  if (r->fmt == F_ASCII) {
    ascii_skip_blank_lines(r);
    if (r->p < r->end)
      return err_set(r->err, VALO_ERR_PARSE, "%s:%zu: text after the last element the header declares", r->path, r->line);
  }
  return VALO_OK;
}

valo_status ply_check(const char *path, const unsigned char *data, size_t len, size_t *cr_at, valo_error *err) {
  if (cr_at) *cr_at = 0;
  ply_reader r = {path, data, data, data + len, F_ASCII, 1, err};
  ply_elem *elems = calloc(PLY_MAX_ELEMENTS, sizeof *elems);
  if (!elems) return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", path);
  valo_status st = VALO_OK;
  int nel = 0, have_format = 0, done = 0, in_props = 0;
  size_t line = 0;
  const unsigned char *p = data, *end = data + (len < PLY_MAX_HEADER ? len : PLY_MAX_HEADER);
  while (!done) {
    const unsigned char *nl = memchr(p, '\n', (size_t)(end - p));
    if (!nl) { st = err_set(err, VALO_ERR_PARSE, "%s: the PLY header has no end_header line", path); goto out; }
    line++;
    char buf[512];
    size_t n = (size_t)(nl - p);
    if (n && p[n - 1] == '\r') n--;
    if (n >= sizeof buf) { st = err_set(err, VALO_ERR_PARSE, "%s:%zu: header line too long", path, line); goto out; }
    /* the header is text: a control byte (a NUL in a property's name) would make valo and
     * Assimp read different headers (fuzz/regressions/scene_ply) */
    for (size_t k = 0; k < n; k++)
      if (p[k] < 32 && p[k] != '\t') { st = err_set(err, VALO_ERR_PARSE, "%s:%zu: control bytes in the PLY header", path, line); goto out; }
    memcpy(buf, p, n);
    buf[n] = 0;
    p = nl + 1;
    char w0[64] = "", w1[64] = "", w2[64] = "", w3[64] = "", w4[64] = "";
    int nw = sscanf(buf, "%63s %63s %63s %63s %63s", w0, w1, w2, w3, w4);
    if (line == 1) {
      if (strcmp(w0, "ply") || nw != 1) { st = err_set(err, VALO_ERR_PARSE, "%s:1: not a PLY file (no 'ply' line)", path); goto out; }
      continue;
    }
    /* Assimp ends an element's properties at the first line that is neither a property
     * nor a comment, and skips the properties after it: a blank line or an obj_info
     * there would give it a different layout (fuzz/regressions/scene_ply) */
    if (nw <= 0) { st = err_set(err, VALO_ERR_PARSE, "%s:%zu: a blank line in the PLY header", path, line); goto out; }
    if (!strcmp(w0, "comment")) continue;
    if (!strcmp(w0, "obj_info")) { in_props = 0; continue; }
    if (!strcmp(w0, "property") && nel && !in_props) {
      st = err_set(err, VALO_ERR_PARSE, "%s:%zu: a property after an obj_info line: put obj_info lines before the first element", path, line);
      goto out;
    }
    if (!strcmp(w0, "format")) {
      if (have_format) { st = err_set(err, VALO_ERR_PARSE, "%s:%zu: a second format line", path, line); goto out; }
      if (nw != 3 || strcmp(w2, "1.0")) { st = err_set(err, VALO_ERR_PARSE, "%s:%zu: bad format line (want 'format ascii|binary_little_endian|binary_big_endian 1.0')", path, line); goto out; }
      if (!strcmp(w1, "ascii")) r.fmt = F_ASCII;
      else if (!strcmp(w1, "binary_little_endian")) r.fmt = F_LE;
      else if (!strcmp(w1, "binary_big_endian")) r.fmt = F_BE;
      else { st = err_set(err, VALO_ERR_PARSE, "%s:%zu: unknown PLY format '%s'", path, line, w1); goto out; }
      have_format = 1;
    } else if (!strcmp(w0, "element")) {
      if (nel == PLY_MAX_ELEMENTS) { st = err_set(err, VALO_ERR_PARSE, "%s:%zu: more than %d elements", path, line, PLY_MAX_ELEMENTS); goto out; }
      char *e;
      errno = 0;
      unsigned long long c = strtoull(w2, &e, 10);
      if (nw != 3 || *e || errno || !isdigit((unsigned char)w2[0])) { st = err_set(err, VALO_ERR_PARSE, "%s:%zu: bad element line (want 'element NAME COUNT')", path, line); goto out; }
      if (!strcmp(w1, "tristrips")) {
        st = err_set(err, VALO_ERR_UNSUPPORTED, "%s: PLY triangle strips (element tristrips) are not supported; convert the mesh to faces", path);
        goto out;
      }
      /* Assimp reads every vertex (face) element into the one mesh, with arrays sized by
       * one of them: two of either corrupt its heap (fuzz/regressions/scene_ply) */
      for (int k = 0; k < nel; k++)
        if ((is_vertex_elem(w1) && is_vertex_elem(elems[k].name)) || (is_face_elem(w1) && is_face_elem(elems[k].name))) {
          st = err_set(err, VALO_ERR_UNSUPPORTED, "%s:%zu: a second '%s' element (valo reads one vertex and one face element per PLY)", path, line, w1);
          goto out;
        }
      /* (and it takes the count of one from the digits its name starts with) */
      if ((c || isdigit((unsigned char)w1[0])) && !assimp_counts_elem(w1)) {
        st = err_set(err, VALO_ERR_UNSUPPORTED, "%s:%zu: element '%s' is not one the PLY reader knows (vertex, face, edge, material); remove it or rename it", path, line, w1);
        goto out;
      }
      snprintf(elems[nel].name, sizeof elems[nel].name, "%s", w1);
      elems[nel].count = c;
      nel++;
      in_props = 1;
    } else if (!strcmp(w0, "property")) {
      if (!nel) { st = err_set(err, VALO_ERR_PARSE, "%s:%zu: a property before any element", path, line); goto out; }
      ply_elem *e = &elems[nel - 1];
      if (e->nprops == PLY_MAX_PROPS) { st = err_set(err, VALO_ERR_PARSE, "%s:%zu: more than %d properties", path, line, PLY_MAX_PROPS); goto out; }
      ply_prop *pp = &e->props[e->nprops];
      if (!strcmp(w1, "list")) {
        pp->count_type = type_of(w2);
        pp->type = type_of(w3);
        if (nw != 5 || !type_is_int(pp->count_type) || pp->type == T_BAD) {
          st = err_set(err, VALO_ERR_PARSE, "%s:%zu: bad list property (want 'property list COUNT_TYPE ITEM_TYPE NAME')", path, line);
          goto out;
        }
        snprintf(pp->name, sizeof pp->name, "%s", w4);
      } else {
        pp->count_type = T_BAD;
        pp->type = type_of(w1);
        if (nw != 3 || pp->type == T_BAD) { st = err_set(err, VALO_ERR_PARSE, "%s:%zu: bad property line (want 'property TYPE NAME')", path, line); goto out; }
        snprintf(pp->name, sizeof pp->name, "%s", w2);
      }
      if (is_face_elem(e->name) && is_index_list(pp->name) && (pp->count_type == T_BAD || !type_is_int(pp->type))) {
        st = err_set(err, VALO_ERR_PARSE, "%s:%zu: a face's '%s' must be a list of integers", path, line, pp->name);
        goto out;
      }
      e->nprops++;
    } else if (!strcmp(w0, "end_header")) {
      done = 1;
    } else {
      st = err_set(err, VALO_ERR_PARSE, "%s:%zu: unknown header line '%s'", path, line, w0);
      goto out;
    }
  }
  if (!have_format) { st = err_set(err, VALO_ERR_PARSE, "%s: the PLY header has no format line", path); goto out; }
  /* Every element takes at least one byte per property (ASCII: a digit and a separator);
   * counts beyond what the body can hold are refused before anything is read. */
  uint64_t body = (uint64_t)(r.end - p), nverts = 0;
  int have_vertex = 0;
  for (int k = 0; k < nel; k++) {
    uint64_t min = 0;
    for (int j = 0; j < elems[k].nprops; j++)
      min += r.fmt == F_ASCII ? 2 : type_size(elems[k].props[j].count_type != T_BAD ? elems[k].props[j].count_type : elems[k].props[j].type);
    if (min && elems[k].count > body / min) {
      st = err_set(err, VALO_ERR_PARSE, "%s: the header declares %llu '%s' elements, more than the file's %llu bytes of data can hold",
                   path, (unsigned long long)elems[k].count, elems[k].name, (unsigned long long)body);
      goto out;
    }
    if (is_vertex_elem(elems[k].name)) {
      int xyz = 0;
      for (int j = 0; j < elems[k].nprops; j++)
        if (elems[k].props[j].count_type == T_BAD && strlen(elems[k].props[j].name) == 1 && strchr("xyz", elems[k].props[j].name[0]))
          xyz++;
      if (xyz != 3) { st = err_set(err, VALO_ERR_PARSE, "%s: the vertex element has no x, y and z properties", path); goto out; }
      nverts = elems[k].count;
      have_vertex = 1;
    }
  }
  for (int k = 0; k < nel; k++)
    if (is_face_elem(elems[k].name) && elems[k].count && !have_vertex) {
      st = err_set(err, VALO_ERR_PARSE, "%s: faces without a vertex element", path);
      goto out;
    }
  r.p = p;
  r.line = line + 1;
  st = check_body(&r, elems, nel, nverts);
  /* Assimp skips a line feed that starts the binary data after a header ending "\n" (not
   * after one ending "\r\n"): the first vertex would lose its first byte */
  if (!st && cr_at && r.fmt != F_ASCII && p < data + len && *p == '\n' && p[-2] != '\r') *cr_at = (size_t)(p - 1 - data);
out:
  free(elems);
  return st;
}

valo_status ply_check_file(const char *path, char **fixed, size_t *fixed_len, valo_error *err) {
  *fixed = NULL;
  *fixed_len = 0;
  FILE *f = fopen(path, "rb");
  if (!f) return err_set(err, VALO_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
  unsigned char magic[4];
  size_t got = fread(magic, 1, 4, f);
  if (!ply_is_ply(magic, got)) {
    fclose(f);
    /* a .ply without the magic would go to Assimp's PLY reader, which can spin on such
     * a file for minutes (fuzz/regressions/scene_ply) */
    size_t n = strlen(path);
    if (n >= 4 && !strcasecmp(path + n - 4, ".ply"))
      return err_set(err, VALO_ERR_PARSE, "%s:1: not a PLY file: it does not start with the line \"ply\"", path);
    return VALO_OK;
  }
  if (fseek(f, 0, SEEK_END) || ftell(f) < 0) { fclose(f); return err_set(err, VALO_ERR_IO, "%s: cannot read", path); }
  size_t len = (size_t)ftell(f);
  rewind(f);
  unsigned char *buf = malloc(len ? len : 1);
  if (!buf) { fclose(f); return err_set(err, VALO_ERR_NOMEM, "%s: out of memory (%zu bytes)", path, len); }
  size_t n = fread(buf, 1, len, f);
  fclose(f);
  size_t cr_at = 0;
  valo_status st = n == len ? ply_check(path, buf, len, &cr_at, err) : err_set(err, VALO_ERR_IO, "%s: cannot read", path);
  if (!st && cr_at) { /* the same file with its header ending "\r\n" */
    char *f2 = malloc(len + 1);
    if (!f2) { free(buf); return err_set(err, VALO_ERR_NOMEM, "%s: out of memory (%zu bytes)", path, len + 1); }
    memcpy(f2, buf, cr_at);
    f2[cr_at] = '\r';
    memcpy(f2 + cr_at + 1, buf + cr_at, len - cr_at);
    *fixed = f2;
    *fixed_len = len + 1;
  }
  free(buf);
  return st;
}
