/* medium.h — owns what a participating medium does to a ray: the Henyey-Greenstein phase
 * function (value and sampling); in a homogeneous medium free-flight distance sampling
 * with single-sample MIS over the path's channels, RGB or four wavelengths (pbrt-v3's
 * HomogeneousMedium::Sample) and
 * transmittance (Beer-Lambert); in a grid medium (medium.c) spectral tracking (Kutz et
 * al. 2017: delta tracking against one majorant, null and real collisions chosen in
 * proportion to their throughput-weighted coefficients) and ratio tracking. Directions
 * follow pbrt: wo points back along the path, so forward scattering (g > 0) sends wi
 * close to -wo. */
#ifndef VALO_MEDIUM_H
#define VALO_MEDIUM_H
#include "core/sampling.h"
#include "scene/scene.h"
#include "core/spectrum.h"
#include <math.h>

/* The HG phase function of cos theta = dot(wo, wi); integrates to 1 over the sphere. */
static inline float phase_hg(float cos_theta, float g) {
  float denom = 1 + g * g + 2 * g * cos_theta;
  return (1 - g * g) / (4 * PI_F * denom * sqrtf(fmaxf(denom, 1e-12f)));
}
/* Samples wi from phase_hg(dot(wo, wi), g) for (u1, u2) in [0, 1)^2; returns its pdf
 * (= the phase value, so the sample's weight is 1). */
static inline float phase_hg_sample(vec3 wo, float g, float u1, float u2, vec3 *wi) {
  float cos_theta;
  if (fabsf(g) < 1e-3f) cos_theta = 1 - 2 * u1;
  else {
    float q = (1 - g * g) / (1 + g - 2 * g * u1);
    cos_theta = -(1 + g * g - q * q) / (2 * g);
  }
  cos_theta = fminf(fmaxf(cos_theta, -1), 1);
  float sin_theta = sqrtf(fmaxf(0, 1 - cos_theta * cos_theta)), phi = 2 * PI_F * u2;
  frame f = frame_from_n(wo);
  *wi = v3_norm(frame_to_world(&f, v3(sin_theta * cosf(phi), sin_theta * sinf(phi), cos_theta)));
  return phase_hg(cos_theta, g);
}

/* A medium's coefficients on a path's channels: the three RGB channels (n = 3, lane 3
 * unused and 0), or with --spectral the path's four wavelengths (n = 4, the RGB values
 * upsampled: medium_coef). Colours on the channels are spec4. */
typedef struct mcoef { float a[N_LAMBDA], s[N_LAMBDA], le[N_LAMBDA]; int n; } mcoef;
/* m's coefficients for a path at wavelengths wl, or in RGB (wl NULL). */
mcoef medium_coef(const medium *m, const wavelengths *wl);
/* A colour on the channels: RGB into lanes 0-2, or upsampled at wl. */
static inline spec4 chan_from_rgb(rgb c, const wavelengths *wl) {
  if (wl) return spec_from_rgb(c, wl);
  spec4 v = {{c.r, c.g, c.b, 0}};
  return v;
}
/* 1 on the first n lanes, 0 beyond. */
static inline spec4 lanes_one(int n) {
  spec4 v = spec_const(0);
  for (int k = 0; k < n; k++) v.v[k] = 1;
  return v;
}
/* 1 on every channel of the path (lane 3 is 0 in RGB). */
static inline spec4 chan_one(const wavelengths *wl) { return lanes_one(wl ? N_LAMBDA : 3); }
/* Transmittance over distance d (d may be infinite: channels with sigma_t 0 keep 1). */
static inline spec4 medium_tr(const mcoef *c, float d) {
  spec4 tr = spec_const(0);
  for (int k = 0; k < c->n; k++) {
    float st = c->a[k] + c->s[k];
    tr.v[k] = st > 0 ? expf(-st * d) : 1;
  }
  return tr;
}
/* Samples a free-flight distance along a ray that meets a surface at distance tmax
 * (INFINITY: none): a channel picked by uc, the distance from that channel's
 * exponential by ud, the channel k with probability P_k in proportion to sel_k, the path's
 * throughput (NULL: uniform), so that the channels the path still carries choose its
 * distances (Kutz et al. 2017; uniform choice gives dense channels heavy-tailed weights).
 * Returns 1 with *t < tmax and the weight sigma_s Tr(t) / pdf(t) for a scattering event,
 * or 0 with the weight Tr(tmax) / P(no event) for reaching the surface; pdf and P are the
 * mixture sum_k P_k (density of channel k) (one-sample MIS), so the weights are
 * unbiased for every channel. A weight of 0 ends the path. *tr_pdf is Tr / pdf (of the
 * event or of passing), what the event's emission is weighted by. */
static inline int medium_sample_distance(const mcoef *c, const spec4 *sel, float uc, float ud, float tmax, float *t, spec4 *weight,
                                         spec4 *tr_pdf) {
  float P[N_LAMBDA], sum = 0;
  for (int k = 0; k < c->n; k++) sum += (P[k] = sel ? fmaxf(sel->v[k], 0) : 1);
  if (!(sum > 0) || !isfinite(sum)) { sum = (float)c->n; for (int k = 0; k < c->n; k++) P[k] = 1; }
  int ch = c->n - 1;
  float acc = 0;
  for (int k = 0; k < c->n - 1; k++) {
    acc += P[k] / sum;
    if (uc < acc) { ch = k; break; }
  }
  float s = c->a[ch] + c->s[ch];
  float d = s > 0 ? -logf(1 - ud) / s : INFINITY;
  int event = d < tmax;
  spec4 tr = medium_tr(c, event ? d : tmax);
  float p = 0;
  for (int k = 0; k < c->n; k++) p += P[k] / sum * (event ? c->a[k] + c->s[k] : 1) * tr.v[k];
  *tr_pdf = p > 0 ? spec_scale(tr, 1 / p) : spec_const(0);
  *weight = *tr_pdf;
  if (!event) return 0;
  *t = d;
  for (int k = 0; k < c->n; k++) weight->v[k] *= c->s[k];
  return 1;
}

/* Where a ray from o along unit d in medium m (coefficients c) first scatters before
 * the surface at tmax (INFINITY: none), as medium_sample_distance: homogeneous media from
 * (uc, ud), grid media by spectral tracking inside the grid's box with random numbers
 * hashed from key (their count varies); sel, the path's throughput, weights the choice
 * of channel or of collision (NULL: not). *emit: the weight of the medium's emission Le
 * collected on the way (the estimate of the integral of Tr sigma_a over the segment
 * walked): at a homogeneous medium's event sigma_a Tr / pdf, in a grid sigma_a /
 * majorant times the tracking weight at every tentative collision. */
int medium_sample(const medium *m, const mcoef *c, const spec4 *sel, vec3 o, vec3 d, float tmax, float uc, float ud, uint64_t key, float *t,
                  spec4 *weight, spec4 *emit);
/* Transmittance from o along unit d over length len (INFINITY: for ever): exact in a
 * homogeneous medium, by ratio tracking (random numbers from key) in a grid. */
spec4 medium_transmittance(const medium *m, const mcoef *c, vec3 o, vec3 d, float len, uint64_t key);
#endif
