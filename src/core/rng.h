/* rng.h — owns the counter-based random numbers and the samplers: every sample value is a
 * function of (seed, pixel, sample index, dimension), so images do not depend on thread
 * count or tile order (ARCHITECTURE "Determinism"). Hashes are a 64-bit splitmix /
 * Stafford-13 finaliser of a combined key. */
#ifndef VALO_RNG_H
#define VALO_RNG_H
#include <stdint.h>

static inline uint64_t rng_mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
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
/* Second Sobol dimension (primitive polynomial x + 1) before bit reversal: its generator
 * is the Pascal matrix mod 2, which maps the index's bits (as a polynomial f(z)) to those
 * of f(z + 1); since (1 + z)^(2^m) = 1 + z^(2^m) mod 2 that takes five shift-xor steps
 * (halves of each 2^(m+1)-bit block) instead of a loop over the index's bits. The Sobol
 * fraction is rng_reverse_bits of this. */
static inline uint32_t rng_sobol1_rev(uint32_t x) {
  x ^= (x >> 16) & 0x0000FFFFu;
  x ^= (x >> 8) & 0x00FF00FFu;
  x ^= (x >> 4) & 0x0F0F0F0Fu;
  x ^= (x >> 2) & 0x33333333u;
  x ^= (x >> 1) & 0x55555555u;
  return x;
}
static inline uint32_t rng_sobol1(uint32_t i) { return rng_reverse_bits(rng_sobol1_rev(i)); }

/* A sampler stream for one sample of one pixel: a key fixed per (seed, pixel, sample), the
 * sample's index and a running dimension. Two kinds:
 *  - SAMPLER_INDEPENDENT: every value a hash of (key, dimension);
 *  - SAMPLER_SOBOL (rendering's default): Owen-scrambled Sobol points padded per dimension
 *    (Burley, "Practical Hash-based Owen Scrambling", JCGT 2020): dimension d of sample i
 *    is Sobol point shuffle_d(i) (an Owen scramble of the index, seeded per pixel and
 *    dimension), Owen-scrambled per pixel and dimension. 1D values use Sobol's first
 *    dimension (van der Corput), 2D values its first two. Each point is uniformly
 *    distributed (estimators stay unbiased); a pixel's first 2^k samples are stratified in
 *    every 1D dimension into 2^k intervals and in every 2D pair into every elementary
 *    interval of area 2^-k (a (0,2)-net), for any number of dimensions and any sample
 *    count. Integrators give each use a fixed dimension (sampler_set_dim; layout below),
 *    so the same decision draws from the same stratified stream in every sample. */
typedef enum sampler_kind { SAMPLER_INDEPENDENT = 0, SAMPLER_SOBOL = 1 } sampler_kind;
typedef struct sampler { uint64_t key; uint64_t pixel_key; uint32_t index; uint32_t dim; int kind; } sampler;

