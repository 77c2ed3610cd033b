/* rng.h — owns the counter-based random numbers: every sample value is a function of
 * (seed, pixel, sample index, dimension), so images do not depend on thread count or
 * tile order (ARCHITECTURE "Determinism"). 1D values are hashes (a 64-bit splitmix /
 * Stafford-13 finaliser of a combined key). 2D values come from the first two Sobol
 * dimensions with hash-based Owen scrambling and a per-pixel, per-dimension shuffle of the
 * sample index (Burley, "Practical Hash-based Owen Scrambling", JCGT 2020): each point is
 * uniformly distributed (so estimators stay unbiased) while a pixel's samples stratify
 * every 2D pair progressively, for any sample count. */
#ifndef VALO_RNG_H
#define VALO_RNG_H
#include <stdint.h>

static inline uint64_t rng_mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
/* A sampler stream: a key fixed per (seed, pixel, sample) and a running dimension. */
typedef struct sampler { uint64_t key; uint64_t pixel_key; uint32_t index; uint32_t dim; } sampler;

static inline sampler sampler_make(uint64_t seed, uint64_t pixel, uint64_t sample_index) {
  sampler s;
  s.pixel_key = rng_mix64(seed * 0x9e3779b97f4a7c15ULL + pixel);
  s.key = rng_mix64(s.pixel_key ^ (sample_index * 0xd1b54a32d192ed03ULL + 0x632be59bd9b4e019ULL));
  s.index = (uint32_t)sample_index;
  s.dim = 0;
  return s;
}
static inline uint32_t sampler_u32(sampler *s) {
  return (uint32_t)(rng_mix64(s->key + (uint64_t)(s->dim++) * 0x9e3779b97f4a7c15ULL) >> 32);
}
/* Uniform float in [0, 1). */
static inline float sampler_1d(sampler *s) { return (float)(sampler_u32(s) >> 8) * 0x1p-24f; }

static inline uint32_t rng_reverse_bits(uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
  return __builtin_bswap32(x);
}
/* A permutation in which bit k of the result depends only on bits <= k of the input
 * (adds and multiplications by even constants carry only upwards); applied to
 * bit-reversed values it is a nested uniform (Owen) scramble. */
static inline uint32_t rng_owen_lk(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}
static inline uint32_t rng_owen_scramble(uint32_t x, uint32_t seed) {
  return rng_reverse_bits(rng_owen_lk(rng_reverse_bits(x), seed));
}
/* Second Sobol dimension (primitive polynomial x + 1), as a 32-bit fraction. */
static inline uint32_t rng_sobol1(uint32_t i) {
  uint32_t r = 0;
  for (uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1)
    if (i & 1) r ^= v;
  return r;
}
/* A 2D point in [0,1)^2 for this sample; consumes one dimension. The first
 * SAMPLER_LDS_DIMS dimensions (camera, lens, the first two bounces) are stratified;
 * deeper ones gain little from it and use independent hashes. */
#define SAMPLER_LDS_DIMS 12
static inline void sampler_2d(sampler *s, float *u1, float *u2) {
  if (s->dim >= SAMPLER_LDS_DIMS) {
    *u1 = sampler_1d(s);
    *u2 = sampler_1d(s);
    return;
  }
  uint64_t h = rng_mix64(s->pixel_key + (uint64_t)(s->dim++) * 0x9e3779b97f4a7c15ULL);
  uint32_t shuffle = (uint32_t)h, sx = (uint32_t)(h >> 32), sy = (uint32_t)rng_mix64(h);
  uint32_t idx = rng_owen_scramble(s->index, shuffle);
  uint32_t x = rng_owen_scramble(rng_reverse_bits(idx), sx), y = rng_owen_scramble(rng_sobol1(idx), sy);
  *u1 = (float)(x >> 8) * 0x1p-24f;
  *u2 = (float)(y >> 8) * 0x1p-24f;
}
#endif
