/* tonemap.h — owns the display transforms applied to PNG output (linear formats stay
 * untouched): exposure (2^stops), then one tone curve — `clamp` (none), `log` (the thesis'
 * natural logarithm, digest 000 §6.10: v' = ln(1 + v)), `reinhard` (on luminance,
 * L' = L / (1 + L), colour scaled by L'/L) or `aces` (Narkowicz's fit of the ACES filmic
 * curve) — then the sRGB transfer function. */
#ifndef VALO_TONEMAP_H
#define VALO_TONEMAP_H
#include "core/vec.h"

typedef enum tonemap_kind { TONEMAP_CLAMP, TONEMAP_LOG, TONEMAP_REINHARD, TONEMAP_ACES } tonemap_kind;
/* Returns 0 and sets *k for a known name, -1 otherwise. */
int tonemap_parse(const char *name, tonemap_kind *k);
rgb tonemap_apply(tonemap_kind k, rgb c);
float srgb_encode(float linear);
/* The sRGB decoding curve (8-bit colour maps, and data AOVs stored linearly in PNG). */
float srgb_to_linear(float encoded);
/* Bloom (digest 000 §6.10): adds strength x (Gaussian blur, std. dev. sigma pixels, of
 * max(c - threshold, 0)) to the image in place. Returns 0, or -1 on OOM. */
int bloom_apply(int w, int h, float *rgb, float threshold, float strength, float sigma);
#endif
