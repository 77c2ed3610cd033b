/* rng.h — owns the counter-based random numbers: every sample value is a hash of
 * (seed, pixel, sample index, dimension), so images do not depend on thread count or
 * tile order (ARCHITECTURE "Determinism"). The hash is a 64-bit finaliser
 * (splitmix64 / Stafford variant 13) applied to a combined key. */
#ifndef VALO_RNG_H
#define VALO_RNG_H
#include <stdint.h>

static inline uint64_t rng_mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
/* A sampler stream: a key fixed per (seed, pixel, sample) and a running dimension. */
typedef struct sampler { uint64_t key; uint32_t dim; } sampler;

static inline sampler sampler_make(uint64_t seed, uint64_t pixel, uint64_t sample_index) {
  sampler s;
  s.key = rng_mix64(rng_mix64(seed * 0x9e3779b97f4a7c15ULL + pixel) ^ (sample_index * 0xd1b54a32d192ed03ULL + 0x632be59bd9b4e019ULL));
  s.dim = 0;
  return s;
}
static inline uint32_t sampler_u32(sampler *s) {
  return (uint32_t)(rng_mix64(s->key + (uint64_t)(s->dim++) * 0x9e3779b97f4a7c15ULL) >> 32);
}
/* Uniform float in [0, 1). */
static inline float sampler_1d(sampler *s) { return (float)(sampler_u32(s) >> 8) * 0x1p-24f; }
#endif
