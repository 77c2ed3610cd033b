/* bench_raykernel.c — valo's SAH kd-tree against Embree 3 on the same incoherent rays
 * (camera rays plus one cosine-weighted bounce from each camera hit), 1 and 2 threads:
 * build seconds, Mrays/s for closest-hit and for shadow (any-hit) queries, and the
 * kd/Embree ratio, on the bunny, nefertiti, the dragon, Sponza and a Cornell box with the
 * bunny. Then the kd-tree build on the dragon's four resolutions (N log N growth, 2
 * threads) with the tree's bytes and the build's peak resident bytes per triangle.
 * Prints Markdown tables; scenes come from ../shared/scenes (or VALO_SHARED). --classes
 * instead times camera misses, camera hits and bounce rays apart; --bound times the
 * kd-tree's node walk alone (its leaves free) against the real queries and Embree, and
 * the share of triangle groups a query tests again (what mailboxing could skip).
 * --packets times Embree's own queries on camera rays, bounce rays and shadow rays, one
 * ray at a time (rtcIntersect1, as valo uses it) against packets of 8 and 16 consecutive
 * rays (rtcIntersect8/16, rtcOccluded8/16) and streams of 256 (rtcIntersect1M): what
 * many rays in flight would gain in traversal alone.
 * Usage: bench_raykernel [--quick] [--only NAME] [--no-build-table] [--classes] [--bound] [--packets] */
#include "bench_util.h"
#include "scene/scene.h"
#include "load/load.h"
#include "geometry/accel.h"
#include "geometry/offset.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "core/threadpool.h"
#include <stdio.h>
#include <stdlib.h>
#include <malloc.h>
#include <string.h>
#include <time.h>

#ifdef VALO_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

#ifndef VALO_SHARED_DIR
#define VALO_SHARED_DIR "../shared"
#endif

static const char *shared(const char *rel, char *buf, size_t n) {
  const char *root = getenv("VALO_SHARED");
  snprintf(buf, n, "%s/%s", root && *root ? root : VALO_SHARED_DIR, rel);
  return buf;
}
static long status_kb(const char *key) {
  FILE *f = fopen("/proc/self/status", "r");
  char line[256];
  long v = -1;
  size_t n = strlen(key);
  while (f && fgets(line, sizeof line, f)) if (!strncmp(line, key, n)) v = atol(line + n);
  if (f) fclose(f);
  return v;
}
/* Returns freed heap memory to the system and resets the peak resident size to the
 * current one (Linux: clear_refs 5), so that the peak after a build less the size before
 * it is the build's own peak. */
static void reset_peak_rss(void) {
  malloc_trim(0);
  FILE *f = fopen("/proc/self/clear_refs", "w");
  if (f) { fputs("5", f); fclose(f); }
}

typedef struct job { const accel *a; const ray *rays; long n; int shadow; long hits; } job;
typedef struct chunk_arg { job *j; long hits[64]; } chunk_arg;
#define CHUNK 4096
static void trace_chunk(void *user, int64_t item, int t) {
  chunk_arg *c = user;
  long lo = item * CHUNK, hi = lo + CHUNK < c->j->n ? lo + CHUNK : c->j->n, hits = 0;
  for (long i = lo; i < hi; i++) {
    hit h;
    if (c->j->shadow) hits += accel_occluded(c->j->a, &c->j->rays[i]);
    else hits += accel_intersect(c->j->a, &c->j->rays[i], &h);
  }
  c->hits[t] += hits;
}
/* Mrays/s of both backends on the same rays: repetitions alternate between them (kd,
 * Embree, kd, Embree, ...) and each keeps its best, so a slow spell on the shared
 * machine hits both alike instead of one. */
#define REPS 5
static void trace_pair(accel *const a[2], const ray *rays, long n, int threads, int shadow, double mrays[2], long hits[2]) {
  double best[2] = {1e30, 1e30};
  for (int rep = 0; rep < REPS; rep++)
    for (int k = 0; k < 2; k++) {
      job j = {a[k], rays, n, shadow, 0};
      chunk_arg c;
      memset(&c, 0, sizeof c);
      c.j = &j;
      double t0 = bench_now();
      parallel_for(threads, (n + CHUNK - 1) / CHUNK, trace_chunk, &c);
      double dt = bench_now() - t0;
      if (dt < best[k]) best[k] = dt;
      hits[k] = 0;
      for (int t = 0; t < 64; t++) hits[k] += c.hits[t];
    }
  for (int k = 0; k < 2; k++) mrays[k] = n / best[k] * 1e-6;
}

