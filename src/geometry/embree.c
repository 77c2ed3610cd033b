/* embree.c — owns the Embree 3 backend behind accel.h: one triangle geometry with its own
 * vertex/index buffers, robust (watertight) scene flag, rtcIntersect1/rtcOccluded1. */
#include "geometry/accel.h"
#include "core/error.h"
#include <stdlib.h>
#include <string.h>

#ifdef VALO_HAVE_EMBREE
#include <embree3/rtcore.h>

typedef struct embree_accel { accel base; RTCDevice dev; RTCScene scn; accel_filter filter; } embree_accel;

/* Intersection and occlusion filter: rejects hits the alpha test discards. */
static void em_filter(const struct RTCFilterFunctionNArguments *args) {
  const embree_accel *e = args->geometryUserPtr;
  for (unsigned i = 0; i < args->N; i++) {
    if (args->valid[i] != -1) continue;
    /* RTCHitN is SoA: Ng_x[N] Ng_y[N] Ng_z[N] u[N] v[N] primID[N] ... (rtcore_ray.h; its
     * accessors are C++ only). */
    const float *hf = (const float *)args->hit;
    const unsigned *hu = (const unsigned *)args->hit;
    unsigned prim = hu[5 * args->N + i];
    if (!(e->filter.tri_flags[prim] & e->filter.flag_bit)) continue;
    /* RTCRayN is SoA too: org_x org_y org_z tnear dir_x dir_y dir_z ... */
    const float *rf = (const float *)args->ray;
    unsigned n = args->N;
    uint64_t key = accel_ray_key(v3(rf[i], rf[n + i], rf[2 * n + i]), v3(rf[4 * n + i], rf[5 * n + i], rf[6 * n + i]));
    if (!e->filter.pass(e->filter.user, prim, hf[3 * args->N + i], hf[4 * args->N + i], key)) args->valid[i] = 0;
  }
}

static int em_intersect(const accel *a, const ray *r, hit *h) {
  const embree_accel *e = (const embree_accel *)a;
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  struct RTCRayHit rh;
  rh.ray.org_x = r->o.x; rh.ray.org_y = r->o.y; rh.ray.org_z = r->o.z;
  rh.ray.dir_x = r->d.x; rh.ray.dir_y = r->d.y; rh.ray.dir_z = r->d.z;
  rh.ray.tnear = 0; rh.ray.tfar = r->tmax; rh.ray.time = 0; rh.ray.mask = 0xFFFFFFFF; rh.ray.id = 0; rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID; rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(e->scn, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID || !(rh.ray.tfar > 0)) return 0;
  h->t = rh.ray.tfar; h->b1 = rh.hit.u; h->b2 = rh.hit.v; h->tri = rh.hit.primID;
  return 1;
}
static int em_occluded(const accel *a, const ray *r) {
  const embree_accel *e = (const embree_accel *)a;
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  struct RTCRay ry;
  ry.org_x = r->o.x; ry.org_y = r->o.y; ry.org_z = r->o.z;
  ry.dir_x = r->d.x; ry.dir_y = r->d.y; ry.dir_z = r->d.z;
  ry.tnear = 0; ry.tfar = r->tmax; ry.time = 0; ry.mask = 0xFFFFFFFF; ry.id = 0; ry.flags = 0;
  rtcOccluded1(e->scn, &ctx, &ry);
  return ry.tfar < 0;
}
static void em_destroy(accel *a) {
  embree_accel *e = (embree_accel *)a;
  if (!e) return;
  if (e->scn) rtcReleaseScene(e->scn);
  if (e->dev) rtcReleaseDevice(e->dev);
  free(e);
}
static const accel_ops em_ops = {"embree", em_intersect, em_occluded, em_destroy};

int embree_available(void) { return 1; }

valo_status embree_create(const vec3 *pos, const uint32_t *idx, uint32_t ntris, const accel_filter *filter, accel **out,
                          valo_error *err) {
  *out = NULL;
  embree_accel *e = calloc(1, sizeof *e);
  if (!e) return err_set(err, VALO_ERR_NOMEM, "embree: out of memory");
  e->base.ops = &em_ops;
  e->dev = rtcNewDevice(NULL);
  if (!e->dev) { free(e); return err_set(err, VALO_ERR_UNSUPPORTED, "embree: cannot create a device"); }
  e->scn = rtcNewScene(e->dev);
  rtcSetSceneFlags(e->scn, RTC_SCENE_FLAG_ROBUST);
  if (ntris > 0) {
    /* Vertices: one per triangle corner would waste memory; share the indexed set. */
    uint32_t maxv = 0;
    for (size_t i = 0; i < (size_t)ntris * 3; i++) if (idx[i] + 1 > maxv) maxv = idx[i] + 1;
    RTCGeometry g = rtcNewGeometry(e->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), maxv);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), ntris);
    if (!vb || !ib) { rtcReleaseGeometry(g); em_destroy(&e->base); return err_set(err, VALO_ERR_NOMEM, "embree: out of memory"); }
    for (uint32_t i = 0; i < maxv; i++) { vb[3 * i] = pos[i].x; vb[3 * i + 1] = pos[i].y; vb[3 * i + 2] = pos[i].z; }
    memcpy(ib, idx, (size_t)ntris * 3 * sizeof(unsigned));
    if (filter && filter->pass && filter->tri_flags) {
      e->filter = *filter;
      rtcSetGeometryUserData(g, e);
      rtcSetGeometryIntersectFilterFunction(g, em_filter);
      rtcSetGeometryOccludedFilterFunction(g, em_filter);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(e->scn, g);
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(e->scn);
  if (rtcGetDeviceError(e->dev) != RTC_ERROR_NONE) { em_destroy(&e->base); return err_set(err, VALO_ERR_INVALID, "embree: scene build failed"); }
  *out = &e->base;
  return VALO_OK;
}
#else
int embree_available(void) { return 0; }
valo_status embree_create(const vec3 *pos, const uint32_t *idx, uint32_t ntris, const accel_filter *filter, accel **out,
                          valo_error *err) {
  (void)pos; (void)idx; (void)ntris;
  *out = NULL;
  return err_set(err, VALO_ERR_UNSUPPORTED, "this valo was built without Embree (install libembree-dev and rebuild)");
}
#endif
