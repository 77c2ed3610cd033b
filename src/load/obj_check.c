/* obj_check.c — see obj_check.h. Two passes over the OBJ: the first counts vertices and
 * reads the MTL files, the second checks each line and writes the repaired text. */
#include "load/obj_check.h"
#include "core/error.h"
#include "core/grow.h"
#include <assimp/cfileio.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

char *obj_check_read_whole(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  size_t cap = 1 << 16, n = 0;
  char *buf = malloc(cap + 1);
  while (buf) {
    size_t got = fread(buf + n, 1, cap - n, f);
    n += got;
    if (n < cap) break;
    char *nb = realloc(buf, 2 * cap + 1);
    if (!nb) { free(buf); buf = NULL; break; }
    buf = nb;
    cap *= 2;
  }
  int bad = ferror(f);
  fclose(f);
  if (!buf || bad) { free(buf); return NULL; }
  buf[n] = 0;
  *len = n;
  return buf;
}

/* Output buffer for a repaired text. */
typedef struct outbuf { char *p; size_t n, cap; int oom; } outbuf;
static void ob_put(outbuf *o, const char *s, size_t n) {
  if (o->oom) return;
  if (o->n + n + 1 > o->cap) {
    size_t nc = o->cap ? o->cap : 4096;
    while (nc < o->n + n + 1) nc *= 2;
    char *q = realloc(o->p, nc);
    if (!q) { o->oom = 1; return; }
    o->p = q;
    o->cap = nc;
  }
  memcpy(o->p + o->n, s, n);
  o->n += n;
  o->p[o->n] = 0;
}

/* Writes line [s, e) with every number token of the form [+-].digit given a leading 0
 * (Assimp 5.2's OBJ reader takes ".8e-1" for no number at all). */
static void put_fixed(outbuf *o, const char *s, const char *e) {
  const char *p = s;
  while (p < e) {
    int tok_start = p == s || isspace((unsigned char)p[-1]);
    if (tok_start) {
      const char *q = p;
      if (*q == '+' || *q == '-') q++;
      if (q + 1 < e && q[0] == '.' && isdigit((unsigned char)q[1])) {
        ob_put(o, p, (size_t)(q - p));
        ob_put(o, "0", 1);
        p = q;
      }
    }
    ob_put(o, p, 1);
    p++;
  }
}

/* The line starting at s: its end (before \r\n or \n) and the next line's start. */
static const char *line_end(const char *s, const char *end, const char **next) {
  const char *e = memchr(s, '\n', (size_t)(end - s));
  if (!e) e = end;
  *next = e < end ? e + 1 : end;
  if (e > s && e[-1] == '\r') e--;
  return e;
}

/* Splits [s, e) into whitespace-separated tokens (at most max); returns the count. */
static int tokens(const char *s, const char *e, const char **tb, const char **te, int max) {
  int n = 0;
  const char *p = s;
  while (p < e) {
    while (p < e && isspace((unsigned char)*p)) p++;
    if (p >= e) break;
    const char *q = p;
    while (q < e && !isspace((unsigned char)*q)) q++;
    if (n < max) { tb[n] = p; te[n] = q; }
    n++;
    p = q;
  }
  return n;
}

/* The end of the rest of a line from token b (names such as "newmtl My Material" run to
 * the line's end, as Assimp reads them), trailing blanks dropped. */
static const char *rest_end(const char *b, const char *e) {
  while (e > b && isspace((unsigned char)e[-1])) e--;
  return e;
}

static int tok_is(const char *b, const char *e, const char *word) {
  size_t n = strlen(word);
  return (size_t)(e - b) == n && !strncmp(b, word, n);
}
static int tok_is_ci(const char *b, const char *e, const char *word) {
  size_t n = strlen(word);
  return (size_t)(e - b) == n && !strncasecmp(b, word, n);
}

/* A number token (with a leading-dot repair); 0 if it is not entirely a number. */
static int tok_number(const char *b, const char *e, double *v) {
  char buf[64];
  size_t n = (size_t)(e - b);
  if (n == 0 || n > 60) return 0;
  memcpy(buf, b, n);
  buf[n] = 0;
  char *end;
  errno = 0;
  *v = strtod(buf, &end);
  return end == buf + n && end != buf;
}