/* Camera rays over a 512x512 view of the bounds, then one cosine bounce from each hit
 * (found with Embree or the kd-tree: the same rays are then given to both). */
static ray *make_rays(const scene *s, const accel *a, long *count, ray **shadow, long *nshadow) {
  int W = 512, H = 512;
  vec3 c = s->center, eye = v3_add(c, v3(0.3f * s->radius, 0.4f * s->radius, 2.4f * s->radius));
  if (s->has_camera) eye = s->cam.pos, c = s->cam.look_at;
  vec3 fwd = v3_norm(v3_sub(c, eye)), right = v3_norm(v3_cross(fwd, v3(0, 1, 0))), up = v3_cross(right, fwd);
  float th = tanf(0.5f * 40 * PI_F / 180);
  ray *r = malloc(sizeof(ray) * W * H * 2);
  ray *sh = malloc(sizeof(ray) * W * H);
  long n = 0, ns = 0;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      sampler sm = sampler_make(1, (uint64_t)(y * W + x), 0);
      float sx = (2 * (x + sampler_1d(&sm)) / W - 1) * th, sy = (1 - 2 * (y + sampler_1d(&sm)) / H) * th;
      ray cr = {eye, v3_norm(v3_add(fwd, v3_add(v3_scale(right, sx), v3_scale(up, sy)))), INFINITY};
      r[n++] = cr;
      hit h;
      if (!accel_intersect(a, &cr, &h)) continue;
      const uint32_t *ix = &s->idx[3 * h.tri];
      vec3 err, p = tri_point(s->pos[ix[0]], s->pos[ix[1]], s->pos[ix[2]], h.b1, h.b2, &err);
      vec3 ng = v3_norm(scene_tri_ng(s, h.tri));
      if (v3_dot(ng, cr.d) > 0) ng = v3_neg(ng);
      frame f = frame_from_n(ng);
      vec3 d = frame_to_world(&f, sample_cosine_hemisphere(sampler_1d(&sm), sampler_1d(&sm)));
      ray br = {offset_origin(p, err, ng, d), d, INFINITY};
      r[n++] = br;
      /* A shadow ray towards a point above the scene (like an area light). */
      vec3 lp = v3_add(s->center, v3((sampler_1d(&sm) - 0.5f) * s->radius, 1.2f * s->radius, (sampler_1d(&sm) - 0.5f) * s->radius));
      vec3 o = offset_origin(p, err, ng, v3_sub(lp, p));
      ray srr = {o, v3_sub(lp, o), 1 - 1e-4f};
      sh[ns++] = srr;
    }
  *count = n; *shadow = sh; *nshadow = ns;
  return r;
}

static int load(scene *s, const char *rel, const float *xf) {
  char buf[2048];
  valo_error err;
  if (load_mesh(s, shared(rel, buf, sizeof buf), xf, UINT32_MAX, 0, NULL, &err)) { fprintf(stderr, "skip %s: %s\n", rel, err.message); return -1; }
  return 0;
}

/* --classes: the closest-hit rays split into camera rays that miss, camera rays that hit
 * and bounce rays (which start on a surface, go anywhere and find cold caches), each
 * class timed on both backends, single-threaded, alternating. */
