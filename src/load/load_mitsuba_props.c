/* load_mitsuba_props.c — owns the Mitsuba reader's access to a plugin's properties: the
 * typed readers (numbers, booleans, strings, points, colours and bitmaps), transforms
 * (translate, rotate, scale, matrix, lookat, composed in order), ids and refs, and the
 * messages that name the file, the line and the element. */
#include "load/mitsuba_internal.h"
#include "load/load_json_internal.h"
#include "core/error.h"
#include "core/spectrum.h"
#include "core/grow.h"
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char *label(const xml_node *n, char *buf, size_t len) {
  const char *type = xml_attr_get(n, "type"), *name = xml_attr_get(n, "name"), *id = xml_attr_get(n, "id");
  snprintf(buf, len, "<%s%s%.40s%s%s%.40s%s%s%.40s%s>", n->name, type ? " type=\"" : "", type ? type : "", type ? "\"" : "",
           name ? " name=\"" : "", name ? name : "", name ? "\"" : "", id ? " id=\"" : "", id ? id : "", id ? "\"" : "");
  return buf;
}

valo_status mi_bad(mctx *c, const xml_node *n, const char *fmt, ...) {
  char msg[600], lb[200];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  if (!n) return err_set(c->err, VALO_ERR_INVALID, "%s: %s", c->path, msg);
  return err_set(c->err, VALO_ERR_INVALID, "%s:%d: %s: %s", mi_file(c, n), n->line, label(n, lb, sizeof lb), msg);
}

const char *mi_file(const mctx *c, const xml_node *n) { return n->file ? n->file : c->path; }

/* the length of the main file's folder, its slash included (0 for a bare name) */
static size_t mi_dir_len(const mctx *c) {
  const char *slash = strrchr(c->path, '/');
  return slash ? (size_t)(slash - c->path + 1) : 0;
}

/* name found in the last <path> folder that holds it (malloc'd), or NULL (*nomem set when
 * out of memory) */
static char *in_search(const mctx *c, const char *name, int *nomem) {
  *nomem = 0;
  if (name[0] == '/') return NULL;
  for (int i = c->nsearch - 1; i >= 0; i--) {
    size_t len = strlen(c->search[i]) + strlen(name) + 2;
    char *p = malloc(len);
    if (!p) { *nomem = 1; return NULL; }
    snprintf(p, len, "%s/%s", c->search[i], name);
    if (!access(p, F_OK)) return p;
    free(p);
  }
  return NULL;
}

const char *mi_found(mctx *c, const char *name) {
  int nomem;
  char *p = in_search(c, name, &nomem), **k;
  if (!p) return nomem ? NULL : name;
  if (!(k = grow_for(c->found, (size_t)c->nfound, sizeof *k))) { free(p); return NULL; }
  c->found = k;
  return c->found[c->nfound++] = p;
}

char *mi_beside(const char *file, const char *name) {
  const char *slash = strrchr(file, '/');
  size_t dl = name[0] == '/' || !slash ? 0 : (size_t)(slash - file + 1), len = dl + strlen(name) + 1;
  char *path = malloc(len);
  if (path) snprintf(path, len, "%.*s%s", (int)dl, file, name);
  return path;
}

char *mi_resolve(const mctx *c, const char *name) {
  int nomem;
  char *found = in_search(c, name, &nomem);
  if (found || nomem) return found;
  return mi_beside(c->path, name);
}

const char *mi_where(const mctx *c, const xml_node *n, char *buf, size_t len) {
  if (!n->file) {
    snprintf(buf, len, "line%d", n->line);
    return buf;
  }
  /* the included file's name as its <include> gave it: the main file's folder is where
   * every relative name starts (expand_includes) */
  size_t dl = mi_dir_len(c);
  const char *f = !strncmp(n->file, c->path, dl) ? n->file + dl : n->file;
  snprintf(buf, len, "%.60s:line%d", f, n->line);
  return buf;
}

const char *mi_place(const mctx *c, const xml_node *n, char *buf, size_t len) {
  char w[96];
  snprintf(buf, len, "%s:%d", mi_where(c, n, w, sizeof w), n->col);
  return buf;
}

