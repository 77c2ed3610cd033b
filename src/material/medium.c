/* medium.c — see medium.h: a medium's coefficients on a path's channels, and the grid
 * media's tracking. */
#include "material/medium.h"
#include "core/rng.h"
#include "scene/volume.h"

/* Tracking steps before a walk is taken to be lost (weight 0): a majorant of this many
 * collisions per ray is far beyond any medium a path tracer renders. */
#define TRACK_STEPS_MAX 100000

mcoef medium_coef(const medium *m, const wavelengths *wl) {
  mcoef c;
  spec4 a = chan_from_rgb(m->sigma_a, wl), s = chan_from_rgb(m->sigma_s, wl), le = chan_from_rgb(m->Le, wl);
  c.n = wl ? N_LAMBDA : 3;
  for (int k = 0; k < N_LAMBDA; k++) { c.a[k] = a.v[k]; c.s[k] = s.v[k]; c.le[k] = le.v[k]; }
  return c;
}

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
/* max density x the largest sigma_t over the channels */
static float majorant(const medium *m, const mcoef *c) {
  float mx = 0;
  for (int k = 0; k < c->n; k++) mx = fmaxf(mx, c->a[k] + c->s[k]);
  return m->grid->dmax * mx;
}

int medium_sample(const medium *m, const mcoef *c, const spec4 *sel, vec3 o, vec3 d, float tmax, float uc, float ud, uint64_t key, float *t,
                  spec4 *weight, spec4 *emit) {
  *emit = spec_const(0);
  if (!m->grid) {
    spec4 trp;
    int ev = medium_sample_distance(c, sel, uc, ud, tmax, t, weight, &trp);
    if (ev)
      for (int k = 0; k < c->n; k++) emit->v[k] = c->a[k] * trp.v[k];
    return ev;
  }
  spec4 w = lanes_one(c->n);
  float mu = majorant(m, c), t0, t1;
  *weight = w;
  if (!(mu > 0) || !box_span(m->grid, o, d, tmax, &t0, &t1)) return 0;
  float x = t0;
  for (uint32_t step = 0; step < TRACK_STEPS_MAX; step++) {
    x -= logf(1 - hashed_u(key, 2 * step)) / mu;
    if (x >= t1) { *weight = w; return 0; }
    float dens = density_grid_at(m->grid, v3_add(o, v3_scale(d, x)));
    float ps = 0, pn = 0;
    spec4 ss, sn;
    for (int k = 0; k < N_LAMBDA; k++) {
      ss.v[k] = c->s[k] * dens;
      sn.v[k] = fmaxf(mu - (c->a[k] + c->s[k]) * dens, 0);
      emit->v[k] += w.v[k] * c->a[k] * dens / mu;
      float b = sel && isfinite(sel->v[k]) ? fmaxf(sel->v[k], 0) : 1;
      ps += ss.v[k] * w.v[k] * b;
      pn += sn.v[k] * w.v[k] * b;
    }
    if (!(ps + pn > 0)) { *weight = spec_const(0); *t = x; return 1; } /* absorbed for certain */
    ps /= ps + pn;
    if (hashed_u(key, 2 * step + 1) < ps) {
      *weight = spec_mul(w, spec_scale(ss, 1 / (mu * ps)));
      *t = x;
      return 1;
    }
    w = spec_mul(w, spec_scale(sn, 1 / (mu * (1 - ps))));
  }
  *weight = spec_const(0);
  *t = x;
  return 1;
}

spec4 medium_transmittance(const medium *m, const mcoef *c, vec3 o, vec3 d, float len, uint64_t key) {
  if (!m->grid) return medium_tr(c, len);
  spec4 tr = lanes_one(c->n);
  float mu = majorant(m, c), t0, t1;
  if (!(mu > 0) || !box_span(m->grid, o, d, len, &t0, &t1)) return tr;
  float x = t0;
  for (uint32_t step = 0; step < TRACK_STEPS_MAX; step++) {
    x -= logf(1 - hashed_u(key, step)) / mu;
    if (x >= t1) return tr;
    float dens = density_grid_at(m->grid, v3_add(o, v3_scale(d, x)));
    for (int k = 0; k < c->n; k++) tr.v[k] *= fmaxf(1 - (c->a[k] + c->s[k]) * dens / mu, 0);
    if (spec_black(tr)) return tr;
  }
  return spec_const(0);
}
