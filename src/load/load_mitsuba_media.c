/* load_mitsuba_media.c — owns the translation of Mitsuba's media (homogeneous, and
 * heterogeneous over a grid volume) into valo's media (docs/scene-format.md, "Mitsuba
 * scenes"). */
#include "load/mitsuba_internal.h"
#include "load/load_json_internal.h"
#include "core/error.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NOMEM err_set(c->err, VALO_ERR_NOMEM, "out of memory")

static valo_status phase_g(mctx *c, xml_node *med, double *g) {
  xml_node *p = mi_child(c, med, "phase", 0);
  *g = 0;
  if (!p) return VALO_OK;
  const char *t = xml_attr_get(p, "type");
  if (t && !strcmp(t, "hg")) TRY(mi_float(c, p, "g", g));
  else if (!t || strcmp(t, "isotropic")) return mi_bad(c, p, "valo's phase functions are isotropic and hg");
  if (!(*g > -1 && *g < 1)) return mi_bad(c, p, "g must be in (-1, 1)");
  mi_warn_unused(c, p);
  return VALO_OK;
}

/* A constant medium property: a colour, or a constvolume holding one. */
static valo_status const_color(mctx *c, xml_node *med, const char *name, double def, double v[3]) {
  xml_node *k = mi_prop(c, med, name);
  v[0] = v[1] = v[2] = def;
  if (!k) return VALO_OK;
  xml_node *src = med;
  const char *key = name;
  if (!strcmp(k->name, "volume")) {
    const char *t = xml_attr_get(k, "type");
    if (!t || strcmp(t, "constvolume")) return mi_bad(c, k, "valo reads %s as a constant here", name);
    src = k;
    key = "value";
  }
  cJSON *col;
  TRY(mi_color(c, src, key, MI_RGB_ONLY, &col));
  if (col) {
    for (int i = 0; i < 3; i++) v[i] = cJSON_GetArrayItem(col, i)->valuedouble;
    cJSON_Delete(col);
  }
  if (src != med) mi_warn_unused(c, src);
  return VALO_OK;
}

valo_status mi_medium(mctx *c, xml_node *med, char *name, size_t n) {
  const char *id = xml_attr_get(med, "id");
  char where[96];
  if (id) snprintf(name, n, "%.90s", id);
  else snprintf(name, n, "medium@%s", mi_place(c, med, where, sizeof where));
  if (cJSON_GetObjectItemCaseSensitive(c->media, name)) return VALO_OK;
  med->used = 1;
  const char *type = xml_attr_get(med, "type");
  int het = type && !strcmp(type, "heterogeneous");
  if (!het && (!type || strcmp(type, "homogeneous"))) return mi_bad(c, med, "valo reads homogeneous and heterogeneous media");
  cJSON *o = cJSON_CreateObject();
  if (!o) return NOMEM;
  cJSON_AddItemToObject(c->media, name, o);
  double g, scale = 1, albedo[3], st[3], sa[3], ss[3];
  TRY(phase_g(c, med, &g));
  TRY(mi_float(c, med, "scale", &scale));
  xml_node *grid = NULL;
  if (het) {
    xml_node *k = mi_prop(c, med, "sigma_t");
    if (!k) k = mi_prop(c, med, "density"); /* Mitsuba 0.6 */
    if (k && !strcmp(k->name, "volume")) {
      const char *t = xml_attr_get(k, "type");
      if (!t || strcmp(t, "gridvolume")) return mi_bad(c, k, "valo reads a density grid from a gridvolume (.vol file)");
      grid = k;
    } else {
      return mi_bad(c, med, "a heterogeneous medium needs sigma_t as a gridvolume");
    }
  }
  TRY(const_color(c, med, "albedo", 0.75, albedo));
  if (!grid) TRY(const_color(c, med, "sigma_t", 1, st));
  else st[0] = st[1] = st[2] = 1;
  if (mi_prop(c, med, "sigma_a") || mi_prop(c, med, "sigma_s")) {
    /* Mitsuba 0.6: sigma_a and sigma_s */
    TRY(const_color(c, med, "sigma_a", 0, sa));
    TRY(const_color(c, med, "sigma_s", 0, ss));
  } else {
    for (int i = 0; i < 3; i++) { ss[i] = albedo[i] * st[i]; sa[i] = st[i] - ss[i]; }
  }
  for (int i = 0; i < 3; i++)
    if (!(sa[i] >= 0 && ss[i] >= 0)) return mi_bad(c, med, "the coefficients must be positive (albedo in [0, 1])");
  cJSON_AddStringToObject(o, "type", grid ? "grid" : "homogeneous");
  cJSON_AddItemToObject(o, "sigma_a", cJSON_CreateDoubleArray(sa, 3));
  cJSON_AddItemToObject(o, "sigma_s", cJSON_CreateDoubleArray(ss, 3));
  cJSON_AddNumberToObject(o, "scale", scale);
  cJSON_AddNumberToObject(o, "g", g);
  if (grid) {
    const char *file = NULL;
    TRY(mi_string(c, grid, "filename", &file));
    if (!file) return mi_bad(c, grid, "needs <string name=\"filename\">");
    if (!(file = mi_found(c, file))) return err_set(c->err, VALO_ERR_NOMEM, "out of memory");
    cJSON_AddStringToObject(o, "file", file);
    double m[16];
    int given;
    TRY(mi_transform(c, grid, "to_world", m, &given));
    if (m[1] != 0 || m[2] != 0 || m[4] != 0 || m[6] != 0 || m[8] != 0 || m[9] != 0)
      return mi_bad(c, grid, "valo's grids are axis-aligned boxes: to_world may only scale and translate");
    /* The unit cube placed by to_world, as Mitsuba 3's gridvolume. */
    double lo[3], hi[3];
    for (int i = 0; i < 3; i++) {
      double a = m[4 * i + 3], b2 = m[4 * i + i] + m[4 * i + 3];
      lo[i] = fmin(a, b2);
      hi[i] = fmax(a, b2);
    }
    cJSON_AddItemToObject(o, "bounds_min", cJSON_CreateDoubleArray(lo, 3));
    cJSON_AddItemToObject(o, "bounds_max", cJSON_CreateDoubleArray(hi, 3));
    mi_warn_unused(c, grid);
  }
  mi_warn_unused(c, med);
  return VALO_OK;
}

