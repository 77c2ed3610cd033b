/* api_integrator.c — owns the public view of the integrator registry: the names, each
 * one's description and parameter table, and the check of parameter text. */
#include "valo/valo.h"
#include "integrator/integrator.h"
#include "core/error.h"
#include <pthread.h>
#include <stdio.h>
#include <string.h>

VALO_API int valo_integrator_describe(const char *name, char *buf, size_t n) {
  const integrator_ops *ops = integrator_find(name);
  if (!ops || !buf || n == 0) return -1;
  size_t used = (size_t)snprintf(buf, n, "%s: %s\n", ops->name, ops->description);
  for (int i = 0; ops->params && ops->params[i].name && used < n; i++) {
    const integrator_param *d = &ops->params[i];
    used += (size_t)snprintf(buf + used, n - used, "    %s.%s = %g  (%s, %g..%g) %s\n", ops->name, d->name, d->def,
                             d->type == IPARAM_INT ? "integer" : "number", d->lo, d->hi, d->doc);
  }
  return 0;
}
static const char *g_names[64];
static pthread_once_t g_names_once = PTHREAD_ONCE_INIT;
static void fill_names(void) {
  for (int i = 0; integrator_at(i) && i < 63; i++) g_names[i] = integrator_at(i)->name;
}
VALO_API const char *const *valo_integrator_names(void) {
  pthread_once(&g_names_once, fill_names);
  return g_names;
}


VALO_API valo_status valo_integrator_check_params(const char *name, const char *params, valo_error *err) {
  if (err) { err->status = VALO_OK; err->message[0] = 0; }
  const integrator_ops *ops = integrator_find(name);
  if (!ops) return err_set(err, VALO_ERR_INVALID, "unknown integrator \"%s\"", name);
  double v[INTEGRATOR_MAX_PARAMS];
  return integrator_params_parse(ops, params, v, 0, err);
}
