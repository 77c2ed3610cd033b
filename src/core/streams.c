/* streams.c — see streams.h: the table the test reads. */
#include "core/streams.h"
#include <stddef.h>

#define BOUNCES_END (SDIM_BOUNCE0 + SDIM_PER_BOUNCE * 0x100000u) /* max_depth is at most 100000 */

const stream_use stream_uses[] = {
    {"pixel", "film position", SDIM_FILM, SDIM_FILM + 1},
    {"pixel", "lens", SDIM_LENS, SDIM_LENS + 1},
    {"pixel", "wavelength", SDIM_WAVELENGTH, SDIM_WAVELENGTH + 1},
    {"pixel", "path bounces and the walk through delta lobes", SDIM_BOUNCE0, BOUNCES_END},
    {"pixel", "free-flight distances in media", SDIM_MEDIUM, SDIM_MEDIUM + 2 * SDIM_MEDIUM_MAX},
    {"pixel", "ao AOV", SDIM_AOV, SDIM_AOV + 1},
    {"pixel", "ao integrator", SDIM_AO, SDIM_AO + 1},
    {"pixel", "restir-gi direction", SDIM_RESTIR_GI_DIR, SDIM_RESTIR_GI_DIR + 2},
    {"pixel", "restir-gi next-event estimate", SDIM_RESTIR_NEE, SDIM_RESTIR_NEE + 2},
    {"pixel", "restir-di candidates", SDIM_RESTIR_CAND, SDIM_RESTIR_CAND + 1},
    {"pixel", "restir-gi path", SDIM_RESTIR_GI_PATH, SDIM_RESTIR_GI_PATH + 1},
    {"gather child", "photon gathering direction", CDIM_GATHER, CDIM_GATHER + 2},
    {"gather child", "its walk through delta lobes", SDIM_BOUNCE0, BOUNCES_END},
    {"vpl child 0 of 1", "compensation's BSDF ray", CDIM_VPL_COMPENSATE, CDIM_VPL_COMPENSATE + 2},
    {"vpl child 0 of 1", "compensation's path", SDIM_BOUNCE0, BOUNCES_END},
    {"vpl child 0 of 1", "sampled shadow rays", CDIM_VPL_SAMPLED, CDIM_VPL_SAMPLED + 1},
    {"vsl child i of n", "cone directions", CDIM_VSL_CONE, CDIM_VSL_CONE + 64},
    {"vsl child 0 of 1", "sampled lights", CDIM_VSL_SAMPLED, CDIM_VSL_SAMPLED + 1},
    {"restir pixel", "candidate choice", RDIM_CAND, RDIM_CAND + 1024},
    {"restir pixel", "temporal reuse", RDIM_TEMPORAL, RDIM_TEMPORAL + 8},
    {"restir pixel", "spatial reuse", RDIM_SPATIAL, RDIM_SPATIAL + 256 * 8 + 8},
    {NULL, NULL, 0, 0}};

const uint64_t stream_keys[] = {STREAM_VPL, STREAM_VPL_PILOT, STREAM_PHOTON, STREAM_RESTIR_PIXEL, STREAM_GUIDE, 0};
