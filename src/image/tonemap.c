/* tonemap.c — see tonemap.h. */
#include "image/tonemap.h"
#include <string.h>

int tonemap_parse(const char *name, tonemap_kind *k) {
  static const struct { const char *n; tonemap_kind k; } t[] = {
      {"clamp", TONEMAP_CLAMP}, {"log", TONEMAP_LOG}, {"reinhard", TONEMAP_REINHARD}, {"aces", TONEMAP_ACES}};
  for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
    if (!strcmp(name, t[i].n)) { *k = t[i].k; return 0; }
  return -1;
}

static float aces1(float x) {
  x = fmaxf(x, 0);
  return clampf((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0, 1);
}

rgb tonemap_apply(tonemap_kind k, rgb c) {
  switch (k) {
  case TONEMAP_CLAMP: return c;
  case TONEMAP_LOG: return c3(log1pf(fmaxf(c.r, 0)), log1pf(fmaxf(c.g, 0)), log1pf(fmaxf(c.b, 0)));
  case TONEMAP_REINHARD: {
    float l = c3_lum(c);
    return l > 0 ? c3_scale(c, 1.0f / (1.0f + l)) : c3(0, 0, 0);
  }
  case TONEMAP_ACES: return c3(aces1(c.r), aces1(c.g), aces1(c.b));
  }
  return c;
}

float srgb_encode(float v) {
  if (!(v > 0)) return 0;
  if (v >= 1) return 1;
  return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1 / 2.4f) - 0.055f;
}