static void class_table(const char *name, accel *const acc[2], const ray *rays, long n) {
  ray *cls[3];
  long nc[3] = {0, 0, 0};
  for (int k = 0; k < 3; k++) cls[k] = malloc(sizeof(ray) * (size_t)n);
  if (!cls[0] || !cls[1] || !cls[2]) { for (int k = 0; k < 3; k++) free(cls[k]); return; }
  vec3 eye = rays[0].o; /* make_rays starts with a camera ray */
  for (long i = 0; i < n; i++) {
    hit h;
    int from_eye = rays[i].o.x == eye.x && rays[i].o.y == eye.y && rays[i].o.z == eye.z;
    int k = from_eye ? accel_intersect(acc[1], &rays[i], &h) : 2;
    cls[k][nc[k]++] = rays[i];
  }
  static const char *const names[3] = {"camera, miss", "camera, hit", "bounce"};
  for (int k = 0; k < 3; k++) {
    double m[2];
    long h[2];
    if (nc[k] == 0) { free(cls[k]); continue; }
    trace_pair(acc, cls[k], nc[k], 1, 0, m, h);
    printf("| %s | %s | %ld | %.2f | %.2f | %.2f |\n", name, names[k], nc[k], m[0], m[1], m[0] / m[1]);
    free(cls[k]);
  }
  fflush(stdout);
}
static int g_classes, g_bound;

/* --bound: what the kd-tree's node walk alone costs. Each query is traced once
 * (kdtree_trace); then, alternating, best of REPS, single-threaded: the real queries,
 * the same walks with no triangle tested (kdtree_walk: leaves cost nothing), and Embree.
 * walk/Embree is the kd/Embree speed this tree would reach if its leaves were free. */
static void bound_row(const char *name, const char *kind, accel *const acc[2], const ray *rays, long n, int any) {
  kd_trace *tr = malloc(sizeof *tr * (size_t)n);
  if (!tr) return;
  double sum[6] = {0, 0, 0, 0, 0, 0};
  long found = 0, wfound = 0, wnodes = 0, wleaves = 0;
  for (long i = 0; i < n; i++) {
    found += kdtree_trace(acc[0], &rays[i], any, &tr[i]);
    sum[0] += tr[i].nodes; sum[1] += tr[i].boxes; sum[2] += tr[i].leaves; sum[3] += tr[i].groups;
    sum[4] += tr[i].descent;
    sum[5] += tr[i].dup_groups;
  }

  for (long i = 0; i < n; i++) {
    kd_trace w = tr[i];
    wfound += kdtree_walk(acc[0], &rays[i], any, &w, 1);
    wnodes += w.nodes; wleaves += w.leaves;
  }
  if (wfound != found || wnodes != (long)sum[0])
    fprintf(stderr, "note: %s %s: the walk alone finds %ld (trace %ld) and visits %ld nodes (trace %.0f), %ld leaves (%.0f)\n", name, kind,
            wfound, found, wnodes, sum[0], wleaves, sum[2]);
  double best[4] = {1e30, 1e30, 1e30, 1e30};
  volatile long sink = 0;
  for (int rep = 0; rep < REPS; rep++)
    for (int k = 0; k < 4; k++) {
      long c = 0;
      double t0 = bench_now();
      for (long i = 0; i < n; i++) {
        hit h;
        if (k == 1 || k == 3) { c += kdtree_walk(acc[0], &rays[i], any, &tr[i], k == 1 ? 0 : -1); continue; }
        const accel *a = acc[k == 0 ? 0 : 1];
        c += any ? accel_occluded(a, &rays[i]) : accel_intersect(a, &rays[i], &h);
      }
      double dt = bench_now() - t0;
      sink += c;
      if (dt < best[k]) best[k] = dt;
    }
  (void)sink;
  double m[3];
  for (int k = 0; k < 3; k++) m[k] = n / best[k] * 1e-6;
  printf("| %s | %s | %ld | %.1f | %.1f | %.1f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f %% | %.0f %% | %.1f %% |\n", name, kind, n,
         sum[0] / n, sum[1] / n, sum[4] / n, sum[2] / n, sum[3] / n, m[0], m[1], m[2], m[0] / m[2], m[1] / m[2], best[2] / (best[0] - best[3]),
         100 * (1 - best[1] / best[0]), 100 * best[3] / best[0], 100 * sum[5] / (sum[3] > 0 ? sum[3] : 1));
  fflush(stdout);
  free(tr);
}

