/* embree.c — owns the Embree 3 backend behind accel.h: one triangle geometry on the
 * scene's own vertex/index arrays (shared; copied when no spare vertex follows), robust
 * (watertight) scene flag, rtcIntersect1/rtcOccluded1 (and rtcOccluded1M for a batch).
 * Embree's own test, less precise on large triangles, lets a ray find the surface it
 * leaves (ambient occlusion of a floor 200 units wide: 1.6 % of rays, 2 000 wide: 44 %),
 * whose error valo's offset ray origins are not made for. So a candidate whose plane lies
 * near the ray's origin is tested again by valo's own watertight test
 * (geometry/triangle.h, the kd-tree's): every occlusion candidate, and a closest hit
 * within EM_FAR of the scene's size from the origin, whose reported t and barycentrics
 * are then that test's. */
#include "geometry/accel.h"
#include "geometry/triangle.h"
#include "core/error.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef VALO_HAVE_EMBREE
#include <embree3/rtcore.h>

struct embree_accel {
  accel base;
  RTCDevice dev;
  RTCScene scn;
  accel_filter filter; /* alpha: filter.pass NULL when no triangle needs it */
  const float *vb;     /* the geometry's vertex and index buffers (the second test) */
  const unsigned *ib;
  float far2;          /* (EM_FAR of the largest coordinate)^2: a closest hit whose plane
                        * lies farther than its root from the ray's origin needs no second test */
};

/* A query's context: Embree's first, so that a filter can reach the rest. */
typedef struct embree_accel embree_accel;
typedef struct em_query {
  struct RTCIntersectContext ctx;
  const embree_accel *e;
  ray_shear sh;
  vec3 o, d;
  float tmax;
} em_query;

static void em_corners(const embree_accel *e, unsigned prim, float v[9]) {
  for (int k = 0; k < 3; k++) memcpy(&v[3 * k], &e->vb[3 * (size_t)e->ib[3 * (size_t)prim + k]], 3 * sizeof(float));
}

/* 1 when the ray from o along d meets the plane of triangle v behind its origin or not at
 * all (in double): a hit Embree finds there but valo's test does not is the surface the
 * ray leaves. Where the plane lies ahead, the two tests differ on an edge between two
 * triangles (each watertight, by its own rules), and Embree's hit stands. */
static int em_left(const float v[9], vec3 o, vec3 d) {
  double e1[3], e2[3], n[3];
  for (int k = 0; k < 3; k++) { e1[k] = (double)v[3 + k] - v[k]; e2[k] = (double)v[6 + k] - v[k]; }
  n[0] = e1[1] * e2[2] - e1[2] * e2[1]; n[1] = e1[2] * e2[0] - e1[0] * e2[2]; n[2] = e1[0] * e2[1] - e1[1] * e2[0];
  double nd = n[0] * d.x + n[1] * d.y + n[2] * d.z, nw = n[0] * ((double)v[0] - o.x) + n[1] * ((double)v[1] - o.y) + n[2] * ((double)v[2] - o.z);
  return !(nd != 0 && nw / nd > 0);
}

/* The alpha test (a geometry filter, set when a triangle needs it): rejects the hits it
 * discards. */
