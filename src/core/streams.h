/* streams.h — owns the table of random streams: every stream valo draws from, with the
 * key that sets it apart from the others and the dimensions (sampler_set_dim) each use
 * takes in it, so that one place shows that no two uses share numbers
 * (test_chi2.streams_disjoint checks the table). The layout of the path integrators'
 * per-bounce dimensions is in rng.h (SDIM_*); this table places every other use.
 *
 * Streams:
 *   pixel         sampler_make_kind(seed, pixel, sample index): every camera sample, and
 *                 restir's per-pixel choices (sample index = frame)
 *   medium walks  rng_mix64(the pixel stream's key ^ the walk's number): the tracking
 *                 walks of grid media (path_media.c walk_key), whose count of random
 *                 numbers varies, hashed rather than taken from a dimension
 *   pixel child   sampler_child(pixel stream, j, n): final gathering (photon), per-light
 *                 cones (vsl), compensation and sampled shadow rays (vpl), RIS
 *                 candidates (restir: children 0..M-1 of M, the next M/K of them for
 *                 each of restir-di's K reservoirs), restir-gi's path from its sample point
 *   restir pixel  sampler_make(seed ^ STREAM_RESTIR_PIXEL, pixel, frame): reservoir choices
 *                 (restir-di's K reservoirs per pixel: the M candidates' choices in
 *                 turn from RDIM_CAND; reservoir k >= 1 merges from child k of K of the
 *                 merge's stream, at its dimension)
 *   guide pixel   sampler_make_kind(seed ^ STREAM_GUIDE, pixel, training sample): guided's
 *                 training paths (the pixel stream's layout)
 *   light paths   sampler_make_kind(key, 0, path index) with key from the pass:
 *                 rng_mix64(seed * GOLDEN + sample index + STREAM_VPL / STREAM_PHOTON),
 *                 the photon caustic map rng_mix64(that + 1), the VPL pilot
 *                 rng_mix64(seed + STREAM_VPL_PILOT) */
#ifndef VALO_STREAMS_H
#define VALO_STREAMS_H
#include "core/rng.h"
#include <stdint.h>

/* Keys that set streams apart (added to or mixed with the seed; see above). */
#define STREAM_VPL 0x76706c73ULL         /* "vpls": a pass's VPL light paths */
#define STREAM_VPL_PILOT 0x70696c6f74ULL /* "pilot": the VPL pilot set (clamping scale) */
#define STREAM_PHOTON 0x70686f746f6eULL  /* "photon": a pass's photon paths */
#define STREAM_RESTIR_PIXEL 0x5bd1e995u  /* restir's reservoir choices, xor the seed */
#define STREAM_GUIDE 0x6775696465ULL     /* "guide": guided's training paths, xor the seed */

/* Dimensions of the pixel stream beyond the path layout (rng.h: SDIM_FILM, SDIM_LENS,
 * SDIM_WAVELENGTH, then SDIM_PER_BOUNCE per bounce from SDIM_BOUNCE0; SDIM_AOV). */
enum {
  SDIM_AO = SDIM_EXTRA,                  /* 2D: the ao integrator's ray */
  SDIM_RESTIR_GI_DIR = SDIM_EXTRA + 0x20, /* 1D + 2D: restir-gi's sample direction */
  SDIM_RESTIR_NEE = SDIM_EXTRA + 0x22,   /* 1D + 2D: restir-gi's next-event estimate (direct=0) */
  SDIM_RESTIR_CAND = SDIM_EXTRA + 0x24,  /* restir-di's candidates: children j of M */
  SDIM_RESTIR_GI_PATH = SDIM_EXTRA + 0x25, /* restir-gi's path: child 0 of 1 */
  SDIM_PIXEL_END = SDIM_EXTRA + 0x26
};
/* Dimensions of a pixel child stream (sampler_child). */
enum {
  CDIM_GATHER = 0,                       /* photon: the gathering direction (1D + 2D), then its
                                            walk through delta lobes from sdim_bounce(d, SDIM_LOBE) */
  CDIM_VSL_CONE = SDIM_EXTRA,            /* vsl: up to 64 2D cone directions (child i of n) */
  CDIM_VPL_COMPENSATE = SDIM_EXTRA,      /* vpl: compensation's BSDF ray (1D + 2D), then its path
                                            from sdim_bounce(d, .) (child 0 of 1) */
  CDIM_VPL_SAMPLED = SDIM_EXTRA + 16,    /* vpl: the sampled shadow rays' offset (1D, child 0 of 1) */
  CDIM_VSL_SAMPLED = SDIM_EXTRA + 96,    /* vsl: the sampled lights' offset (1D, child 0 of 1; n > 1) */
};
/* Dimensions of the restir pixel stream. */
enum {
  RDIM_CAND = 64,                        /* restir-di: the choice among candidates (1D each, M <= 1024) */
  RDIM_TEMPORAL = 0x1000,                /* + 7 gi: temporal reuse */
  RDIM_SPATIAL = 0x2000                  /* + 256 round + 7 gi: spatial reuse (neighbours, choices) */
};

/* One row of the table: stream, use, dimensions [lo, hi). */
typedef struct stream_use { const char *stream, *use; uint32_t lo, hi; } stream_use;
/* The table, ended by a NULL stream (streams.c). */
extern const stream_use stream_uses[];
/* The keys, ended by 0. */
extern const uint64_t stream_keys[];
#endif