void mi_warn(mctx *c, const xml_node *n, const char *fmt, ...) {
  if (c->quiet) return;
  char msg[600], lb[200];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  log_warning("%s:%d: %s: %s", mi_file(c, n), n->line, label(n, lb, sizeof lb), msg);
}

static xml_node *find_id(xml_node *n, const char *id) {
  for (; n; n = n->next) {
    const char *v = xml_attr_get(n, "id");
    if (v && !strcmp(v, id) && strcmp(n->name, "ref")) return n; /* a <ref> names an id; it is not the element */
    xml_node *r = find_id(n->child, id);
    if (r) return r;
  }
  return NULL;
}
struct mi_id { const char *id; xml_node *n; int order; };

static int count_ids(const xml_node *n) {
  int k = 0;
  for (; n; n = n->next) k += (xml_attr_get(n, "id") && strcmp(n->name, "ref")) + count_ids(n->child);
  return k;
}
static void list_ids(xml_node *n, struct mi_id *v, int *k) {
  for (; n; n = n->next) {
    const char *id = xml_attr_get(n, "id");
    if (id && strcmp(n->name, "ref")) { v[*k] = (struct mi_id){id, n, *k}; (*k)++; }
    list_ids(n->child, v, k);
  }
}
static int id_cmp(const void *a, const void *b) {
  const struct mi_id *x = a, *y = b;
  int d = strcmp(x->id, y->id);
  return d ? d : (x->order > y->order) - (x->order < y->order);
}
static int id_key(const void *key, const void *b) { return strcmp(key, ((const struct mi_id *)b)->id); }

valo_status mi_index_ids(mctx *c) {
  int n = count_ids(c->root->child), k = 0;
  if (!(c->ids = malloc((size_t)n * sizeof *c->ids + 1))) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  list_ids(c->root->child, c->ids, &k);
  qsort(c->ids, (size_t)n, sizeof *c->ids, id_cmp);
  c->nids = n;
  return VALO_OK;
}

xml_node *mi_find_id(mctx *c, const char *id) {
  if (!id) return NULL;
  if (!c->ids) return find_id(c->root->child, id);
  struct mi_id *e = bsearch(id, c->ids, (size_t)c->nids, sizeof *c->ids, id_key);
  while (e && e > c->ids && !strcmp(e[-1].id, id)) e--; /* the first in document order */
  return e ? e->n : NULL;
}

static int is_property(const xml_node *n) {
  static const char *const t[] = {"float", "integer", "boolean", "string", "rgb", "srgb", "spectrum", "point", "vector", "transform", NULL};
  for (int i = 0; t[i]; i++)
    if (!strcmp(n->name, t[i])) return 1;
  return 0;
}

xml_node *mi_prop(mctx *c, xml_node *p, const char *name) {
  for (xml_node *k = p->child; k; k = k->next) {
    const char *nm = xml_attr_get(k, "name");
    if (!nm || strcmp(nm, name)) continue;
    k->used = 1;
    if (!strcmp(k->name, "ref")) {
      const char *id = xml_attr_get(k, "id");
      xml_node *t = id ? mi_find_id(c, id) : NULL;
      if (t) t->used = 1;
      return t ? t : k; /* an unresolved ref is reported by the reader that needs it */
    }
    return k;
  }
  return NULL;
}

int mi_numbers(const char *s, double *v, int n) {
  int k = 0;
  while (s && *s) {
    while (*s == ',' || isspace((unsigned char)*s)) s++;
    if (!*s) break;
    char *end;
    errno = 0;
    double d = strtod(s, &end);
    if (end == s || !isfinite(d)) return -1;
    if (k < n) v[k] = d;
    k++;
    s = end;
    if (*s && *s != ',' && !isspace((unsigned char)*s)) return -1;
  }
  return k;
}

static valo_status value_of(mctx *c, xml_node *k, const char **v) {
  *v = xml_attr_get(k, "value");
  if (!*v) return mi_bad(c, k, "needs a value=\"...\"");
  return VALO_OK;
}

