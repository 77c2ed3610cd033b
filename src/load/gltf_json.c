/* gltf_json.c — see gltf_json.h. A recursive-descent reader into a flat node array; the
 * unescaped strings go to one buffer no longer than the text. */
#include "load/gltf_json.h"
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct jparse {
  jdoc *d;
  const char *p, *end;
  size_t line;
  char *msg;
  size_t msg_size;
} jparse;

static int fail(jparse *j, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(j->msg, j->msg_size, fmt, ap);
  va_end(ap);
  return -1;
}

static void skip_ws(jparse *j) {
  while (j->p < j->end && (*j->p == ' ' || *j->p == '\t' || *j->p == '\n' || *j->p == '\r')) {
    if (*j->p == '\n') j->line++;
    j->p++;
  }
}

static uint32_t new_node(jparse *j, jtype t) {
  jdoc *d = j->d;
  if (d->count == d->cap) {
    uint32_t nc = d->cap ? 2 * d->cap : 256;
    if (nc > (1u << 28)) return 0;
    jnode *g = realloc(d->nodes, (size_t)nc * sizeof *g);
    if (!g) return 0;
    d->nodes = g;
    d->cap = nc;
  }
  memset(&d->nodes[d->count], 0, sizeof d->nodes[0]);
  d->nodes[d->count].t = t;
  return d->count++;
}

static int hex4(const char *p, unsigned *v) {
  *v = 0;
  for (int i = 0; i < 4; i++) {
    char c = p[i];
    int h = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
    if (h < 0) return -1;
    *v = *v << 4 | (unsigned)h;
  }
  return 0;
}

/* A string at p (on its opening quote); its unescaped bytes go to the string buffer. */
static int parse_string(jparse *j, const char **out) {
  char *o = j->d->strs + j->d->nstrs;
  *out = o;
  j->p++;
  for (;;) {
    if (j->p >= j->end) return fail(j, "a string is not closed");
    unsigned char c = (unsigned char)*j->p++;
    if (c == '"') break;
    if (c < 0x20) return fail(j, "a control character (0x%02x) inside a string", c);
    if (c != '\\') { *o++ = (char)c; continue; }
    if (j->p >= j->end) return fail(j, "a string is not closed");
    char e = *j->p++;
    const char *simple = strchr("\"\\/bfnrt", e);
    if (e && simple) { *o++ = "\"\\/\b\f\n\r\t"[simple - "\"\\/bfnrt"]; continue; }
    if (e != 'u') return fail(j, "a bad escape \\%c in a string", e);
    unsigned u, lo;
    if (j->end - j->p < 4 || hex4(j->p, &u)) return fail(j, "a bad \\u escape in a string");
    j->p += 4;
    if (u == 0) return fail(j, "a \\u0000 in a string");
    if (u >= 0xDC00 && u <= 0xDFFF) return fail(j, "a lone surrogate \\u%04X in a string", u);
    if (u >= 0xD800 && u <= 0xDBFF) {
      if (j->end - j->p < 6 || j->p[0] != '\\' || j->p[1] != 'u' || hex4(j->p + 2, &lo) || lo < 0xDC00 || lo > 0xDFFF)
        return fail(j, "a lone surrogate \\u%04X in a string", u);
      j->p += 6;
      u = 0x10000 + ((u - 0xD800) << 10) + (lo - 0xDC00);
    }
    if (u < 0x80) *o++ = (char)u;
    else if (u < 0x800) { *o++ = (char)(0xC0 | u >> 6); *o++ = (char)(0x80 | (u & 63)); }
    else if (u < 0x10000) { *o++ = (char)(0xE0 | u >> 12); *o++ = (char)(0x80 | (u >> 6 & 63)); *o++ = (char)(0x80 | (u & 63)); }
    else { *o++ = (char)(0xF0 | u >> 18); *o++ = (char)(0x80 | (u >> 12 & 63)); *o++ = (char)(0x80 | (u >> 6 & 63)); *o++ = (char)(0x80 | (u & 63)); }
  }
  *o++ = 0;
  j->d->nstrs = (size_t)(o - j->d->strs);
  return 0;
}

static int digits(jparse *j) {
  const char *s = j->p;
  while (j->p < j->end && *j->p >= '0' && *j->p <= '9') j->p++;
  return j->p > s;
}

