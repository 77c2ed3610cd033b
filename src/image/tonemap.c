/* tonemap.c — see tonemap.h. */
#include "image/tonemap.h"
#include <string.h>
#include <stdlib.h>

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

float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f); }

float srgb_encode(float v) {
  if (!(v > 0)) return 0;
  if (v >= 1) return 1;
  return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1 / 2.4f) - 0.055f;
}

/* Separable Gaussian, kernel truncated at 3 sigma and normalised; borders clamp. */
int bloom_apply(int w, int h, float *px, float threshold, float strength, float sigma) {
  if (!(strength > 0) || !(sigma > 0)) return 0;
  int r = (int)ceilf(3 * sigma);
  if (r > 512) r = 512;
  float *k = malloc((2 * (size_t)r + 1) * sizeof(float));
  float *a = malloc((size_t)w * h * 3 * sizeof(float)), *b = malloc((size_t)w * h * 3 * sizeof(float));
  if (!k || !a || !b) { free(k); free(a); free(b); return -1; }
  float ks = 0;
  for (int i = -r; i <= r; i++) { k[i + r] = expf(-0.5f * (float)(i * i) / (sigma * sigma)); ks += k[i + r]; }
  for (int i = 0; i <= 2 * r; i++) k[i] /= ks;
  for (size_t i = 0; i < (size_t)w * h * 3; i++) a[i] = px[i] > threshold ? px[i] - threshold : 0;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      for (int c = 0; c < 3; c++) {
        float acc = 0;
        for (int i = -r; i <= r; i++) {
          int xx = x + i < 0 ? 0 : (x + i >= w ? w - 1 : x + i);
          acc += k[i + r] * a[3 * ((size_t)y * w + xx) + c];
        }
        b[3 * ((size_t)y * w + x) + c] = acc;
      }
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      for (int c = 0; c < 3; c++) {
        float acc = 0;
        for (int i = -r; i <= r; i++) {
          int yy = y + i < 0 ? 0 : (y + i >= h ? h - 1 : y + i);
          acc += k[i + r] * b[3 * ((size_t)yy * w + x) + c];
        }
        px[3 * ((size_t)y * w + x) + c] += strength * acc;
      }
  free(k); free(a); free(b);
  return 0;
}