#ifdef VALO_HAVE_EMBREE
/* --packets: Embree's queries one at a time, in packets and in streams, on the same rays. */
enum { PK_ONE, PK_8, PK_16, PK_STREAM, PK_KINDS };
static long pk_trace(RTCScene scn, const ray *rays, long n, int kind, int shadow) {
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  long hits = 0;
  if (kind == PK_ONE) {
    for (long i = 0; i < n; i++) {
      struct RTCRayHit rh;
      memset(&rh, 0, sizeof rh);
      rh.ray.org_x = rays[i].o.x; rh.ray.org_y = rays[i].o.y; rh.ray.org_z = rays[i].o.z;
      rh.ray.dir_x = rays[i].d.x; rh.ray.dir_y = rays[i].d.y; rh.ray.dir_z = rays[i].d.z;
      rh.ray.tfar = rays[i].tmax; rh.ray.mask = 0xFFFFFFFF; rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      if (shadow) { rtcOccluded1(scn, &ctx, &rh.ray); hits += rh.ray.tfar < 0; }
      else { rtcIntersect1(scn, &ctx, &rh); hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID; }
    }
    return hits;
  }
  if (kind == PK_STREAM) {
    enum { M = 256 };
    static struct RTCRayHit rh[M];
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    for (long i0 = 0; i0 < n; i0 += M) {
      int m = (int)(n - i0 < M ? n - i0 : M);
      for (int j = 0; j < m; j++) {
        const ray *r = &rays[i0 + j];
        memset(&rh[j], 0, sizeof rh[j]);
        rh[j].ray.org_x = r->o.x; rh[j].ray.org_y = r->o.y; rh[j].ray.org_z = r->o.z;
        rh[j].ray.dir_x = r->d.x; rh[j].ray.dir_y = r->d.y; rh[j].ray.dir_z = r->d.z;
        rh[j].ray.tfar = r->tmax; rh[j].ray.mask = 0xFFFFFFFF; rh[j].hit.geomID = RTC_INVALID_GEOMETRY_ID;
      }
      if (shadow) { rtcOccluded1M(scn, &ctx, &rh[0].ray, (unsigned)m, sizeof rh[0]); for (int j = 0; j < m; j++) hits += rh[j].ray.tfar < 0; }
      else { rtcIntersect1M(scn, &ctx, rh, (unsigned)m, sizeof rh[0]); for (int j = 0; j < m; j++) hits += rh[j].hit.geomID != RTC_INVALID_GEOMETRY_ID; }
    }
    return hits;
  }
  int w = kind == PK_8 ? 8 : 16;
  for (long i0 = 0; i0 < n; i0 += w) {
    RTC_ALIGN(64) struct RTCRayHit16 p;
    RTC_ALIGN(64) int valid[16];
    memset(&p, 0, sizeof p);
    for (int j = 0; j < w; j++) {
      valid[j] = i0 + j < n ? -1 : 0;
      const ray *r = &rays[i0 + j < n ? i0 + j : n - 1];
      p.ray.org_x[j] = r->o.x; p.ray.org_y[j] = r->o.y; p.ray.org_z[j] = r->o.z;
      p.ray.dir_x[j] = r->d.x; p.ray.dir_y[j] = r->d.y; p.ray.dir_z[j] = r->d.z;
      p.ray.tfar[j] = r->tmax; p.ray.mask[j] = 0xFFFFFFFF; p.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;
    }
    /* RTCRayHit8 is RTCRayHit16's layout with 8 lanes: repack for the 8-wide query. */
    if (w == 8) {
      RTC_ALIGN(32) struct RTCRayHit8 q;
      memset(&q, 0, sizeof q);
      for (int j = 0; j < 8; j++) {
        q.ray.org_x[j] = p.ray.org_x[j]; q.ray.org_y[j] = p.ray.org_y[j]; q.ray.org_z[j] = p.ray.org_z[j];
        q.ray.dir_x[j] = p.ray.dir_x[j]; q.ray.dir_y[j] = p.ray.dir_y[j]; q.ray.dir_z[j] = p.ray.dir_z[j];
        q.ray.tfar[j] = p.ray.tfar[j]; q.ray.mask[j] = 0xFFFFFFFF; q.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;
      }
      if (shadow) rtcOccluded8(valid, scn, &ctx, &q.ray); else rtcIntersect8(valid, scn, &ctx, &q);
      for (int j = 0; j < 8; j++) if (valid[j]) hits += shadow ? q.ray.tfar[j] < 0 : q.hit.geomID[j] != RTC_INVALID_GEOMETRY_ID;
    } else {
      if (shadow) rtcOccluded16(valid, scn, &ctx, &p.ray); else rtcIntersect16(valid, scn, &ctx, &p);
      for (int j = 0; j < 16; j++) if (valid[j]) hits += shadow ? p.ray.tfar[j] < 0 : p.hit.geomID[j] != RTC_INVALID_GEOMETRY_ID;
    }
  }
  return hits;
}
static void packet_rows(const char *name, const scene *s, const ray *rays, long n, const ray *sh, long ns) {
  RTCDevice dev = rtcNewDevice(NULL);
  RTCScene scn = rtcNewScene(dev);
  rtcSetSceneFlags(scn, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, s->pos, 0, sizeof(vec3), s->nverts);
  rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, s->idx, 0, 3 * sizeof(uint32_t), s->ntris);
  rtcCommitGeometry(g);
  rtcAttachGeometry(scn, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scn);
  /* camera rays (make_rays starts with one and gives each its bounce after it) and bounces */
  ray *cls[3] = {malloc(sizeof(ray) * (size_t)n), malloc(sizeof(ray) * (size_t)n), (ray *)sh};
  long nc[3] = {0, 0, ns};
  vec3 eye = rays[0].o;
  for (long i = 0; i < n; i++) {
    int k = rays[i].o.x == eye.x && rays[i].o.y == eye.y && rays[i].o.z == eye.z ? 0 : 1;
    cls[k][nc[k]++] = rays[i];
  }
  static const char *const names[3] = {"camera", "bounce", "shadow"};
  for (int c = 0; c < 3; c++) {
    double best[PK_KINDS];
    long hits[PK_KINDS];
    for (int k = 0; k < PK_KINDS; k++) best[k] = 1e30;
    for (int rep = 0; rep < REPS; rep++)
      for (int k = 0; k < PK_KINDS; k++) {
        double t0 = bench_now();
        hits[k] = pk_trace(scn, cls[c], nc[c], k, c == 2);
        double dt = bench_now() - t0;
        if (dt < best[k]) best[k] = dt;
      }
    for (int k = 1; k < PK_KINDS; k++)
      if (hits[k] != hits[0]) fprintf(stderr, "note: %s %s: %ld hits one at a time, %ld by kind %d\n", name, names[c], hits[0], hits[k], k);
    printf("| %s | %s | %ld | %.2f | %.2f | %.2f | %.2f |\n", name, names[c], nc[c], nc[c] / best[PK_ONE] * 1e-6, best[PK_ONE] / best[PK_8],
           best[PK_ONE] / best[PK_16], best[PK_ONE] / best[PK_STREAM]);
    fflush(stdout);
  }
  free(cls[0]); free(cls[1]);
  rtcReleaseScene(scn);
  rtcReleaseDevice(dev);
}
#endif
static int g_packets;