static int parse_number(jparse *j, jnode *n) {
  const char *s = j->p;
  if (*j->p == '-') j->p++;
  if (j->p < j->end && *j->p == '0') j->p++;
  else if (!digits(j)) return fail(j, "a bad number");
  n->is_int = 1;
  if (j->p < j->end && *j->p == '.') { j->p++; n->is_int = 0; if (!digits(j)) return fail(j, "a bad number"); }
  if (j->p < j->end && (*j->p == 'e' || *j->p == 'E')) {
    j->p++;
    n->is_int = 0;
    if (j->p < j->end && (*j->p == '+' || *j->p == '-')) j->p++;
    if (!digits(j)) return fail(j, "a bad number");
  }
  char buf[64];
  size_t len = (size_t)(j->p - s);
  if (len >= sizeof buf) return fail(j, "a number of more than %zu characters", sizeof buf - 1);
  memcpy(buf, s, len);
  buf[len] = 0;
  n->num = strtod(buf, NULL);
  if (!isfinite(n->num)) return fail(j, "a number (%s) past the range of a double", buf);
  return 0;
}

static int parse_value(jparse *j, uint32_t *out, int depth);

/* An array or object at p; members of an object get their keys. */
static int parse_container(jparse *j, uint32_t id, int depth) {
  int obj = j->d->nodes[id].t == J_OBJ;
  char close = obj ? '}' : ']';
  j->p++;
  skip_ws(j);
  if (j->p < j->end && *j->p == close) { j->p++; return 0; }
  uint32_t last = 0;
  for (;;) {
    const char *key = NULL, *key_at = NULL;
    if (obj) {
      if (j->p >= j->end || *j->p != '"') return fail(j, "a member name (a string) expected");
      key_at = j->p;
      if (parse_string(j, &key)) return -1;
      skip_ws(j);
      if (j->p >= j->end || *j->p != ':') return fail(j, "':' expected after a member name");
      j->p++;
    }
    uint32_t c;
    if (parse_value(j, &c, depth + 1)) return -1;
    j->d->nodes[c].key = key;
    j->d->nodes[c].key_at = key_at;
    if (last) j->d->nodes[last].next = c;
    else j->d->nodes[id].child = c;
    last = c;
    j->d->nodes[id].n++;
    skip_ws(j);
    if (j->p < j->end && *j->p == ',') { j->p++; skip_ws(j); continue; }
    if (j->p < j->end && *j->p == close) { j->p++; return 0; }
    return fail(j, "',' or '%c' expected", close);
  }
}

static int parse_value(jparse *j, uint32_t *out, int depth) {
  skip_ws(j);
  if (depth > JSON_MAX_DEPTH) return fail(j, "nested more than %d deep", JSON_MAX_DEPTH);
  if (j->p >= j->end) return fail(j, "a value expected, the text ended");
  char c = *j->p;
  jtype t = c == '{' ? J_OBJ : c == '[' ? J_ARR : c == '"' ? J_STR : c == '-' || (c >= '0' && c <= '9') ? J_NUM
          : c == 't' ? J_TRUE : c == 'f' ? J_FALSE : J_NULL;
  uint32_t id = new_node(j, t);
  if (!id) return fail(j, "out of memory");
  *out = id;
  switch (t) {
  case J_OBJ: case J_ARR: return parse_container(j, id, depth);
  case J_STR: return parse_string(j, &j->d->nodes[id].str);
  case J_NUM: return parse_number(j, &j->d->nodes[id]);
  case J_NULL: case J_TRUE: case J_FALSE: default: {
    const char *word = t == J_TRUE ? "true" : t == J_FALSE ? "false" : "null";
    size_t wl = strlen(word);
    if ((size_t)(j->end - j->p) < wl || memcmp(j->p, word, wl)) return fail(j, "a value expected");
    j->p += wl;
    return 0;
  }
  }
}

int json_parse(jdoc *d, const char *text, size_t len, size_t *line, char *msg, size_t msg_size) {
  memset(d, 0, sizeof *d);
  const char *nul = memchr(text, 0, len);
  if (nul) len = (size_t)(nul - text);
  jparse j = {d, text, text + len, 1, msg, msg_size};
  d->strs = malloc(len + 1);
  uint32_t root = 0;
  new_node(&j, J_NULL); /* node 0 stands for "none" */
  int rc = !d->strs || d->count != 1 ? fail(&j, "out of memory") : parse_value(&j, &root, 1);
  if (!rc) {
    skip_ws(&j);
    if (j.p < j.end) rc = fail(&j, "text after the end of the document");
  }
  *line = j.line;
  if (rc) json_free(d);
  return rc;
}

void json_free(jdoc *d) {
  free(d->nodes);
  free(d->strs);
  memset(d, 0, sizeof *d);
}

uint32_t json_get(const jdoc *d, uint32_t o, const char *key) {
  if (!o || d->nodes[o].t != J_OBJ) return 0;
  for (uint32_t c = d->nodes[o].child; c; c = d->nodes[c].next)
    if (!strcmp(d->nodes[c].key, key)) return c;
  return 0;
}