valo_status mi_float(mctx *c, xml_node *p, const char *name, double *out) {
  xml_node *k = mi_prop(c, p, name);
  if (!k) return VALO_OK;
  if (strcmp(k->name, "float") && strcmp(k->name, "integer")) return mi_bad(c, k, "must be a <float>");
  const char *v;
  valo_status st = value_of(c, k, &v);
  if (st) return st;
  double d;
  if (mi_numbers(v, &d, 1) != 1) return mi_bad(c, k, "value \"%.60s\" is not a number", v);
  *out = d;
  return VALO_OK;
}

valo_status mi_int(mctx *c, xml_node *p, const char *name, int *out) {
  xml_node *k = mi_prop(c, p, name);
  if (!k) return VALO_OK;
  if (strcmp(k->name, "integer")) return mi_bad(c, k, "must be an <integer>");
  const char *v;
  valo_status st = value_of(c, k, &v);
  if (st) return st;
  char *end;
  errno = 0;
  long l = strtol(v, &end, 10);
  if (end == v || *end || errno || l < INT32_MIN || l > INT32_MAX) return mi_bad(c, k, "value \"%.60s\" is not an integer", v);
  *out = (int)l;
  return VALO_OK;
}

valo_status mi_bool(mctx *c, xml_node *p, const char *name, int *out) {
  xml_node *k = mi_prop(c, p, name);
  if (!k) return VALO_OK;
  const char *v;
  if (strcmp(k->name, "boolean")) return mi_bad(c, k, "must be a <boolean>");
  valo_status st = value_of(c, k, &v);
  if (st) return st;
  if (!strcmp(v, "true")) *out = 1;
  else if (!strcmp(v, "false")) *out = 0;
  else return mi_bad(c, k, "value must be true or false");
  return VALO_OK;
}

valo_status mi_string(mctx *c, xml_node *p, const char *name, const char **out) {
  xml_node *k = mi_prop(c, p, name);
  if (!k) return VALO_OK;
  if (strcmp(k->name, "string")) return mi_bad(c, k, "must be a <string>");
  return value_of(c, k, out);
}

/* x, y, z attributes or value="x, y, z". */
static valo_status xyz_of(mctx *c, xml_node *k, double def, double v[3]) {
  const char *val = xml_attr_get(k, "value");
  if (val) {
    int n = mi_numbers(val, v, 3);
    if (n == 1) { v[1] = v[2] = v[0]; return VALO_OK; }
    if (n != 3) return mi_bad(c, k, "value must hold three numbers");
    return VALO_OK;
  }
  static const char *const ax[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; i++) {
    const char *a = xml_attr_get(k, ax[i]);
    v[i] = def;
    if (a && mi_numbers(a, &v[i], 1) != 1) return mi_bad(c, k, "%s=\"%.40s\" is not a number", ax[i], a);
  }
  return VALO_OK;
}

valo_status mi_point(mctx *c, xml_node *p, const char *name, vec3 *out) {
  xml_node *k = mi_prop(c, p, name);
  if (!k) return VALO_OK;
  if (strcmp(k->name, "point") && strcmp(k->name, "vector")) return mi_bad(c, k, "must be a <point> or <vector>");
  double v[3];
  valo_status st = xyz_of(c, k, 0, v);
  if (st) return st;
  *out = v3((float)v[0], (float)v[1], (float)v[2]);
  return VALO_OK;
}

void mi_mat_mul(double r[16], const double a[16], const double b[16]) {
  double t[16];
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) t[4 * i + j] = a[4 * i] * b[j] + a[4 * i + 1] * b[4 + j] + a[4 * i + 2] * b[8 + j] + a[4 * i + 3] * b[12 + j];
  memcpy(r, t, sizeof t);
}

static void identity(double m[16]) {
  memset(m, 0, 16 * sizeof m[0]);
  m[0] = m[5] = m[10] = m[15] = 1;
}

static valo_status vec_attr(mctx *c, xml_node *k, const char *a, int need, double v[3]) {
  const char *s = xml_attr_get(k, a);
  if (!s) {
    if (need) return mi_bad(c, k, "needs %s=\"x, y, z\"", a);
    return VALO_OK;
  }
  if (mi_numbers(s, v, 3) != 3) return mi_bad(c, k, "%s must hold three numbers", a);
  return VALO_OK;
}

