/* registry.c — owns the list of integrators and their parameter tables' parsing
 * ("name=value" text from the scene file and --param, checked against type and range). */
#include "integrator/integrator.h"
#include "core/error.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Adding an integrator: its file defines `const integrator_ops integrator_NAME`, and one
 * line here lists it. */
#define INTEGRATORS(X) \
  X(path) X(guided) X(path_spectral) X(whitted) X(distribution) X(photon) X(vpl) X(vsl) X(ao) X(proximity_ao) X(restir_di) X(restir_gi)

#define DECLARE(n) extern const integrator_ops integrator_##n;
INTEGRATORS(DECLARE)
#define ENTRY(n) &integrator_##n,
static const integrator_ops *const registry[] = {INTEGRATORS(ENTRY) NULL};

const integrator_ops *integrator_at(int i) {
  return i >= 0 && i < (int)(sizeof registry / sizeof registry[0]) ? registry[i] : NULL;
}

const integrator_ops *integrator_find(const char *name) {
  for (int i = 0; registry[i]; i++)
    if (!strcmp(registry[i]->name, name)) return registry[i];
  return NULL;
}

int integrator_param_index(const integrator_ops *ops, const char *name) {
  for (int i = 0; ops->params && ops->params[i].name; i++)
    if (!strcmp(ops->params[i].name, name)) return i;
  return -1;
}

static int is_sep(char ch) { return ch == ' ' || ch == ',' || ch == '\n' || ch == '\t' || ch == ';'; }

valo_status integrator_params_parse(const integrator_ops *ops, const char *text, double *values, int prefixed_only, valo_error *err) {
  int n = 0;
  for (; ops->params && ops->params[n].name; n++) values[n] = ops->params[n].def;
  const char *p = text ? text : "";
  size_t own = strlen(ops->name);
  while (*p) {
    while (*p && is_sep(*p)) p++;
    if (!*p) break;
    const char *e = p;
    while (*e && !is_sep(*e)) e++;
    char item[256];
    snprintf(item, sizeof item, "%.*s", (int)(e - p) < 255 ? (int)(e - p) : 255, p);
    p = e;
    char *eq = strchr(item, '=');
    if (!eq || eq == item) return err_set(err, VALO_ERR_INVALID, "parameter \"%s\": expected name=value", item);
    *eq = 0;
    const char *name = item, *val = eq + 1;
    char *dot = strchr(item, '.');
    if (dot) {
      /* "photon.count": for the photon integrator only */
      if ((size_t)(dot - item) != own || strncmp(item, ops->name, own)) {
        *dot = 0;
        if (!integrator_find(item)) return err_set(err, VALO_ERR_INVALID, "parameter \"%s.%s\": there is no integrator \"%s\"", item, dot + 1, item);
        continue;
      }
      name = dot + 1;
    } else if (prefixed_only) {
      continue;
    }
    int k = integrator_param_index(ops, name);
    if (k < 0) {
      char known[512] = "";
      for (int i = 0; i < n; i++) {
        strncat(known, i ? ", " : "", sizeof known - strlen(known) - 1);
        strncat(known, ops->params[i].name, sizeof known - strlen(known) - 1);
      }
      return err_set(err, VALO_ERR_INVALID, "unknown parameter \"%s\" for the %s integrator (%s%s)", name, ops->name,
                     n ? "it has: " : "it has none", known);
    }
    const integrator_param *d = &ops->params[k];
    char *end;
    double v = strtod(val, &end);
    if (end == val || *end || !(v >= d->lo && v <= d->hi) || (d->type == IPARAM_INT && v != floor(v)))
      return err_set(err, VALO_ERR_INVALID, "parameter %s.%s=%s: expected %s in [%g, %g]", ops->name, name, val,
                     d->type == IPARAM_INT ? "a whole number" : "a number", d->lo, d->hi);
    values[k] = v;
  }
  return VALO_OK;
}

