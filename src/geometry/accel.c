/* accel.c — owns choosing an acceleration backend by name (see accel.h). */
#include "geometry/accel.h"
#include "core/error.h"
#include <string.h>

valo_status accel_create(const char *kind, const vec3 *pos, uint32_t npos, const uint32_t *idx, uint32_t ntris, int threads,
                         const accel_filter *filter, accel **out, valo_error *err) {
#ifdef VALO_HAVE_EMBREE
  if (!kind || !*kind) kind = "embree"; /* the default where valo was built with Embree (core/options.c) */
#endif
  if (!kind || !*kind || !strcmp(kind, "kdtree")) return kdtree_create(pos, idx, ntris, threads, filter, out, err);
  if (!strcmp(kind, "embree")) return embree_create(pos, npos, idx, ntris, filter, out, err);
  *out = NULL;
  return err_set(err, VALO_ERR_INVALID, "unknown accelerator \"%s\" (kdtree, embree)", kind);
}