/* One operation of a <transform>: the matrix it applies. */
static valo_status transform_op(mctx *c, xml_node *k, double m[16]) {
  identity(m);
  double v[3];
  if (!strcmp(k->name, "translate")) {
    TRY(xyz_of(c, k, 0, v));
    m[3] = v[0]; m[7] = v[1]; m[11] = v[2];
  } else if (!strcmp(k->name, "scale")) {
    TRY(xyz_of(c, k, 1, v));
    m[0] = v[0]; m[5] = v[1]; m[10] = v[2];
  } else if (!strcmp(k->name, "rotate")) {
    double ang = 0;
    const char *a = xml_attr_get(k, "angle");
    if (!a || mi_numbers(a, &ang, 1) != 1) return mi_bad(c, k, "needs angle=\"degrees\"");
    TRY(xyz_of(c, k, 0, v));
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(len > 0)) return mi_bad(c, k, "needs a rotation axis (x, y, z or value)");
    double x = v[0] / len, y = v[1] / len, z = v[2] / len, t = ang * M_PI / 180, cs = cos(t), sn = sin(t), oc = 1 - cs;
    double r[16] = {cs + x * x * oc,     x * y * oc - z * sn, x * z * oc + y * sn, 0, y * x * oc + z * sn, cs + y * y * oc,
                    y * z * oc - x * sn, 0,                   z * x * oc - y * sn, z * y * oc + x * sn, cs + z * z * oc, 0,
                    0,                   0,                   0,                   1};
    memcpy(m, r, sizeof r);
  } else if (!strcmp(k->name, "matrix")) {
    const char *s = xml_attr_get(k, "value");
    double t[16];
    int n = s ? mi_numbers(s, t, 16) : 0;
    if (n == 16) memcpy(m, t, sizeof t);
    else if (n == 9) { for (int i = 0; i < 3; i++) for (int j = 0; j < 3; j++) m[4 * i + j] = t[3 * i + j]; }
    else return mi_bad(c, k, "value must hold 16 numbers (or 9)");
    if (m[12] != 0 || m[13] != 0 || m[14] != 0 || m[15] != 1) return mi_bad(c, k, "the last row must be 0 0 0 1 (no projective transforms)");
  } else if (!strcmp(k->name, "lookat") || !strcmp(k->name, "look_at")) {
    double o[3], t[3], up[3] = {0, 1, 0};
    TRY(vec_attr(c, k, "origin", 1, o));
    TRY(vec_attr(c, k, "target", 1, t));
    TRY(vec_attr(c, k, "up", 0, up));
    double d[3] = {t[0] - o[0], t[1] - o[1], t[2] - o[2]}, dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(dl > 0)) return mi_bad(c, k, "origin and target must differ");
    for (int i = 0; i < 3; i++) d[i] /= dl;
    /* Mitsuba's look-at frame: columns left = up x dir, up' = dir x left, dir. */
    double l[3] = {up[1] * d[2] - up[2] * d[1], up[2] * d[0] - up[0] * d[2], up[0] * d[1] - up[1] * d[0]};
    double ll = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    if (!(ll > 1e-9)) return mi_bad(c, k, "up must not be parallel to the view direction");
    for (int i = 0; i < 3; i++) l[i] /= ll;
    double u[3] = {d[1] * l[2] - d[2] * l[1], d[2] * l[0] - d[0] * l[2], d[0] * l[1] - d[1] * l[0]};
    for (int i = 0; i < 3; i++) { m[4 * i] = l[i]; m[4 * i + 1] = u[i]; m[4 * i + 2] = d[i]; m[4 * i + 3] = o[i]; }
  } else {
    return mi_bad(c, k, "unknown transform operation (translate, rotate, scale, matrix, lookat)");
  }
  return VALO_OK;
}

