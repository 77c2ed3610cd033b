/* aov.h — owns the AOVs of the first camera hit (albedo, shading normal facing the
 * camera, distance, the radiance it emits, and one ambient-occlusion ray: unoccluded
 * fraction and bent normal)
 * and their one table of output prefixes ("albedo:", ... "spp:"), which output.c and the
 * public API (valo_output_prefix) read. */
#ifndef VALO_AOV_H
#define VALO_AOV_H
#include "render/session.h"

typedef enum aov_kind { AOV_KIND_ALBEDO, AOV_KIND_NORMAL, AOV_KIND_DEPTH, AOV_KIND_AO, AOV_KIND_BENT, AOV_KIND_SPP, AOV_KIND_DENOISED, AOV_KIND_COUNT } aov_kind;
/* The output prefix of each kind ("albedo:" ...), AOV_KIND_COUNT of them. */
extern const char *const aov_prefixes[AOV_KIND_COUNT];
/* The kind an output name asks for (its prefix; *plen gets the prefix's length), or -1
 * for the image itself. */
int aov_kind_of(const char *output, size_t *plen);
/* Adds the AOVs of camera ray ry to acc (AOV_FLOATS floats); the ao ray when the
 * options ask for it (VALO_AOVS_AO). */
void aov_record(const session *ss, ray ry, float *acc, sampler *smp, thread_stats *ts);
#endif