static void em_alpha(const struct RTCFilterFunctionNArguments *args) {
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

/* Occlusion queries' context filter: drops a candidate valo's test does not find that
 * lies on the surface the ray leaves (em_left). */
static void em_verify(const struct RTCFilterFunctionNArguments *args) {
  const em_query *q = (const em_query *)args->context;
  for (unsigned i = 0; i < args->N; i++) {
    if (args->valid[i] != -1) continue;
    unsigned prim = ((const unsigned *)args->hit)[5 * args->N + i];
    float v[9], t, b1, b2;
    em_corners(q->e, prim, v);
    if (!tri_intersect(&q->sh, v, q->tmax, &t, &b1, &b2) && em_left(v, q->o, q->d)) args->valid[i] = 0;
  }
}

/* The share of the scene's largest coordinate beyond which a triangle's plane cannot be
 * the surface a ray leaves: valo's offset origins sit about 1e-6 of their coordinates off
 * that surface, and Embree's error in the plane's distance is a few float ulps of the
 * coordinates (2^-23 each), so 2^-12 leaves a margin of 2 000 ulps. */
#define EM_FAR 0x1p-12f

/* The closest hit: Embree's. Where its triangle's plane lies near the ray's origin (the
 * origin's distance from it, t |Ng.d| / |Ng|, below EM_FAR of the scene's size), valo's test checks it again:
 * where that test does not find it and the ray does not even cross the plane ahead
 * (Embree's error on a large triangle exceeds valo's offset: the surface the ray leaves),
 * the query goes on past it (at most four times), and where the two tests disagree on an
 * edge, Embree's hit stands; valo's numbers are reported where its test finds the hit.
 * Farther off, the hit cannot be the surface the ray leaves and Embree's t and
 * barycentrics are reported as they are (the second test was 6 % of a path's
 * instructions on Veach's MIS file, and its triangle's fetch stalled on memory). */
static int em_intersect(const accel *a, const ray *r, hit *h) {
  const embree_accel *e = (const embree_accel *)a;
  em_query q;
  rtcInitIntersectContext(&q.ctx);
  q.sh = ray_shear_make(r->o, r->d);
  q.tmax = r->tmax;
  q.e = e;
  float tnear = 0;
  for (int tries = 0; tries < 4; tries++) {
    struct RTCRayHit rh;
    rh.ray.org_x = r->o.x; rh.ray.org_y = r->o.y; rh.ray.org_z = r->o.z;
    rh.ray.dir_x = r->d.x; rh.ray.dir_y = r->d.y; rh.ray.dir_z = r->d.z;
    rh.ray.tnear = tnear; rh.ray.tfar = r->tmax; rh.ray.time = 0; rh.ray.mask = 0xFFFFFFFF; rh.ray.id = 0; rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID; rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(e->scn, &q.ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID || !(rh.ray.tfar > 0)) return 0;
    h->t = rh.ray.tfar; h->b1 = rh.hit.u; h->b2 = rh.hit.v; h->tri = rh.hit.primID;
    float nd = rh.hit.Ng_x * r->d.x + rh.hit.Ng_y * r->d.y + rh.hit.Ng_z * r->d.z;
    float n2 = rh.hit.Ng_x * rh.hit.Ng_x + rh.hit.Ng_y * rh.hit.Ng_y + rh.hit.Ng_z * rh.hit.Ng_z;
    float dist = h->t * fabsf(nd);                     /* the origin's distance from the plane, times |Ng| */
    if (dist * dist > e->far2 * n2) return 1;         /* false for NaN: tested */
    float v[9];
    em_corners(e, rh.hit.primID, v);
    if (tri_intersect(&q.sh, v, q.tmax, &h->t, &h->b1, &h->b2)) return 1; /* valo's own numbers */
    if (!em_left(v, r->o, r->d)) return 1; /* the tests differ on an edge: Embree's hit stands */
    tnear = nextafterf(rh.ray.tfar, INFINITY);
  }
  return 0;
}
static int em_occluded(const accel *a, const ray *r) {
  const embree_accel *e = (const embree_accel *)a;
  em_query q;
  rtcInitIntersectContext(&q.ctx);
  q.sh = ray_shear_make(r->o, r->d);
  q.tmax = r->tmax;
  q.o = r->o;
  q.d = r->d;
  q.e = e;
  q.ctx.filter = em_verify;
  struct RTCRay ry;
  ry.org_x = r->o.x; ry.org_y = r->o.y; ry.org_z = r->o.z;
  ry.dir_x = r->d.x; ry.dir_y = r->d.y; ry.dir_z = r->d.z;
  ry.tnear = 0; ry.tfar = r->tmax; ry.time = 0; ry.mask = 0xFFFFFFFF; ry.id = 0; ry.flags = 0;
  rtcOccluded1(e->scn, &q.ctx, &ry);
  return ry.tfar < 0;
}
/* The stream query's context: the rays, found by the id each Embree ray carries. */
typedef struct em_query_n {
  struct RTCIntersectContext ctx;
  const embree_accel *e;
  const ray *r;
} em_query_n;

/* em_verify for the rays of a stream (RTCRayN is SoA: ... tfar mask id flags, id at
 * 10 N). */
static void em_verify_n(const struct RTCFilterFunctionNArguments *args) {
  const em_query_n *q = (const em_query_n *)args->context;
  const unsigned *ids = (const unsigned *)args->ray + 10 * (size_t)args->N;
  for (unsigned i = 0; i < args->N; i++) {
    if (args->valid[i] != -1) continue;
    const ray *r = &q->r[ids[i]];
    unsigned prim = ((const unsigned *)args->hit)[5 * args->N + i];
    float v[9], t, b1, b2;
    em_corners(q->e, prim, v);
    ray_shear sh = ray_shear_make(r->o, r->d);
    if (!tri_intersect(&sh, v, r->tmax, &t, &b1, &b2) && em_left(v, r->o, r->d)) args->valid[i] = 0;
  }
}

/* em_occluded for n rays, given to Embree as streams of up to 256 (rtcOccluded1M). */
static void em_occluded_n(const accel *a, const ray *r, uint8_t *blocked, int n) {
  const embree_accel *e = (const embree_accel *)a;
  em_query_n q;
  rtcInitIntersectContext(&q.ctx);
  q.ctx.filter = em_verify_n;
  q.e = e;
  enum { CHUNK = 256 };
  struct RTCRay ry[CHUNK];
  for (int k0 = 0; k0 < n; k0 += CHUNK) {
    int m = n - k0 < CHUNK ? n - k0 : CHUNK;
    q.r = r + k0;
    for (int i = 0; i < m; i++) {
      const ray *ri = &r[k0 + i];
      struct RTCRay *y = &ry[i];
      y->org_x = ri->o.x; y->org_y = ri->o.y; y->org_z = ri->o.z;
      y->dir_x = ri->d.x; y->dir_y = ri->d.y; y->dir_z = ri->d.z;
      y->tnear = 0; y->tfar = ri->tmax; y->time = 0; y->mask = 0xFFFFFFFF; y->id = (unsigned)i; y->flags = 0;
    }
    rtcOccluded1M(e->scn, &q.ctx, ry, (unsigned)m, sizeof(struct RTCRay));
    for (int i = 0; i < m; i++) blocked[k0 + i] = ry[i].tfar < 0;
  }
}

static void em_destroy(accel *a) {
  embree_accel *e = (embree_accel *)a;
  if (!e) return;
  if (e->scn) rtcReleaseScene(e->scn);
  if (e->dev) rtcReleaseDevice(e->dev);
  free(e);
}
static const accel_ops em_ops = {"embree", em_intersect, em_occluded, em_destroy, em_occluded_n};

int embree_available(void) { return 1; }

valo_status embree_create(const vec3 *pos, uint32_t npos, const uint32_t *idx, uint32_t ntris, const accel_filter *filter, accel **out,
                          valo_error *err) {
  *out = NULL;
  embree_accel *e = calloc(1, sizeof *e);
  if (!e) return err_set(err, VALO_ERR_NOMEM, "embree: out of memory");
  e->base.ops = &em_ops;
  e->dev = rtcNewDevice(NULL);
  if (!e->dev) { free(e); return err_set(err, VALO_ERR_UNSUPPORTED, "embree: cannot create a device"); }
  e->scn = rtcNewScene(e->dev);
  rtcSetSceneFlags(e->scn, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
  if (ntris > 0) {
    uint32_t maxv = 0;
    for (size_t i = 0; i < (size_t)ntris * 3; i++) if (idx[i] + 1 > maxv) maxv = idx[i] + 1;
    if (maxv > npos) { em_destroy(&e->base); return err_set(err, VALO_ERR_INVALID, "embree: a triangle uses vertex %u of %u", maxv - 1, npos); }
    RTCGeometry g = rtcNewGeometry(e->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    const float *vb;
    const unsigned *ib;
    if (maxv < npos) { /* a spare vertex after the last one used: Embree's 16-byte loads stay inside */
      rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, pos, 0, sizeof(vec3), maxv);
      rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, idx, 0, 3 * sizeof(unsigned), ntris);
      vb = &pos[0].x;
      ib = idx;
    } else {
      float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), maxv);
      unsigned *i3 = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), ntris);
      if (!v || !i3) { rtcReleaseGeometry(g); em_destroy(&e->base); return err_set(err, VALO_ERR_NOMEM, "embree: out of memory"); }
      for (uint32_t i = 0; i < maxv; i++) { v[3 * i] = pos[i].x; v[3 * i + 1] = pos[i].y; v[3 * i + 2] = pos[i].z; }
      memcpy(i3, idx, (size_t)ntris * 3 * sizeof(unsigned));
      vb = v;
      ib = i3;
    }
    if (filter && filter->pass && filter->tri_flags) e->filter = *filter;
    float big = 0;
    for (uint32_t i = 0; i < maxv; i++) big = fmaxf(big, fmaxf(fabsf(pos[i].x), fmaxf(fabsf(pos[i].y), fabsf(pos[i].z))));
    e->far2 = (EM_FAR * big) * (EM_FAR * big);
    e->vb = vb;
    e->ib = ib;
    if (e->filter.pass) {
      rtcSetGeometryUserData(g, e);
      rtcSetGeometryIntersectFilterFunction(g, em_alpha);
      rtcSetGeometryOccludedFilterFunction(g, em_alpha);
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
valo_status embree_create(const vec3 *pos, uint32_t npos, const uint32_t *idx, uint32_t ntris, const accel_filter *filter, accel **out,
                          valo_error *err) {
  (void)pos; (void)npos; (void)idx; (void)ntris;
  *out = NULL;
  return err_set(err, VALO_ERR_UNSUPPORTED, "this valo was built without Embree (install libembree-dev and rebuild)");
}
#endif