valo_status mi_transform(mctx *c, xml_node *p, const char *name, double m[16], int *given) {
  identity(m);
  if (given) *given = 0;
  xml_node *k = mi_prop(c, p, name);
  if (!k) return VALO_OK;
  if (strcmp(k->name, "transform")) return mi_bad(c, k, "must be a <transform>");
  if (given) *given = 1;
  for (xml_node *op = k->child; op; op = op->next) {
    double t[16];
    TRY(transform_op(c, op, t));
    mi_mat_mul(m, t, m); /* each operation applies after the ones before it */
  }
  for (int i = 0; i < 16; i++)
    if (!isfinite(m[i])) return mi_bad(c, k, "is not finite");
  return VALO_OK;
}

static float srgb_to_linear(double v) { return (float)(v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4)); }

static cJSON *rgb_json(double r, double g, double b) {
  double v[3] = {r, g, b};
  return cJSON_CreateDoubleArray(v, 3);
}

/* A <spectrum> of wavelength:value pairs ("400:0.2, 500:0.8") or a file of "wavelength
 * value" lines (# comments), in linear sRGB as Mitsuba's RGB modes read it
 * (spectrum_list_to_rgb). */
#define MI_SPECTRUM_MAX 4096
static valo_status mi_spectrum_list(mctx *c, xml_node *k, int emitter, rgb *out) {
  const char *val = xml_attr_get(k, "value"), *file = xml_attr_get(k, "filename");
  if (val && file) return mi_bad(c, k, "give value or filename, not both");
  char *text = NULL;
  if (file) {
    char *path = mi_resolve(c, file);
    if (!path) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    size_t tl;
    valo_error e2;
    valo_status rs = scene_text_read(path, &text, &tl, &e2);
    free(path);
    if (rs) return mi_bad(c, k, "%s", e2.message);
    for (char *p = text; *p; p++) /* comments end at the line's end */
      if (*p == '#') while (*p && *p != '\n') *p++ = ' ';
  }
  float *nm = malloc(2 * MI_SPECTRUM_MAX * sizeof(float));
  if (!nm) { free(text); return err_set(c->err, VALO_ERR_NOMEM, "out of memory"); }
  float *v = nm + MI_SPECTRUM_MAX;
  int n = 0;
  const char *p = file ? text : val, *bad = NULL;
  while (!bad) {
    while (*p && (isspace((unsigned char)*p) || *p == ',')) p++;
    if (!*p) break;
    char *e;
    errno = 0;
    double l = strtod(p, &e);
    if (e == p) { bad = "is not a list of wavelength:value pairs"; break; }
    p = e;
    while (*p == ' ' || *p == '\t') p++;
    if (!file && *p++ != ':') { bad = "is not a list of wavelength:value pairs"; break; }
    double x = strtod(p, &e);
    if (e == p || errno) { bad = "is not a list of wavelength:value pairs"; break; }
    p = e;
    if (n == MI_SPECTRUM_MAX) { bad = "has more than 4096 wavelengths"; break; }
    if (!(l >= 100 && l <= 20000) || (n && !(l > nm[n - 1])) || !isfinite(x)) { bad = "needs increasing wavelengths in nm (100 to 20000) and finite values"; break; }
    nm[n] = (float)l; v[n] = (float)x; n++;
  }
  if (!bad && n == 0) bad = "lists no wavelengths";
  if (!bad) *out = spectrum_list_to_rgb(nm, v, n, emitter);
  free(nm);
  free(text);
  if (bad) return file ? mi_bad(c, k, "%s %s", file, bad) : mi_bad(c, k, "%s", bad);
  return VALO_OK;
}

/* A <texture> as a valo texture object (docs/scene-format.md, "Textures"): a bitmap's file,
 * raw, wrap and filter, or a checkerboard's colours; to_uv as "uv_matrix", turned into
 * valo's texture coordinates (v up where Mitsuba's runs down: F A F with F(u, v) = (u, 1 - v)). */
