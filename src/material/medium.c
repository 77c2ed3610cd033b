/* medium.c — see medium.h: the grid media's tracking. */
#include "material/medium.h"
#include "core/rng.h"
#include "scene/volume.h"

/* Tracking steps before a walk is taken to be lost (weight 0): a majorant of this many
 * collisions per ray is far beyond any medium a path tracer renders. */
#define TRACK_STEPS_MAX 100000

/* The part [*t0, *t1] of [0, len] inside the grid's box, on the ray o + t d; 0 if none. */
static int box_span(const density_grid *g, vec3 o, vec3 d, float len, float *t0, float *t1) {
  float lo = 0, hi = len, ov[3] = {o.x, o.y, o.z}, dv[3] = {d.x, d.y, d.z};
  float bl[3] = {g->box.lo.x, g->box.lo.y, g->box.lo.z}, bh[3] = {g->box.hi.x, g->box.hi.y, g->box.hi.z};
  for (int k = 0; k < 3; k++) {
    float inv = 1 / dv[k], a = (bl[k] - ov[k]) * inv, b = (bh[k] - ov[k]) * inv;
    if (a > b) { float x = a; a = b; b = x; }
    if (a == a) lo = a > lo ? a : lo; /* NaN: the ray lies in the slab's face plane */
    if (b == b) hi = b < hi ? b : hi;
  }
  *t0 = lo;
  *t1 = hi;
  return lo < hi;
}

static inline float hashed_u(uint64_t key, uint32_t k) { return rng_to_float((uint32_t)(rng_mix64(key + (uint64_t)k * 0x9e3779b97f4a7c15ULL) >> 32)); }
static float majorant(const medium *m) { return m->grid->dmax * c3_max(medium_sigma_t(m)); }

int medium_sample(const medium *m, vec3 o, vec3 d, float tmax, float uc, float ud, uint64_t key, float *t, rgb *weight, rgb *emit) {
  *emit = c3(0, 0, 0);
  if (!m->grid) {
    rgb trp;
    int ev = medium_sample_distance(m, uc, ud, tmax, t, weight, &trp);
    if (ev) *emit = c3_mul(m->sigma_a, trp);
    return ev;
  }
  rgb w = c3(1, 1, 1), st0 = medium_sigma_t(m);
  float mu = majorant(m), t0, t1;
  *weight = w;
  if (!(mu > 0) || !box_span(m->grid, o, d, tmax, &t0, &t1)) return 0;
  float x = t0;
  for (uint32_t k = 0; k < TRACK_STEPS_MAX; k++) {
    x -= logf(1 - hashed_u(key, 2 * k)) / mu;
    if (x >= t1) { *weight = w; return 0; }
    float dens = density_grid_at(m->grid, v3_add(o, v3_scale(d, x)));
    rgb ss = c3_scale(m->sigma_s, dens), st = c3_scale(st0, dens);
    *emit = c3_add(*emit, c3_mul(w, c3_scale(m->sigma_a, dens / mu)));
    rgb sn = c3(fmaxf(mu - st.r, 0), fmaxf(mu - st.g, 0), fmaxf(mu - st.b, 0));
    float ps = c3_avg(c3_mul(ss, w)), pn = c3_avg(c3_mul(sn, w));
    if (!(ps + pn > 0)) { *weight = c3(0, 0, 0); *t = x; return 1; } /* absorbed for certain */
    ps /= ps + pn;
    if (hashed_u(key, 2 * k + 1) < ps) {
      *weight = c3_mul(w, c3_scale(ss, 1 / (mu * ps)));
      *t = x;
      return 1;
    }
    w = c3_mul(w, c3_scale(sn, 1 / (mu * (1 - ps))));
  }
  *weight = c3(0, 0, 0);
  *t = x;
  return 1;
}

rgb medium_transmittance(const medium *m, vec3 o, vec3 d, float len, uint64_t key) {
  if (!m->grid) return medium_tr(m, len);
  rgb tr = c3(1, 1, 1), st0 = medium_sigma_t(m);
  float mu = majorant(m), t0, t1;
  if (!(mu > 0) || !box_span(m->grid, o, d, len, &t0, &t1)) return tr;
  float x = t0;
  for (uint32_t k = 0; k < TRACK_STEPS_MAX; k++) {
    x -= logf(1 - hashed_u(key, k)) / mu;
    if (x >= t1) return tr;
    float dens = density_grid_at(m->grid, v3_add(o, v3_scale(d, x)));
    rgb st = c3_scale(st0, dens);
    tr = c3_mul(tr, c3(fmaxf(1 - st.r / mu, 0), fmaxf(1 - st.g / mu, 0), fmaxf(1 - st.b / mu, 0)));
    if (c3_black(tr)) return tr;
  }
  return c3(0, 0, 0);
}
