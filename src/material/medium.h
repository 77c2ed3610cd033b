/* medium.h — owns what a participating medium does to a ray: the Henyey-Greenstein phase
 * function (value and sampling); in a homogeneous medium free-flight distance sampling
 * with single-sample MIS over the RGB channels (pbrt-v3's HomogeneousMedium::Sample) and
 * transmittance (Beer-Lambert); in a grid medium (medium.c) spectral tracking (Kutz et
 * al. 2017: delta tracking against one majorant, null and real collisions chosen in
 * proportion to their throughput-weighted coefficients) and ratio tracking. Directions
 * follow pbrt: wo points back along the path, so forward scattering (g > 0) sends wi
 * close to -wo. */
#ifndef VALO_MEDIUM_H
#define VALO_MEDIUM_H
#include "core/sampling.h"
#include "scene/scene.h"
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

static inline rgb medium_sigma_t(const medium *m) { return c3_add(m->sigma_a, m->sigma_s); }
/* Transmittance over distance d (d may be infinite: channels with sigma_t 0 keep 1). */
static inline rgb medium_tr(const medium *m, float d) {
  rgb st = medium_sigma_t(m);
  return c3(st.r > 0 ? expf(-st.r * d) : 1, st.g > 0 ? expf(-st.g * d) : 1, st.b > 0 ? expf(-st.b * d) : 1);
}
/* Samples a free-flight distance along a ray that meets a surface at distance tmax
 * (INFINITY: none): a channel picked by uc, the distance from that channel's
 * exponential by ud. Returns 1 with *t < tmax and the weight sigma_s Tr(t) / pdf(t) for
 * a scattering event, or 0 with the weight Tr(tmax) / P(no event) for reaching the
 * surface; pdf and P average the three channels' densities (the balance heuristic), so
 * the weights are unbiased for every channel. A weight of 0 ends the path. *tr_pdf is
 * Tr / pdf (of the event or of passing), what the event's emission is weighted by. */
static inline int medium_sample_distance(const medium *m, float uc, float ud, float tmax, float *t, rgb *weight, rgb *tr_pdf) {
  rgb st = medium_sigma_t(m);
  int ch = (int)(uc * 3);
  float s = ch <= 0 ? st.r : ch == 1 ? st.g : st.b;
  float d = s > 0 ? -logf(1 - ud) / s : INFINITY;
  if (d < tmax) {
    rgb tr = medium_tr(m, d);
    float pdf = (st.r * tr.r + st.g * tr.g + st.b * tr.b) / 3;
    *t = d;
    *tr_pdf = pdf > 0 ? c3_scale(tr, 1 / pdf) : c3(0, 0, 0);
    *weight = c3_mul(m->sigma_s, *tr_pdf);
    return 1;
  }
  rgb tr = medium_tr(m, tmax);
  float p = (tr.r + tr.g + tr.b) / 3;
  *weight = *tr_pdf = p > 0 ? c3_scale(tr, 1 / p) : c3(0, 0, 0);
  return 0;
}

/* Where a ray from o along unit d in medium m first scatters before the surface at
 * tmax (INFINITY: none), as medium_sample_distance: homogeneous media from (uc, ud),
 * grid media by spectral tracking inside the grid's box with random numbers hashed
 * from key (their count varies). *emit: the weight of the medium's emission Le collected
 * on the way (the estimate of the integral of Tr sigma_a over the segment walked): at
 * a homogeneous medium's event sigma_a Tr / pdf, in a grid sigma_a / majorant times the
 * tracking weight at every tentative collision. */
int medium_sample(const medium *m, vec3 o, vec3 d, float tmax, float uc, float ud, uint64_t key, float *t, rgb *weight, rgb *emit);
/* Transmittance from o along unit d over length len (INFINITY: for ever): exact in a
 * homogeneous medium, by ratio tracking (random numbers from key) in a grid. */
rgb medium_transmittance(const medium *m, vec3 o, vec3 d, float len, uint64_t key);
#endif