static valo_status mi_texture(mctx *c, xml_node *k, cJSON **out) {
  const char *type = xml_attr_get(k, "type");
  cJSON *o = cJSON_CreateObject();
  if (!o) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  valo_status st = VALO_OK;
  if (type && !strcmp(type, "bitmap")) {
    const char *file = NULL, *filter = "bilinear", *wrap = "repeat";
    int raw = 0;
    if (!(st = mi_string(c, k, "filename", &file)) && !file) st = mi_bad(c, k, "a bitmap needs <string name=\"filename\">");
    if (!st && !(file = mi_found(c, file))) st = err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    if (!st) st = mi_string(c, k, "filter_type", &filter);
    if (!st) st = mi_string(c, k, "wrap_mode", &wrap);
    if (!st) st = mi_bool(c, k, "raw", &raw);
    if (!st && strcmp(filter, "bilinear") && strcmp(filter, "nearest")) st = mi_bad(c, k, "filter_type must be bilinear or nearest");
    if (!st && strcmp(wrap, "repeat") && strcmp(wrap, "mirror") && strcmp(wrap, "clamp")) st = mi_bad(c, k, "wrap_mode must be repeat, mirror or clamp");
    if (!st && !(cJSON_AddStringToObject(o, "file", file) && cJSON_AddBoolToObject(o, "raw", raw) && cJSON_AddStringToObject(o, "filter", filter) &&
                 cJSON_AddStringToObject(o, "wrap", wrap)))
      st = err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  } else if (type && !strcmp(type, "checkerboard")) {
    cJSON *c0 = NULL, *c1 = NULL;
    if (!cJSON_AddStringToObject(o, "type", "checkerboard")) st = err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    if (!st) st = mi_color(c, k, "color0", MI_RGB_ONLY, &c0);
    if (!st) st = mi_color(c, k, "color1", MI_RGB_ONLY, &c1);
    if (c0) cJSON_AddItemToObject(o, "color0", c0);
    if (c1) cJSON_AddItemToObject(o, "color1", c1);
  } else {
    st = mi_bad(c, k, "valo reads \"bitmap\" and \"checkerboard\" textures");
  }
  double m[16];
  int given = 0;
  if (!st) st = mi_transform(c, k, "to_uv", m, &given);
  if (!st && given) {
    double a = m[0], b = m[1], cc = m[3], d = m[4], e = m[5], f = m[7];
    double uvm[6] = {a, -b, b + cc, -d, e, 1 - e - f};
    cJSON *arr = cJSON_CreateDoubleArray(uvm, 6);
    if (!arr) st = err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    else cJSON_AddItemToObject(o, "uv_matrix", arr);
  }
  if (st) { cJSON_Delete(o); return st; }
  mi_warn_unused(c, k);
  *out = o;
  return VALO_OK;
}

/* Mitsuba's mesh_attribute texture of the mesh's vertex colours, as a diffuse colour:
 * [scale, scale, scale], c->vertex_color set for the material's "vertex_colors". */
static valo_status vertex_color(mctx *c, xml_node *k, int how, cJSON **out) {
  const char *name = NULL;
  double scale = 1;
  TRY(mi_string(c, k, "name", &name));
  if (!name) return mi_bad(c, k, "a mesh_attribute needs <string name=\"name\">");
  if (strcmp(name, "vertex_color"))
    return mi_bad(c, k, "valo reads the mesh attribute \"vertex_color\" (a PLY file's vertex colours), not \"%s\"", name);
  if (!(how & MI_VERTEX))
    return mi_bad(c, k, "valo reads vertex colours as a diffuse colour (diffuse reflectance, a plastic's or phong's diffuse_reflectance, principled's base_color) only");
  TRY(mi_float(c, k, "scale", &scale));
  if (!(scale >= 0 && scale < 1e6)) return mi_bad(c, k, "scale must be a number from 0");
  mi_warn_unused(c, k);
  if (!(*out = cJSON_CreateDoubleArray((double[]){scale, scale, scale}, 3))) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
  c->vertex_color = 1;
  return VALO_OK;
}

