/* xml.c — see xml.h. A recursive-descent reader over the whole text; nesting deeper than
 * XML_MAX_DEPTH is an error, so no input can exhaust the stack. */
#include "load/xml.h"
#include "core/error.h"
#include "core/grow.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define XML_MAX_DEPTH 64
#define XML_MAX_ATTRS 256 /* per element (the check for a repeated name is quadratic in it) */

typedef struct {
  const char *path, *text, *p, *end;
  valo_error *err;
  const char *mark; /* line_col's last position, with its line and column: the reader */
  int mark_line, mark_col; /* moves forward, so counting goes on from there (linear time) */
} xml_in;

static void line_col(xml_in *x, const char *at, int *line, int *col) {
  if (at < x->mark) { x->mark = x->text; x->mark_line = x->mark_col = 1; } /* behind the mark: count again */
  int l = x->mark_line, c = x->mark_col;
  const char *q = x->mark;
  for (; q < at && q < x->end; q++) {
    if (*q == '\n') { l++; c = 1; } else c++;
  }
  x->mark = q; x->mark_line = *line = l; x->mark_col = *col = c;
}

static valo_status bad(xml_in *x, const char *at, const char *what) {
  int line, col;
  line_col(x, at, &line, &col);
  return err_set(x->err, VALO_ERR_PARSE, "%s:%d:%d: XML: %s", x->path, line, col, what);
}

static int is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
static int is_name(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.' ||
         c == ':' || (unsigned char)c >= 0x80;
}
static void skip_space(xml_in *x) { while (x->p < x->end && is_space(*x->p)) x->p++; }
static int starts(const xml_in *x, const char *s) {
  size_t n = strlen(s);
  return (size_t)(x->end - x->p) >= n && !memcmp(x->p, s, n);
}

/* Skips whitespace, comments and (outside the root) the prolog and doctype. */
static valo_status skip_misc(xml_in *x, int prolog) {
  for (;;) {
    skip_space(x);
    if (starts(x, "<!--")) {
      const char *e = NULL;
      for (const char *q = x->p + 4; q + 3 <= x->end; q++)
        if (q[0] == '-' && q[1] == '-' && q[2] == '>') { e = q; break; }
      if (!e) return bad(x, x->p, "comment not closed (no -->)");
      x->p = e + 3;
    } else if (prolog && (starts(x, "<?") || starts(x, "<!DOCTYPE"))) {
      const char *e = memchr(x->p, '>', (size_t)(x->end - x->p));
      if (!e) return bad(x, x->p, "declaration not closed (no >)");
      x->p = e + 1;
    } else {
      return VALO_OK;
    }
  }
}

static char *read_name(xml_in *x) {
  const char *s = x->p;
  while (x->p < x->end && is_name(*x->p)) x->p++;
  if (x->p == s) return NULL;
  char *n = malloc((size_t)(x->p - s) + 1);
  if (n) { memcpy(n, s, (size_t)(x->p - s)); n[x->p - s] = 0; }
  return n;
}

static int utf8_put(char *o, unsigned long cp) {
  if (cp < 0x80) { o[0] = (char)cp; return 1; }
  if (cp < 0x800) { o[0] = (char)(0xc0 | (cp >> 6)); o[1] = (char)(0x80 | (cp & 0x3f)); return 2; }
  if (cp < 0x10000) {
    o[0] = (char)(0xe0 | (cp >> 12)); o[1] = (char)(0x80 | ((cp >> 6) & 0x3f)); o[2] = (char)(0x80 | (cp & 0x3f));
    return 3;
  }
  o[0] = (char)(0xf0 | (cp >> 18)); o[1] = (char)(0x80 | ((cp >> 12) & 0x3f));
  o[2] = (char)(0x80 | ((cp >> 6) & 0x3f)); o[3] = (char)(0x80 | (cp & 0x3f));
  return 4;
}

/* A quoted attribute value with its entities decoded (the decoded text is never longer). */
static valo_status read_value(xml_in *x, char **out) {
  char q = *x->p;
  if (q != '"' && q != '\'') return bad(x, x->p, "attribute value must be quoted");
  const char *s = ++x->p;
  const char *e = memchr(s, q, (size_t)(x->end - s));
  if (!e) return bad(x, s - 1, "attribute value not closed");
  char *v = malloc((size_t)(e - s) + 1), *o = v;
  if (!v) return err_set(x->err, VALO_ERR_NOMEM, "out of memory");
  for (const char *c = s; c < e;) {
    if (*c == '<') { free(v); return bad(x, c, "'<' inside an attribute value"); }
    if (*c != '&') { *o++ = *c++; continue; }
    const char *semi = memchr(c, ';', (size_t)(e - c));
    size_t n = semi ? (size_t)(semi - c) : 0;
    static const struct { const char *name; char ch; } ent[] = {{"&amp", '&'}, {"&lt", '<'}, {"&gt", '>'}, {"&quot", '"'}, {"&apos", '\''}};
    int done = 0;
    for (size_t i = 0; semi && i < 5 && !done; i++)
      if (n == strlen(ent[i].name) && !memcmp(c, ent[i].name, n)) { *o++ = ent[i].ch; done = 1; }
    if (!done && semi && n >= 3 && c[1] == '#') {
      int hex = c[2] == 'x';
      unsigned long cp = 0;
      const char *d = c + 2 + hex;
      for (; d < semi; d++) {
        int dv = (*d >= '0' && *d <= '9') ? *d - '0' : hex && (*d | 32) >= 'a' && (*d | 32) <= 'f' ? (*d | 32) - 'a' + 10 : -1;
        if (dv < 0 || cp > 0x10ffff) break;
        cp = cp * (hex ? 16u : 10u) + (unsigned long)dv;
      }
      /* Its UTF-8 is never longer than the reference's text. */
      if (d == semi && d > c + 2 + hex && cp > 0 && cp <= 0x10ffff) { o += utf8_put(o, cp); done = 1; }
    }
    if (!done) { free(v); return bad(x, c, "unknown entity (&amp; &lt; &gt; &quot; &apos; &#N; &#xN;)"); }
    c = semi + 1;
  }
  *o = 0;
  x->p = e + 1;
  *out = v;
  return VALO_OK;
}