/* Whether pass 2 keeps a vertex line cut off by the end of the file: it has the numbers
 * it needs before the first token that is not one. Other lines: 1. */
static int truncated_line_kept(const char *s, const char *e) {
  const char *tb[64], *te[64];
  int nt = tokens(s, e, tb, te, 64);
  int kv = tok_is(tb[0], te[0], "v"), kt = tok_is(tb[0], te[0], "vt"), kn = tok_is(tb[0], te[0], "vn");
  if (!(kv || kt || kn)) return 1;
  int got = 0;
  double v;
  for (int k = 1; k < nt && k < 64 && tok_number(tb[k], te[k], &v); k++) got++;
  return got >= (kt ? 1 : 3);
}

static int line_printable(const char *s, const char *e) {
  for (const char *p = s; p < e; p++)
    if ((unsigned char)*p < 32 && *p != '\t') return 0;
  return 1;
}

/* ----------------------------------------------------------------- MTL */

static const char *mtl_number_keys[] = {"Ka", "Kd", "Ks", "Ke", "Tf", "Ns", "Ni", "d", "Tr", "illum", "sharpness", NULL};

static valo_status read_mtl(obj_check *oc, const char *path, const char *obj_path, int obj_line, valo_error *err) {
  (void)err;
  if (oc->nfiles >= (int)(sizeof oc->files / sizeof oc->files[0])) {
    log_warning("%s:%d: material library %s is past the %d valo reads: its materials become grey diffuse", obj_path, obj_line,
                path, (int)(sizeof oc->files / sizeof oc->files[0]) - 1);
    return VALO_OK;
  }
  size_t len;
  char *txt = obj_check_read_whole(path, &len);
  if (!txt) {
    log_warning("%s:%d: material library %s cannot be read (%s): its materials become grey diffuse", obj_path, obj_line, path,
                strerror(errno));
    return VALO_OK;
  }
  /* Assimp's MTL reader ends a line at NUL, form feed or a lone carriage return too, so
   * a comment could hide a statement from valo: such bytes become spaces, which both read
   * as valo did. */
  for (size_t i = 0; i < len; i++) {
    unsigned char c = (unsigned char)txt[i];
    if (c < 32 && c != '\t' && c != '\n' && !(c == '\r' && i + 1 < len && txt[i + 1] == '\n')) txt[i] = ' ';
  }
  outbuf o = {0};
  const char *s = txt, *end = txt + len, *next;
  int line = 0;
  mtl_pbr *cur = NULL;
  char ignored[128] = "";
  int orphans = 0, orphan_line = 0;
  for (; s < end; s = next) {
    const char *e = line_end(s, end, &next);
    line++;
    const char *tb[8], *te[8];
    int nt = tokens(s, e, tb, te, 8);
    if (nt == 0 || *tb[0] == '#') { ob_put(&o, s, (size_t)(next - s)); continue; }
    if (tok_is(tb[0], te[0], "newmtl") && nt >= 2) {
      mtl_pbr *np = grow_for(oc->pbr, (size_t)oc->npbr, sizeof *np);
      if (!np) { free(txt); free(o.p); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
      oc->pbr = np;
      cur = &oc->pbr[oc->npbr++];
      memset(cur, 0, sizeof *cur);
      /* The name runs to the end of the line, as Assimp reads it. */
      const char *ne = rest_end(tb[1], e);
      snprintf(cur->name, sizeof cur->name, "%.*s", (int)(ne - tb[1]), tb[1]);
      ob_put(&o, tb[0], (size_t)(next - tb[0]));
      continue;
    }
    if (!cur) { /* Assimp writes a texture statement here through a null material */
      if (!orphans++) orphan_line = line;
      continue;
    }
    double v;
    if ((tok_is(tb[0], te[0], "Pr") || tok_is(tb[0], te[0], "Pm")) && nt >= 2 && tok_number(tb[1], te[1], &v)) {
      if (isfinite(v)) {
        if (tb[0][1] == 'r') { cur->has_pr = 1; cur->pr = (float)v; }
        else { cur->has_pm = 1; cur->pm = (float)v; }
      }
      continue; /* valo reads these itself */
    }
    if ((tok_is(tb[0], te[0], "map_Pr") || tok_is(tb[0], te[0], "map_Pm")) && nt >= 2) {
      snprintf(tb[0][5] == 'r' ? cur->map_pr : cur->map_pm, sizeof cur->map_pr, "%.*s", (int)(te[nt < 8 ? nt - 1 : 7] - tb[nt < 8 ? nt - 1 : 7]), tb[nt < 8 ? nt - 1 : 7]);
      continue;
    }
    const char *ign[] = {"Ps", "Pc", "Pcr", "aniso", "anisor", "map_Ps", "map_Pc", "map_Pcr", NULL};
    int dropped = 0;
    for (int k = 0; ign[k]; k++)
      if (tok_is(tb[0], te[0], ign[k])) {
        if (!strstr(ignored, ign[k]) && strlen(ignored) + strlen(ign[k]) + 3 < sizeof ignored) {
          if (ignored[0]) strcat(ignored, ", ");
          strcat(ignored, ign[k]);
        }
        dropped = 1;
      }
    if (dropped) continue;
    int numeric = 0;
    for (int k = 0; mtl_number_keys[k]; k++) numeric |= tok_is(tb[0], te[0], mtl_number_keys[k]);
    if (numeric) { put_fixed(&o, tb[0], e); ob_put(&o, "\n", 1); }
    else ob_put(&o, tb[0], (size_t)(next - tb[0]));
  }
  free(txt);
  if (o.oom) { free(o.p); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  if (orphans)
    log_warning("%s:%d: %d statement%s before the first newmtl belong%s to no material and %s ignored", path, orphan_line, orphans,
                orphans > 1 ? "s" : "", orphans > 1 ? "" : "s", orphans > 1 ? "are" : "is");
  if (ignored[0]) log_warning("%s: %s (sheen, clearcoat, anisotropy) are not modelled by valo and are ignored", path, ignored);
  obj_text *f = &oc->files[oc->nfiles++];
  snprintf(f->path, sizeof f->path, "%s", path);
  f->text = o.p ? o.p : calloc(1, 1);
  f->len = o.n;
  return VALO_OK;
}

static int mtl_known(const obj_check *oc, const char *b, const char *e) {
  for (int i = 0; i < oc->npbr; i++)
    if ((size_t)(e - b) == strlen(oc->pbr[i].name) && !strncmp(b, oc->pbr[i].name, (size_t)(e - b))) return 1;
  return 0;
}

const mtl_pbr *obj_check_pbr(const obj_check *oc, const char *name) {
  for (int i = oc->npbr - 1; i >= 0; i--)
    if (!strcmp(oc->pbr[i].name, name)) return &oc->pbr[i];
  return NULL;
}

/* ----------------------------------------------------------------- OBJ */

/* Checks one face vertex reference "v[/vt[/vn]]" against the counts so far (negative:
 * relative) and in all (positive). Returns 0, or -1 with a message in msg. */
static int check_ref(const char *b, const char *e, const long sofar[3], const long total[3], char *msg, size_t nmsg) {
  static const char *what[3] = {"vertex", "texture coordinate", "normal"};
  const char *p = b;
  for (int k = 0; k < 3 && p <= e; k++) {
    const char *q = p;
    while (q < e && *q != '/') q++;
    if (q == p) {
      if (k == 0) { snprintf(msg, nmsg, "face vertex \"%.*s\" has no vertex number", (int)(e - b), b); return -1; }
    } else {
      char buf[32];
      size_t n = (size_t)(q - p);
      if (n >= sizeof buf) n = sizeof buf - 1;
      memcpy(buf, p, n);
      buf[n] = 0;
      char *end;
      long v = strtol(buf, &end, 10);
      if (*end) { snprintf(msg, nmsg, "face vertex \"%.*s\" is not a vertex number", (int)(e - b), b); return -1; }
      long idx = v > 0 ? v : sofar[k] + v + 1;
      long limit = v > 0 ? total[k] : sofar[k];
      if (v == 0 || idx < 1 || idx > limit) {
        snprintf(msg, nmsg, "face refers to %s %ld, but the file defines %ld", what[k], v, v > 0 ? total[k] : sofar[k]);
        return -1;
      }
    }
    p = q + 1;
  }
  return 0;
}

valo_status obj_check_read(const char *path, obj_check *oc, valo_error *err) {
  memset(oc, 0, sizeof *oc);
  size_t len;
  char *txt = obj_check_read_whole(path, &len);
  if (!txt) return err_set(err, VALO_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
  const char *end = txt + len, *next;
  char dir[1024] = "";
  const char *slash = strrchr(path, '/');
  if (slash) snprintf(dir, sizeof dir, "%.*s/", (int)(slash - path), path);
  oc->nfiles = 1;
  /* Pass 1: totals, and the material libraries. */
  long total[3] = {0, 0, 0};
  int line = 0;
  for (const char *s = txt; s < end; s = next) {
    const char *e = line_end(s, end, &next);
    line++;
    const char *tb[2], *te[2];
    int nt = tokens(s, e, tb, te, 2);
    if (nt == 0 || !line_printable(s, e)) continue; /* pass 2 refuses or ignores it */
    if (next >= end && e == end && len > 0 && txt[len - 1] != '\n' && !truncated_line_kept(s, e)) continue; /* pass 2 drops it */
    if (tok_is(tb[0], te[0], "v")) total[0]++;
    else if (tok_is(tb[0], te[0], "vt")) total[1]++;
    else if (tok_is(tb[0], te[0], "vn")) total[2]++;
    else if (tok_is(tb[0], te[0], "mtllib") && nt >= 2) {
      const char *ne = rest_end(tb[1], e);
      char mp[2048];
      snprintf(mp, sizeof mp, "%s%.*s", tb[1][0] == '/' ? "" : dir, (int)(ne - tb[1]), tb[1]);
      valo_status st = read_mtl(oc, mp, path, line, err);
      if (st) { free(txt); obj_check_free(oc); return st; }
    }
  }
  /* Pass 2: check and repair each line. */
  outbuf o = {0};
  long sofar[3] = {0, 0, 0};
  long kept_faces = 0, dropped_faces = 0, first_dropped = 0, elements = 0, not_understood = 0, first_nu = 0, bad_usemtl = 0;
  char msg[256];
  valo_status st = VALO_OK;
  line = 0;
  for (const char *s = txt; s < end; s = next) {
    const char *e = line_end(s, end, &next);
    line++;
    int last = next >= end;
    int truncated = last && (e == end) && len > 0 && txt[len - 1] != '\n';
    const char *tb[64], *te[64];
    int nt = tokens(s, e, tb, te, 64);
    if (nt == 0 || *tb[0] == '#') { ob_put(&o, "\n", 1); continue; } /* a comment may hold a byte Assimp ends a line at */
    if (!line_printable(s, e)) {
      /* control bytes in a vertex or face line: a damaged file (dropping the line would
       * shift every index after it) */
      if (tok_is(tb[0], te[0], "v") || tok_is(tb[0], te[0], "vt") || tok_is(tb[0], te[0], "vn") || tok_is(tb[0], te[0], "f")) {
        st = err_set(err, VALO_ERR_PARSE, "%s:%d: control bytes (binary data) in a %.*s line: the file is damaged", path, line,
                     (int)(te[0] - tb[0]), tb[0]);
        goto done;
      }
      if (!not_understood++) first_nu = line;
      continue;
    }
    int kv = tok_is(tb[0], te[0], "v"), kt = tok_is(tb[0], te[0], "vt"), kn = tok_is(tb[0], te[0], "vn");
    if (kv || kt || kn) {
      int need = kt ? 1 : 3, got = 0;
      for (int k = 1; k < nt && k < 64; k++) {
        double v;
        if (!tok_number(tb[k], te[k], &v)) {
          if (truncated) break;
          st = err_set(err, VALO_ERR_PARSE, "%s:%d: \"%.*s\" is not a number", path, line, (int)(te[k] - tb[k]), tb[k]);
          goto done;
        }
        if ((!isfinite(v) || fabs(v) > FLT_MAX) && k <= 3) {
          st = err_set(err, VALO_ERR_INVALID, "%s:%d: %s coordinate \"%.*s\" is not a finite number", path, line,
                       kv ? "vertex" : kt ? "texture" : "normal", (int)(te[k] - tb[k]), tb[k]);
          goto done;
        }
        got++;
      }
      if (got < need) {
        if (truncated) {
          log_warning("%s:%d: the file ends in the middle of a line (truncated?); that line is ignored", path, line);
          continue;
        }
        st = err_set(err, VALO_ERR_PARSE, "%s:%d: a %s needs %d numbers, found %d", path, line,
                     kv ? "vertex" : kt ? "texture coordinate" : "normal", need, got);
        goto done;
      }
      sofar[kv ? 0 : kt ? 1 : 2]++;
      put_fixed(&o, tb[0], e);
      ob_put(&o, "\n", 1);
      continue;
    }
    if (tok_is(tb[0], te[0], "f")) {
      int bad = 0;
      for (int k = 1; k < nt && k < 64; k++)
        if (check_ref(tb[k], te[k], sofar, total, msg, sizeof msg)) { bad = 1; break; }
      if ((bad || nt - 1 < 3) && truncated) {
        log_warning("%s:%d: the file ends in the middle of a line (truncated?); that face is ignored", path, line);
        continue;
      }
      if (bad) { st = err_set(err, VALO_ERR_INVALID, "%s:%d: %s", path, line, msg); goto done; }
      if (nt - 1 < 3) {
        if (!dropped_faces++) first_dropped = line;
        continue;
      }
      kept_faces++;
      ob_put(&o, tb[0], (size_t)(next - tb[0]));
      continue;
    }
    if (tok_is(tb[0], te[0], "l") || tok_is(tb[0], te[0], "p")) { elements++; continue; }
    if (tok_is(tb[0], te[0], "usemtl")) {
      const char *ne = rest_end(tb[nt > 1 ? 1 : 0], e);
      if (nt >= 2 && !mtl_known(oc, tb[1], ne)) {
        if (bad_usemtl++ < 5)
          log_warning("%s:%d: usemtl %.*s: no material library of this file defines it; those faces are grey diffuse "
                      "(and emit nothing)", path, line, (int)(ne - tb[1]), tb[1]);
      }
      ob_put(&o, tb[0], (size_t)(next - tb[0]));
      continue;
    }
    static const char *known[] = {"g", "o", "s", "mtllib", "vp", "cstype", "deg", "curv", "curv2", "surf", "parm", "trim", "hole",
                                  "scrv", "sp", "end", "con", "bmat", "step", "mg", "call", "csh", "lod", "bevel", "c_interp",
                                  "d_interp", "shadow_obj", "trace_obj", "ctech", "stech", "maplib", "usemap", NULL};
    int ok = 0;
    for (int k = 0; known[k]; k++) ok |= tok_is_ci(tb[0], te[0], known[k]);
    if (ok) { ob_put(&o, tb[0], (size_t)(next - tb[0])); continue; }
    if (!not_understood++) first_nu = line;
  }
  if (o.oom) { st = err_set(err, VALO_ERR_NOMEM, "out of memory"); goto done; }
  if (total[0] == 0) { st = err_set(err, VALO_ERR_INVALID, "%s: no vertices (no \"v\" lines): not an OBJ file, or empty", path); goto done; }
  if (kept_faces == 0) {
    st = err_set(err, VALO_ERR_INVALID, "%s: no usable triangles: no face with three or more vertices (%ld vertices, %ld shorter faces, "
                 "%ld line/point elements)", path, total[0], dropped_faces, elements);
    goto done;
  }
  if (dropped_faces)
    log_warning("%s:%ld: %ld face%s with fewer than three vertices dropped (first at this line)", path, first_dropped, dropped_faces,
                dropped_faces > 1 ? "s" : "");
  if (elements) log_warning("%s: %ld line/point elements (l, p) ignored: valo renders surfaces", path, elements);
  if (not_understood) log_warning("%s:%ld: %ld line%s not understood and ignored (first at this line)", path, first_nu, not_understood,
                                  not_understood > 1 ? "s" : "");
  if (bad_usemtl > 5) log_warning("%s: %ld usemtl lines in all name no material", path, bad_usemtl);
  snprintf(oc->files[0].path, sizeof oc->files[0].path, "%s", path);
  oc->files[0].text = o.p ? o.p : calloc(1, 1);
  oc->files[0].len = o.n;
  o.p = NULL;
done:
  free(txt);
  free(o.p);
  if (st) obj_check_free(oc);
  return st;
}

void obj_check_free(obj_check *oc) {
  for (int i = 0; i < oc->nfiles; i++) free(oc->files[i].text);
  free(oc->pbr);
  free(oc->gmat);
  memset(oc, 0, sizeof *oc);
}

/* ------------------------------------------------- Assimp file callbacks */

typedef struct mem_file { const char *p; size_t len, pos; } mem_file;

static size_t mf_read(struct aiFile *f, char *buf, size_t size, size_t count) {
  mem_file *m = (mem_file *)f->UserData;
  if (size == 0) return 0;
  size_t avail = (m->len - m->pos) / size, n = count < avail ? count : avail;
  memcpy(buf, m->p + m->pos, n * size);
  m->pos += n * size;
  return n;
}
static size_t mf_write(struct aiFile *f, const char *b, size_t s, size_t c) { (void)f; (void)b; (void)s; (void)c; return 0; }
static size_t mf_tell(struct aiFile *f) { return ((mem_file *)f->UserData)->pos; }
static size_t mf_size(struct aiFile *f) { return ((mem_file *)f->UserData)->len; }
static void mf_flush(struct aiFile *f) { (void)f; }
static enum aiReturn mf_seek(struct aiFile *f, size_t off, enum aiOrigin origin) {
  mem_file *m = (mem_file *)f->UserData;
  size_t base = origin == aiOrigin_SET ? 0 : origin == aiOrigin_CUR ? m->pos : m->len;
  if (base + off > m->len) return aiReturn_FAILURE;
  m->pos = base + off;
  return aiReturn_SUCCESS;
}

static const char *base_name(const char *p) {
  const char *s = strrchr(p, '/');
  return s ? s + 1 : p;
}

static struct aiFile *fio_open(struct aiFileIO *io, const char *path, const char *mode) {
  (void)mode;
  obj_check *oc = (obj_check *)io->UserData;
  const obj_text *hit = NULL;
  for (int i = 0; i < oc->nfiles && !hit; i++)
    if (oc->files[i].text && !strcmp(oc->files[i].path, path)) hit = &oc->files[i];
  for (int i = 1; i < oc->nfiles && !hit; i++) /* MTL paths as Assimp spells them */
    if (oc->files[i].text && !strcmp(base_name(oc->files[i].path), base_name(path))) hit = &oc->files[i];
  /* Only the texts valo has read: a file valo did not (an mtllib it found no file for,
   * past its sixteenth, or one Assimp names by another path) is not opened at all. */
  if (!hit) return NULL;
  struct aiFile *f = calloc(1, sizeof *f);
  mem_file *m = calloc(1, sizeof *m);
  if (!f || !m) { free(f); free(m); return NULL; }
  m->p = hit->text;
  m->len = hit->len;
  f->ReadProc = mf_read; f->WriteProc = mf_write; f->TellProc = mf_tell; f->FileSizeProc = mf_size;
  f->SeekProc = mf_seek; f->FlushProc = mf_flush; f->UserData = (aiUserData)m;
  return f;
}
static void fio_close(struct aiFileIO *io, struct aiFile *f) {
  (void)io;
  if (!f) return;
  free(f->UserData);
  free(f);
}

void obj_check_fileio(obj_check *oc, struct aiFileIO *io) {
  io->OpenProc = fio_open;
  io->CloseProc = fio_close;
  io->UserData = (aiUserData)oc;
}