valo_status mi_color(mctx *c, xml_node *p, const char *name, int how, cJSON **out) {
  *out = NULL;
  int rgb_only = how & MI_RGB_ONLY;
  xml_node *k = mi_prop(c, p, name);
  if (!k) return VALO_OK;
  if (!strcmp(k->name, "ref")) return mi_bad(c, k, "refers to an id that no element has");
  if (!strcmp(k->name, "texture")) {
    if (rgb_only) return mi_bad(c, k, "valo reads a constant colour here, not a texture");
    const char *type = xml_attr_get(k, "type");
    if (type && !strcmp(type, "mesh_attribute")) return vertex_color(c, k, how, out);
    TRY(mi_texture(c, k, out));
    if ((how & MI_SCALAR) && !cJSON_AddTrueToObject(*out, "luminance")) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    return VALO_OK;
  }
  double v[3];
  const char *val = xml_attr_get(k, "value");
  if (!strcmp(k->name, "float") || !strcmp(k->name, "integer")) {
    if (!val || mi_numbers(val, v, 1) != 1) return mi_bad(c, k, "needs a number");
    v[1] = v[2] = v[0];
  } else if (!strcmp(k->name, "rgb") || !strcmp(k->name, "srgb")) {
    if (!val) return mi_bad(c, k, "needs value=\"r, g, b\"");
    if (val[0] == '#') {
      unsigned x;
      if (strlen(val) != 7 || sscanf(val + 1, "%6x", &x) != 1) return mi_bad(c, k, "a hex colour is #rrggbb");
      v[0] = ((x >> 16) & 255) / 255.0; v[1] = ((x >> 8) & 255) / 255.0; v[2] = (x & 255) / 255.0;
      if (!strcmp(k->name, "rgb")) for (int i = 0; i < 3; i++) v[i] = srgb_to_linear(v[i]);
    } else {
      int n = mi_numbers(val, v, 3);
      if (n == 1) v[1] = v[2] = v[0];
      else if (n != 3) return mi_bad(c, k, "value must hold three numbers (or one)");
    }
    if (!strcmp(k->name, "srgb")) for (int i = 0; i < 3; i++) v[i] = srgb_to_linear(v[i]);
  } else if (!strcmp(k->name, "spectrum") && (xml_attr_get(k, "filename") || (val && strchr(val, ':')))) {
    rgb col;
    TRY(mi_spectrum_list(c, k, how & MI_EMITTER, &col));
    v[0] = col.r; v[1] = col.g; v[2] = col.b;
  } else if (!strcmp(k->name, "spectrum")) {
    if (!val) return mi_bad(c, k, "needs a value (one number, or wavelength:value pairs) or a filename");
    if (mi_numbers(val, v, 1) != 1) return mi_bad(c, k, "value must be a number");
    v[1] = v[2] = v[0];
    /* The equal-energy spectrum's XYZ (1, 1, 1) in linear sRGB (Mitsuba 3 reads
     * 1.20479, 0.948291, 0.908916 from its CIE tables). */
    static const double E[3] = {1.2047843, 0.9483008, 0.9088427};
    if (how & MI_EMITTER) for (int i = 0; i < 3; i++) v[i] *= E[i];
  } else {
    return mi_bad(c, k, "must be a colour (<rgb>, <spectrum>, <float>%s)", rgb_only ? "" : " or a bitmap <texture>");
  }
  *out = rgb_json(v[0], v[1], v[2]);
  return *out ? VALO_OK : err_set(c->err, VALO_ERR_NOMEM, "out of memory");
}

xml_node *mi_child(mctx *c, xml_node *p, const char *tag, int nth) {
  for (xml_node *k = p->child; k; k = k->next) {
    xml_node *t = k;
    if (!strcmp(k->name, "ref")) { /* named or not: the target's tag decides */
      const char *id = xml_attr_get(k, "id");
      t = id ? mi_find_id(c, id) : NULL;
      if (!t) continue;
    }
    if (strcmp(t->name, tag)) continue;
    if (nth-- > 0) continue;
    k->used = t->used = 1;
    return t;
  }
  return NULL;
}

void mi_warn_unused(mctx *c, xml_node *p) {
  for (xml_node *k = p->child; k; k = k->next) {
    if (k->used) continue;
    k->used = 1; /* once */
    if (is_property(k) || !strcmp(k->name, "ref") || !strcmp(k->name, "texture"))
      mi_warn(c, k, "not read by valo (ignored)");
  }
}