static void bench_scene(const char *name, scene *s) {
  valo_error err;
  if (scene_commit(s, &err)) { fprintf(stderr, "%s: %s\n", name, err.message); return; }
  accel *acc[2] = {NULL, NULL};
  double build[2] = {1e30, 1e30};
  const char *kinds[2] = {"kdtree", "embree"};
  /* Builds on 2 threads, alternating, best of three each (Embree's first build also
   * starts its thread pool). */
  for (int rep = 0; rep < 3; rep++)
    for (int k = 0; k < 2; k++) {
      accel_destroy(acc[k]);
      double t0 = bench_now();
      if (accel_create(kinds[k], s->pos, s->cap_verts, s->idx, s->ntris, 2, NULL, &acc[k], &err)) { fprintf(stderr, "%s\n", err.message); acc[k] = NULL; }
      double dt = bench_now() - t0;
      build[k] = dt < build[k] ? dt : build[k];
    }
  if (!acc[0] || !acc[1]) { accel_destroy(acc[0]); accel_destroy(acc[1]); return; }
  long n, ns;
  ray *sh;
  ray *rays = make_rays(s, acc[1], &n, &sh, &ns);
  if (g_packets) {
#ifdef VALO_HAVE_EMBREE
    packet_rows(name, s, rays, n, sh, ns);
#endif
    free(rays); free(sh);
    accel_destroy(acc[0]); accel_destroy(acc[1]);
    return;
  }
  if (g_classes || g_bound) {
    if (g_classes) class_table(name, acc, rays, n);
    else { bound_row(name, "closest hit", acc, rays, n, 0); bound_row(name, "shadow", acc, sh, ns, 1); }
    free(rays); free(sh);
    accel_destroy(acc[0]); accel_destroy(acc[1]);
    return;
  }
  double mr[2][2], ms[2][2]; /* [backend][threads - 1] */
  long hits[2][2], shits[2][2];
  (void)shits;
  for (int t = 0; t < 2; t++) {
    double m[2], m2[2];
    long h[2], h2[2];
    trace_pair(acc, rays, n, t + 1, 0, m, h);
    trace_pair(acc, sh, ns, t + 1, 1, m2, h2);
    for (int k = 0; k < 2; k++) { mr[k][t] = m[k]; ms[k][t] = m2[k]; hits[k][t] = h[k]; shits[k][t] = h2[k]; }
  }
  if (hits[0][0] != hits[1][0]) fprintf(stderr, "note: %s: hit counts differ (kd %ld, embree %ld)\n", name, hits[0][0], hits[1][0]);
  printf("| %s | %u | %.3f | %.3f | %.1f | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f |\n", name,
         s->ntris, build[0], build[1], build[0] / build[1], mr[0][0], mr[0][1], mr[1][0], mr[1][1], mr[0][0] / mr[1][0], mr[0][1] / mr[1][1], ms[0][0],
         ms[0][1], ms[1][0], ms[1][1], ms[0][0] / ms[1][0], ms[0][1] / ms[1][1]);
  fflush(stdout);
  free(rays); free(sh);
  accel_destroy(acc[0]); accel_destroy(acc[1]);
}

