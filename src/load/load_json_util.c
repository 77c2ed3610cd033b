/* load_json_util.c — owns the JSON loader's typed getters and path helpers
 * (load_json_internal.h). */
#include "load/load_json_internal.h"
#include "core/error.h"
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


valo_status json_bad(jctx *c, const char *where, const char *what) {
  return err_set(c->err, VALO_ERR_INVALID, "%s: %s: %s", c->path, where, what);
}

valo_status json_check_keys(jctx *c, const cJSON *obj, const char *where, const char *const *allowed) {
  if (!cJSON_IsObject(obj)) return json_bad(c, where, "must be an object");
  for (const cJSON *it = obj->child; it; it = it->next) {
    int ok = 0;
    for (const char *const *a = allowed; *a; a++)
      if (!strcmp(it->string, *a)) { ok = 1; break; }
    if (!ok) {
      /* the key is the file's: as long as it likes (snprintf returns the length it
       * wanted, so n is clamped to what was written) */
      char msg[512];
      int n = snprintf(msg, sizeof msg, "unknown key \"%.200s%s\" (allowed:", it->string, strlen(it->string) > 200 ? "..." : "");
      if (n < 0 || n > (int)sizeof msg - 1) n = (int)sizeof msg - 1;
      for (const char *const *a = allowed; *a && n < (int)sizeof msg - 40; a++) {
        int k = snprintf(msg + n, sizeof msg - (size_t)n, " %s", *a);
        n = k < 0 || n + k > (int)sizeof msg - 1 ? (int)sizeof msg - 1 : n + k;
      }
      snprintf(msg + n, sizeof msg - (size_t)n, ")");
      return json_bad(c, where, msg);
    }
  }
  return VALO_OK;
}

valo_status json_get_num(jctx *c, const cJSON *o, const char *key, const char *where, double lo, double hi, double *out) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!v) return VALO_OK;
  char w[300];
  snprintf(w, sizeof w, "%s.%s", where, key);
  if (!cJSON_IsNumber(v)) return json_bad(c, w, "must be a number");
  if (!isfinite(v->valuedouble) || v->valuedouble < lo || v->valuedouble > hi) {
    char msg[160];
    snprintf(msg, sizeof msg, "%g is out of range [%g, %g]", v->valuedouble, lo, hi);
    return json_bad(c, w, msg);
  }
  *out = v->valuedouble;
  return VALO_OK;
}
valo_status json_get_int(jctx *c, const cJSON *o, const char *key, const char *where, double lo, double hi, int *out) {
  double d = *out;
  valo_status st = json_get_num(c, o, key, where, lo, hi, &d);
  if (st) return st;
  if (d != floor(d)) {
    char w[300];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return json_bad(c, w, "must be a whole number");
  }
  *out = (int)d;
  return VALO_OK;
}
valo_status json_get_vec(jctx *c, const cJSON *o, const char *key, const char *where, int allow_scalar, vec3 *out) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!v) return VALO_OK;
  char w[300];
  snprintf(w, sizeof w, "%s.%s", where, key);
  if (allow_scalar && cJSON_IsNumber(v)) {
    if (!isfinite(v->valuedouble)) return json_bad(c, w, "must be finite");
    *out = v3((float)v->valuedouble, (float)v->valuedouble, (float)v->valuedouble);
    return VALO_OK;
  }
  if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
    return json_bad(c, w, allow_scalar ? "must be a number or an array of 3 numbers" : "must be an array of 3 numbers");
  float f[3];
  for (int i = 0; i < 3; i++) {
    const cJSON *e = cJSON_GetArrayItem(v, i);
    if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble)) return json_bad(c, w, "must hold 3 finite numbers");
    f[i] = (float)e->valuedouble;
  }
  *out = v3(f[0], f[1], f[2]);
  return VALO_OK;
}
valo_status json_get_rgb(jctx *c, const cJSON *o, const char *key, const char *where, rgb *out) {
  vec3 v = v3(out->r, out->g, out->b);
  valo_status st = json_get_vec(c, o, key, where, 1, &v);
  if (st) return st;
  if (v.x < 0 || v.y < 0 || v.z < 0) {
    char w[300];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return json_bad(c, w, "must not be negative");
  }
  *out = c3(v.x, v.y, v.z);
  return VALO_OK;
}
valo_status json_get_str(jctx *c, const cJSON *o, const char *key, const char *where, const char **out) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!v) return VALO_OK;
  if (!cJSON_IsString(v)) {
    char w[300];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return json_bad(c, w, "must be a string");
  }
  *out = v->valuestring;
  return VALO_OK;
}
valo_status json_get_bool(jctx *c, const cJSON *o, const char *key, const char *where, int *out) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!v) return VALO_OK;
  if (!cJSON_IsBool(v)) {
    char w[300];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return json_bad(c, w, "must be true or false");
  }
  *out = cJSON_IsTrue(v);
  return VALO_OK;
}

void json_resolve_path(const jctx *c, const char *rel, char *out, size_t n) {
  if (rel[0] == '/' || !c->dir[0]) snprintf(out, n, "%s", rel);
  else snprintf(out, n, "%s/%s", c->dir, rel);
}
void json_line_col(const char *text, const char *at, int *line, int *col) {
  *line = 1; *col = 1;
  for (const char *p = text; p < at && *p; p++) {
    if (*p == '\n') { (*line)++; *col = 1; } else (*col)++;
  }
}

valo_status scene_text_read(const char *path, char **out, size_t *out_len, valo_error *err) {
  *out = NULL;
  FILE *f = fopen(path, "rb");
  if (!f) return err_set(err, VALO_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
  char *text = NULL;
  size_t len = 0, cap = 0;
  for (;;) {
    if (len + 4096 + 1 > cap) {
      cap = cap ? cap * 2 : 65536;
      if (cap > (64u << 20)) { fclose(f); free(text); return err_set(err, VALO_ERR_INVALID, "%s: scene file larger than 64 MiB", path); }
      char *t = realloc(text, cap);
      if (!t) { fclose(f); free(text); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
      text = t;
    }
    size_t n = fread(text + len, 1, 4096, f);
    len += n;
    if (n < 4096) break;
  }
  int rerr = ferror(f);
  fclose(f);
  if (rerr) { free(text); return err_set(err, VALO_ERR_IO, "%s: read error", path); }
  text[len] = 0;
  *out = text;
  *out_len = len;
  return VALO_OK;
}