void xml_free(xml_node *n) {
  while (n) {
    xml_node *next = n->next;
    xml_free(n->child);
    for (int i = 0; i < n->nattrs; i++) { free(n->attrs[i].name); free(n->attrs[i].value); }
    free(n->attrs);
    free(n->name);
    free(n);
    n = next;
  }
}

static valo_status read_element(xml_in *x, xml_node *parent, int depth, xml_node **out) {
  if (depth > XML_MAX_DEPTH) return bad(x, x->p, "elements nested more than 64 deep");
  const char *open = x->p;
  if (!starts(x, "<")) return bad(x, x->p, "expected an element ('<')");
  x->p++;
  xml_node *n = calloc(1, sizeof *n);
  if (!n) return err_set(x->err, VALO_ERR_NOMEM, "out of memory");
  *out = n;
  n->parent = parent;
  int line, col;
  line_col(x, open, &line, &col);
  n->line = line;
  n->col = col;
  if (!(n->name = read_name(x))) return bad(x, x->p, "expected an element name");
  for (;;) {
    skip_space(x);
    if (x->p >= x->end) return bad(x, open, "element not closed");
    if (starts(x, "/>")) { x->p += 2; return VALO_OK; }
    if (*x->p == '>') { x->p++; break; }
    const char *at = x->p;
    char *an = read_name(x);
    if (!an) return bad(x, x->p, "expected an attribute name, '>' or '/>'");
    for (int i = 0; i < n->nattrs; i++)
      if (!strcmp(n->attrs[i].name, an)) { free(an); return bad(x, at, "attribute given twice"); }
    if (n->nattrs == XML_MAX_ATTRS) { free(an); return bad(x, at, "more than 256 attributes on one element"); }
    xml_attr *a = grow_for(n->attrs, (size_t)n->nattrs, sizeof *a);
    if (!a) { free(an); return err_set(x->err, VALO_ERR_NOMEM, "out of memory"); }
    n->attrs = a;
    a[n->nattrs].name = an;
    a[n->nattrs].value = NULL;
    n->nattrs++;
    skip_space(x);
    if (x->p >= x->end || *x->p != '=') return bad(x, x->p, "expected '=' after the attribute name");
    x->p++;
    skip_space(x);
    if (x->p >= x->end) return bad(x, open, "element not closed");
    valo_status st = read_value(x, &a[n->nattrs - 1].value);
    if (st) return st;
  }
  /* Content: children, comments and text (text is ignored). */
  xml_node **tail = &n->child;
  for (;;) {
    while (x->p < x->end && *x->p != '<') x->p++;
    if (x->p >= x->end) return bad(x, open, "element not closed (no end tag)");
    if (starts(x, "<!--")) { valo_status st = skip_misc(x, 0); if (st) return st; continue; }
    if (starts(x, "</")) {
      x->p += 2;
      const char *s = x->p;
      while (x->p < x->end && is_name(*x->p)) x->p++;
      if ((size_t)(x->p - s) != strlen(n->name) || memcmp(s, n->name, (size_t)(x->p - s))) {
        char msg[200];
        snprintf(msg, sizeof msg, "end tag does not match <%.80s> of line %d", n->name, n->line);
        return bad(x, s, msg);
      }
      skip_space(x);
      if (x->p >= x->end || *x->p != '>') return bad(x, x->p, "expected '>' to end the end tag");
      x->p++;
      return VALO_OK;
    }
    if (starts(x, "<![CDATA[") || starts(x, "<?") || starts(x, "<!")) return bad(x, x->p, "CDATA, processing instructions and declarations are not read inside elements");
    valo_status st = read_element(x, n, depth + 1, tail);
    if (st) return st;
    tail = &(*tail)->next;
  }
}

valo_status xml_parse(const char *path, const char *text, size_t len, xml_node **root, valo_error *err) {
  *root = NULL;
  xml_in x = {path, text, text, text + len, err, text, 1, 1};
  if (len >= 3 && (unsigned char)text[0] == 0xef && (unsigned char)text[1] == 0xbb && (unsigned char)text[2] == 0xbf) x.p += 3;
  if (strlen(text) != len) return err_set(err, VALO_ERR_PARSE, "%s: contains a NUL byte: not an XML text file", path);
  valo_status st = skip_misc(&x, 1);
  if (!st && x.p >= x.end) st = bad(&x, x.p, "no element in the file");
  if (!st) st = read_element(&x, NULL, 0, root);
  if (!st) st = skip_misc(&x, 0);
  if (!st && x.p < x.end) st = bad(&x, x.p, "text after the root element");
  if (st) { xml_free(*root); *root = NULL; }
  return st;
}

const char *xml_attr_get(const xml_node *n, const char *name) {
  for (int i = 0; i < n->nattrs; i++)
    if (!strcmp(n->attrs[i].name, name)) return n->attrs[i].value;
  return NULL;
}