int main(int argc, char **argv) {
  int quick = 0, build_table = 1;
  const char *only = NULL;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick")) quick = 1;
    else if (!strcmp(argv[i], "--no-build-table")) build_table = 0;
    else if (!strcmp(argv[i], "--classes")) g_classes = 1, build_table = 0;
    else if (!strcmp(argv[i], "--bound")) g_bound = 1, build_table = 0;
    else if (!strcmp(argv[i], "--packets")) g_packets = 1, build_table = 0;
    else if (!strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
    else { fprintf(stderr, "usage: bench_raykernel [--quick] [--only bunny|nefertiti|dragon|sponza|cornell] [--no-build-table] [--classes] [--bound] [--packets]\n"); return 2; }
  }
  if (g_packets) {
    if (!embree_available()) { fprintf(stderr, "bench_raykernel --packets: this valo was built without Embree\n"); return 2; }
    printf("## Embree's queries one at a time against packets and streams, 1 thread (same rays)\n\n");
    printf("| scene | rays | count | rtcIntersect1 / rtcOccluded1 Mrays/s | packets of 8 / one at a time | packets of 16 / one at a time "
           "| streams of 256 / one at a time |\n|---|---|---|---|---|---|---|\n");
  } else
  if (g_bound) {
    printf("## The kd-tree's node walk alone, 1 thread (kd-tree vs Embree %s)\n\n", embree_available() ? "3" : "(absent)");
    printf("| scene | rays | count | nodes per ray | box nodes per ray | descent nodes per ray | leaves per ray | groups of 4 per ray | kd Mrays/s "
           "| walk alone Mrays/s | Embree Mrays/s | kd/Embree | walk alone/Embree | kd without its descent/Embree | leaves' share of kd time "
           "| descent's share | groups tested again |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  } else if (g_classes) {
    printf("## Closest-hit rays by class, 1 thread (kd-tree vs Embree %s)\n\n", embree_available() ? "3" : "(absent)");
    printf("| scene | rays | count | kd Mrays/s | Embree Mrays/s | kd/Embree |\n|---|---|---|---|---|---|\n");
  } else {
  printf("## Ray kernel: kd-tree vs Embree %s (same rays; camera + 1 cosine bounce; 512x512)\n\n", embree_available() ? "3" : "(absent)");
  printf("| scene | triangles | kd build s | Embree build s | kd/Embree build time | kd Mrays/s 1t / 2t | Embree Mrays/s 1t / 2t | kd/Embree 1t / 2t "
         "| kd shadow Mrays/s 1t / 2t | Embree shadow 1t / 2t | kd/Embree shadow 1t / 2t |\n");
  printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  }
  const char *meshes[4][2] = {{"bunny", "scenes/models/stanford-bunny.obj"}, {"nefertiti", "scenes/models/nefertiti.obj"},
                              {"dragon", "scenes/dragon/dragon_vrip.ply"}, {NULL, NULL}};
  for (int i = 0; meshes[i][0]; i++) {
    if ((quick && i == 2) || (only && strcmp(only, meshes[i][0]))) continue;
    scene *s = scene_new(meshes[i][1]);
    if (load(s, meshes[i][1], NULL) == 0) bench_scene(meshes[i][0], s);
    scene_free(s);
  }
  if (!only || !strcmp(only, "sponza")) {
    scene *s = scene_new("sponza");
    if (load(s, "scenes/sponza/sponza.obj", NULL) == 0) {
      /* The camera of the shared reference (mitsuba-source/scene.xml), in the atrium. */
      s->cam.pos = v3(2.25067f, 8.24132f, -0.0492483f); s->cam.look_at = v3(3.15037f, 7.8048f, -0.0501832f); s->has_camera = 1;
      bench_scene("sponza", s);
    }
    scene_free(s);
  }
  if (!only || !strcmp(only, "cornell")) {
    scene *s = scene_new("cornell+bunny");
    /* The bunny (about 0.15 units tall, base at y=0.033) scaled into the box. */
    float xf[12] = {4, 0, 0, 0.1f, 0, 4, 0, -0.13f, 0, 0, 4, 0.2f};
    if (load(s, "scenes/cornell/CornellBox-Original.obj", NULL) == 0 && load(s, "scenes/models/stanford-bunny.obj", xf) == 0) {
      s->cam.pos = v3(0, 1, 3.4f); s->cam.look_at = v3(0, 1, 0); s->has_camera = 1;
      bench_scene("cornell + bunny", s);
    }
    scene_free(s);
  }
  if (!build_table) return 0;
  printf("\n## kd-tree build growth on the dragon (N log N)\n\n");
  printf("| triangles | build s | ns per N log2 N | nodes | refs per triangle | kd bytes per triangle | build peak bytes per triangle |\n|---|---|---|---|---|---|---|\n");
  const char *res[4] = {"scenes/dragon/dragon_vrip_res4.ply", "scenes/dragon/dragon_vrip_res3.ply", "scenes/dragon/dragon_vrip_res2.ply",
                        "scenes/dragon/dragon_vrip.ply"};
  for (int i = 0; i < (quick ? 3 : 4); i++) {
    scene *s = scene_new(res[i]);
    valo_error err;
    if (load(s, res[i], NULL) == 0 && scene_commit(s, &err) == 0) {
      accel *a;
      reset_peak_rss();
      long rss0 = status_kb("VmRSS:");
      double t0 = bench_now();
      if (kdtree_create(s->pos, s->idx, s->ntris, 2, NULL, &a, &err) == 0) {
        double dt = bench_now() - t0;
        kd_stats st;
        kdtree_stats(a, &st);
        double nlogn = s->ntris * log2((double)s->ntris);
        long peak = status_kb("VmHWM:") - rss0;
        printf("| %u | %.3f | %.1f | %u | %.2f | %.1f | %.0f |\n", s->ntris, dt, dt / nlogn * 1e9, st.nodes, (double)st.refs / s->ntris,
               (double)st.bytes / s->ntris, peak * 1024.0 / s->ntris);
        fflush(stdout);
        accel_destroy(a);
      }
    }
    scene_free(s);
  }
  return 0;
}