static inline sampler sampler_make_kind(uint64_t seed, uint64_t pixel, uint64_t sample_index, sampler_kind kind) {
  sampler s;
  s.pixel_key = rng_mix64(seed * 0x9e3779b97f4a7c15ULL + pixel);
  s.key = rng_mix64(s.pixel_key ^ (sample_index * 0xd1b54a32d192ed03ULL + 0x632be59bd9b4e019ULL));
  s.index = (uint32_t)sample_index;
  s.dim = 0;
  s.kind = kind;
  return s;
}
/* An independent stream (tests and benchmarks that want plain random numbers). */
static inline sampler sampler_make(uint64_t seed, uint64_t pixel, uint64_t sample_index) {
  return sampler_make_kind(seed, pixel, sample_index, SAMPLER_INDEPENDENT);
}
static inline void sampler_set_dim(sampler *s, uint32_t dim) { s->dim = dim; }
/* A raw 32-bit hash (not stratified); consumes one dimension. */
static inline uint32_t sampler_u32(sampler *s) {
  return (uint32_t)(rng_mix64(s->key + (uint64_t)(s->dim++) * 0x9e3779b97f4a7c15ULL) >> 32);
}
static inline float rng_to_float(uint32_t x) { return (float)(x >> 8) * 0x1p-24f; }
/* Uniform float in [0, 1); consumes one dimension. */
static inline float sampler_1d(sampler *s) {
  if (s->kind == SAMPLER_INDEPENDENT) return rng_to_float(sampler_u32(s));
  uint64_t h = rng_mix64(s->pixel_key + (uint64_t)(s->dim++) * 0x9e3779b97f4a7c15ULL);
  uint32_t idx = rng_owen_scramble(s->index, (uint32_t)h);
  /* owen_scramble(reverse(idx)) = reverse(lk(idx)): van der Corput, scrambled. */
  return rng_to_float(rng_reverse_bits(rng_owen_lk(idx, (uint32_t)(h >> 32))));
}
/* A 2D point in [0,1)^2; consumes one dimension. */
static inline void sampler_2d(sampler *s, float *u1, float *u2) {
  if (s->kind == SAMPLER_INDEPENDENT) {
    uint64_t h = rng_mix64(s->key + (uint64_t)(s->dim++) * 0x9e3779b97f4a7c15ULL);
    *u1 = rng_to_float((uint32_t)(h >> 32));
    *u2 = rng_to_float((uint32_t)h);
    return;
  }
  uint64_t h = rng_mix64(s->pixel_key + (uint64_t)(s->dim++) * 0x9e3779b97f4a7c15ULL);
  uint32_t shuffle = (uint32_t)h, sx = (uint32_t)(h >> 32), sy = (uint32_t)rng_mix64(h);
  uint32_t idx = rng_owen_scramble(s->index, shuffle);
  *u1 = rng_to_float(rng_reverse_bits(rng_owen_lk(idx, sx)));
  *u2 = rng_to_float(rng_reverse_bits(rng_owen_lk(rng_sobol1_rev(idx), sy)));
}

/* Stream j of n children of s (final-gathering rays): a Sobol sampler's child j of
 * sample i is point i n + j of a stream keyed apart from s's, so the n rays of one
 * sample and those of all samples are stratified together; independent: a new hash. */
static inline sampler sampler_child(const sampler *s, uint32_t j, uint32_t n) {
  sampler c = *s;
  c.pixel_key = rng_mix64(s->pixel_key ^ 0xc2b2ae3d27d4eb4fULL);
  c.key = rng_mix64(s->key + 0x165667b19e3779f9ULL * (uint64_t)(j + 1));
  c.index = s->index * n + j;
  c.dim = 0;
  return c;
}

/* Dimension layout of the path integrators: one dimension per decision, fixed per bounce. */
enum {
  SDIM_FILM = 0,        /* 2D: position in the pixel */
  SDIM_LENS = 1,        /* 2D: point on the lens */
  SDIM_WAVELENGTH = 2,  /* 1D: hero wavelength (spectral) */
  SDIM_BOUNCE0 = 3,     /* then per bounce: */
  SDIM_LIGHT_PICK = 0,  /*   1D: which light */
  SDIM_LIGHT_POINT = 1, /*   2D: where on it */
  SDIM_LOBE = 2,        /*   1D: which BSDF lobe */
  SDIM_BSDF_DIR = 3,    /*   2D: direction */
  SDIM_ROULETTE = 4,    /*   1D: Russian roulette */
  SDIM_PER_BOUNCE = 5,
  SDIM_MEDIUM = 0x20000000, /* path through media: 1D + 1D per free-flight sample k
                              (channel, distance) at SDIM_MEDIUM + 2k, k < SDIM_MEDIUM_MAX */
  SDIM_MEDIUM_MAX = 0x1000000,
  SDIM_AOV = 0x40000000, /* 2D: the ao AOV's direction (beside any integrator) */
  SDIM_EXTRA = 0x40000100 /* integrator-specific streams start here (ao, photon gathering) */
};
static inline uint32_t sdim_bounce(int depth, int what) { return SDIM_BOUNCE0 + (uint32_t)depth * SDIM_PER_BOUNCE + (uint32_t)what; }
#endif
