/* restir.h — owns the reservoir types and the pieces of restir-di and restir-gi that tests check on
 * their own: candidate generation by RIS, the DI target, the GI Jacobian and the
 * similarity test (digest 001). */
#ifndef VALO_RESTIR_H
#define VALO_RESTIR_H
#include "integrator/integrator.h"

/* A DI sample: light index and a point on it (area: on the triangle; environment: a
 * direction; delta lights: unused). */
typedef struct di_sample { uint32_t light; vec3 y; } di_sample;
/* Reservoir: the kept sample, the sum of resampling weights (of the candidates; merges
 * keep only W), the candidate count M and the contribution weight W (an estimate of
 * 1 / pdf(y)); p, p^(y) at the reservoir's own pixel (restir_di_target there, 0 when
 * none), and f, the unshadowed contribution it found (black when p is 0): merges read
 * them as the input's own target and shading as the pixel's, instead of evaluating the
 * light again. */
typedef struct di_res { di_sample y; float w_sum, M, W, p; rgb f; } di_res;
/* A GI sample: the sample point x_s, its normal n_s (facing the pixel that found it) and
 * the radiance L^ it sends towards that pixel. */
typedef struct gi_res { vec3 xs, ns; rgb Lo; float w_sum, M, W; } gi_res;

/* Streaming weighted reservoir sampling, one candidate of weight w: adds w to *w_sum and
 * returns 1 (keep the candidate) when u * w_sum < w, i.e. with probability w / w_sum; a
 * candidate of weight 0 (or not finite) is never kept and adds nothing. */
int restir_wrs_take(float *w_sum, float w, float u);

typedef struct restir_cfg {
  int candidates, temporal, spatial, iterations, unbiased, jacobian;
  int reservoirs; /* per pixel (restir-di), the candidates split among them */
  float history, radius, normal_threshold, depth_threshold;
} restir_cfg;

/* RIS at a surface point: M candidates from the power-proportional light selection and
 * light sampling (stream smp, child j of M for candidate j), kept by streaming weighted
 * reservoir sampling (uniform numbers from rng), target p^ = luminance of the unshadowed
 * f Le |cos| g. Fills *r (W = w_sum / (M p^(y)), no visibility; p and f by
 * restir_di_target) and, when a sample was kept, *kept (if not NULL) with its light
 * evaluation (for the shadow ray); returns 1 when a sample was kept. */
int restir_di_candidates(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, int M, const sampler *smp,
                         sampler *rng, di_res *r, light_li *kept);
/* The same with candidate j taken as child first + j of `of` (a pixel's M candidates
 * split among its reservoirs: each takes the next children of the M). */
int restir_di_candidates_of(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, int M, uint32_t first,
                            uint32_t of, const sampler *smp, sampler *rng, di_res *r, light_li *kept);
/* p^ of DI sample y at a surface point, with the unshadowed contribution in *contrib and
 * the light's evaluation in *li (for the shadow ray). */
float restir_di_target(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, const di_sample *y, rgb *contrib,
                       light_li *li);
/* Jacobian of moving GI sample point xs (normal ns) from the pixel at x_from to the one
 * at x_to: d omega_to / d omega_from = |cos phi_to| / |cos phi_from| * |x_from - xs|^2 /
 * |x_to - xs|^2 (the solid angle a patch at xs subtends from x_to over that from x_from).
 * A reservoir's W estimates 1 / pdf in x_from's solid angle; times this it does in x_to's.
 * 0 when degenerate. */
float restir_gi_jacobian(vec3 x_from, vec3 x_to, vec3 xs, vec3 ns);
/* The reuse test: normals within normal_threshold (cosine) and depths within
 * depth_threshold (relative to depth_a). */
int restir_similar(const restir_cfg *cfg, vec3 n_a, float depth_a, vec3 n_b, float depth_b);
#endif
