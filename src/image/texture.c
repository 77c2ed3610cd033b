/* texture.c — see texture.h. */
#include "image/texture.h"
#include "image/image_io.h"
#include "image/tonemap.h"
#include "core/error.h"
#include "core/memlimit.h"
#include <stdio.h>
#include <stb_image.h>
#include <stdlib.h>
#include <string.h>

/* Texels are 16 bytes: a header that claims more than this many (4 GiB of texels) is
 * refused from stb's header read, before anything is decoded or allocated. */
#define TEXTURE_MAX_PIXELS (1ull << 28)

/* ok: stb read the header (when it did not, decoding fails below with stb's reason). */
/* The size a PNG's header (IHDR) claims, from the file's first `got` bytes b: 1 and *w,
 * *h, or 0 when it is not a PNG. stb refuses to report sizes above 2^30 bytes of 8-bit
 * texels, without saying them. */
static int png_header_size(const unsigned char *b, size_t got, int *w, int *h) {
  static const unsigned char sig[16] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R'};
  if (got < 24 || memcmp(b, sig, sizeof sig)) return 0;
  uint32_t pw = (uint32_t)b[16] << 24 | (uint32_t)b[17] << 16 | (uint32_t)b[18] << 8 | b[19];
  uint32_t ph = (uint32_t)b[20] << 24 | (uint32_t)b[21] << 16 | (uint32_t)b[22] << 8 | b[23];
  if (pw == 0 || ph == 0 || pw > INT32_MAX || ph > INT32_MAX) return 0;
  *w = (int)pw;
  *h = (int)ph;
  return 1;
}

/* The most pixels a file can decode to per byte, by its format: deflate packs 1 032 bytes
 * into one, 8 pixels a byte in 1-bit PNG rows (GIF's LZW less); a JPEG block needs a few
 * bits; the run-length formats stb reads (TGA, BMP, PSD, PIC) at most 128 pixels in 2
 * bytes. A header claiming more is refused before its decoder runs through pixels the
 * data cannot hold (a 37 KB TGA claiming 4112 x 4112 kept stb busy for seconds). */
static unsigned long long pixels_per_byte_max(const unsigned char *head, size_t n) {
  if (n >= 4 && head[0] == 0x89 && head[1] == 'P' && head[2] == 'N' && head[3] == 'G') return 10000;
  if (n >= 4 && !memcmp(head, "GIF8", 4)) return 10000;
  if (n >= 2 && head[0] == 0xff && head[1] == 0xd8) return 2000;
  return 256;
}

static valo_status check_size(int ok, int w, int h, size_t bytes, unsigned long long per_byte, const char *name, valo_error *err) {
  if (ok && (w < 1 || h < 1))
    return err_set(err, VALO_ERR_PARSE, "%s: the image header gives a size of %d x %d pixels", name, w, h);
  if (ok && (unsigned long long)w * (unsigned long long)h > TEXTURE_MAX_PIXELS)
    return err_set(err, VALO_ERR_NOMEM, "%s: image of %d x %d pixels is larger than valo's texture limit (%llu pixels, %llu MiB as float RGBA)",
                   name, w, h, TEXTURE_MAX_PIXELS, TEXTURE_MAX_PIXELS * 16 >> 20);
  if (ok && (unsigned long long)w * (unsigned long long)h > per_byte * bytes + 65536)
    return err_set(err, VALO_ERR_PARSE, "%s: the image header claims %d x %d pixels, more than its %zu bytes can hold (damaged)", name, w,
                   h, bytes);
  /* float RGBA, and the decoder's 8-bit copy (at most 4 channels) while converting */
  return ok ? mem_check_pixels((uint64_t)w, (uint64_t)h, 20, name, err) : VALO_OK;
}


static valo_status from_8bit(texture *t, unsigned char *data, int w, int h, int n, int srgb, const char *name, valo_error *err) {
  t->px = malloc((size_t)w * h * 4 * sizeof(float));
  if (!t->px) { stbi_image_free(data); return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", name); }
  float lut[256];
  for (int i = 0; i < 256; i++) lut[i] = srgb ? srgb_to_linear(i / 255.0f) : i / 255.0f;
  for (size_t i = 0; i < (size_t)w * h; i++) {
    const unsigned char *p = &data[(size_t)n * i];
    float *o = &t->px[4 * i];
    if (n >= 3) { o[0] = lut[p[0]]; o[1] = lut[p[1]]; o[2] = lut[p[2]]; }
    else { o[0] = o[1] = o[2] = lut[p[0]]; }
    o[3] = (n == 2 || n == 4) ? p[n - 1] / 255.0f : 1.0f; /* alpha is always linear */
  }
  t->w = w; t->h = h;
  t->has_alpha = (n == 2 || n == 4);
  stbi_image_free(data);
  return VALO_OK;
}

valo_status texture_load_memory(texture *t, const unsigned char *data, size_t len, const char *name, int srgb, valo_error *err) {
  memset(t, 0, sizeof *t);
  if (len > (size_t)INT32_MAX) return err_set(err, VALO_ERR_INVALID, "%s: embedded image too large", name);
  int w = 0, h = 0, n = 0;
  int ok = stbi_info_from_memory(data, (int)len, &w, &h, &n);
  valo_status st = check_size(ok, w, h, len, pixels_per_byte_max(data, len), name, err);
  if (st) return st;
  unsigned char *img = stbi_load_from_memory(data, (int)len, &w, &h, &n, 0);
  if (!img) return err_set(err, VALO_ERR_PARSE, "%s: cannot decode image: %s", name, stbi_failure_reason());
  return from_8bit(t, img, w, h, n, srgb, name, err);
}

valo_status texture_load_file(texture *t, const char *path, int srgb, valo_error *err) {
  return texture_load_file_as(t, path, srgb, "texture", err);
}

valo_status texture_load_file_as(texture *t, const char *path, int srgb, const char *what, valo_error *err) {
  memset(t, 0, sizeof *t);
  if (image_is_float_file(path)) {
    image im;
    valo_status st = image_read(path, &im, err);
    if (st) return st;
    if ((st = mem_check_pixels((uint64_t)im.w, (uint64_t)im.h, 28, path, err))) { image_free(&im); return st; }
    t->px = malloc((size_t)im.w * im.h * 4 * sizeof(float));
    if (!t->px) { image_free(&im); return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", path); }
    for (size_t i = 0; i < (size_t)im.w * im.h; i++) {
      for (int c = 0; c < 3; c++) t->px[4 * i + c] = im.rgb[3 * i + c];
      t->px[4 * i + 3] = 1;
    }
    t->w = im.w; t->h = im.h;
    image_free(&im);
    return VALO_OK;
  }
  int w = 0, h = 0, n = 0;
  int ok = stbi_info(path, &w, &h, &n);
  /* the file's first bytes (its format, a PNG's size) and its length */
  unsigned char head[24];
  size_t hn = 0, bytes = 0;
  FILE *hf = fopen(path, "rb");
  if (hf) {
    hn = fread(head, 1, sizeof head, hf);
    if (fseek(hf, 0, SEEK_END) == 0 && ftell(hf) > 0) bytes = (size_t)ftell(hf);
    fclose(hf);
  }
  if (!ok) ok = png_header_size(head, hn, &w, &h); /* a size stb refuses to report */
  valo_status st = check_size(ok, w, h, bytes, pixels_per_byte_max(head, hn), path, err);
  if (st) return st;
  unsigned char *img = stbi_load(path, &w, &h, &n, 0);
  if (!img) return err_set(err, VALO_ERR_IO, "%s: cannot read %s: %s", path, what, stbi_failure_reason());
  return from_8bit(t, img, w, h, n, srgb, path, err);
}

valo_status texture_checkerboard(texture *t, const float c0[3], const float c1[3], valo_error *err) {
  memset(t, 0, sizeof *t);
  t->px = malloc(16 * sizeof(float));
  if (!t->px) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  for (int i = 0; i < 4; i++) {
    const float *c = (i == 0 || i == 3) ? c0 : c1;
    for (int k = 0; k < 3; k++) t->px[4 * i + k] = c[k];
    t->px[4 * i + 3] = 1;
  }
  t->w = t->h = 2;
  t->smp.filter = TEX_NEAREST;
  return VALO_OK;
}

void texture_free(texture *t) {
  if (!t->shares_px) free(t->px);
  t->px = NULL;
}

static int wrap_coord(int i, int n, tex_wrap m) {
  switch (m) {
  case TEX_CLAMP: return i < 0 ? 0 : (i >= n ? n - 1 : i);
  case TEX_MIRROR: {
    int p = 2 * n;
    i %= p;
    if (i < 0) i += p;
    return i < n ? i : p - 1 - i;
  }
  case TEX_REPEAT: break;
  }
  i %= n;
  return i < 0 ? i + n : i;
}

void texture_texel(const texture *t, int x, int y, float out[4]) {
  x = wrap_coord(x, t->w, t->smp.wrap);
  y = wrap_coord(y, t->h, t->smp.wrap);
  memcpy(out, &t->px[4 * ((size_t)y * t->w + x)], 4 * sizeof(float));
}

/* (u, v) through the map of the texture coordinates; (0, 0), returning 0, when it is not
 * finite. */
static int mapped_uv(const texture *t, float *u, float *v) {
  if (t->smp.has_uvm) {
    float tu = t->smp.uvm[0] * *u + t->smp.uvm[1] * *v + t->smp.uvm[2];
    *v = t->smp.uvm[3] * *u + t->smp.uvm[4] * *v + t->smp.uvm[5];
    *u = tu;
  }
  if (isfinite(*u) && isfinite(*v)) return 1;
  *u = *v = 0;
  return 0;
}

/* The bilinear cell of mapped (u, v): its four texels a b / c d (a top-left) and the
 * weights fx, fy of the right and lower ones. Texel centres sit at (x + 0.5)/w; v = 0 is
 * the bottom row. */
static void bilinear_cell(const texture *t, float u, float v, float px[4][4], float *fx, float *fy) {
  float x = u * t->w - 0.5f, y = (1 - v) * t->h - 0.5f;
  float fx0 = floorf(x), fy0 = floorf(y);
  if (fabsf(fx0) > 1e8f || fabsf(fy0) > 1e8f) { fx0 = 0; fy0 = 0; }
  int x0 = (int)fx0, y0 = (int)fy0;
  *fx = x - fx0;
  *fy = y - fy0;
  texture_texel(t, x0, y0, px[0]); texture_texel(t, x0 + 1, y0, px[1]);
  texture_texel(t, x0, y0 + 1, px[2]); texture_texel(t, x0 + 1, y0 + 1, px[3]);
}

void texture_lookup(const texture *t, float u, float v, float out[4]) {
  mapped_uv(t, &u, &v);
  if (t->smp.filter == TEX_NEAREST) {
    float fx = floorf(u * t->w), fy = floorf((1 - v) * t->h);
    if (fabsf(fx) > 1e8f || fabsf(fy) > 1e8f) { fx = 0; fy = 0; }
    texture_texel(t, (int)fx, (int)fy, out);
    return;
  }
  float px[4][4], fx, fy;
  bilinear_cell(t, u, v, px, &fx, &fy);
  for (int k = 0; k < 4; k++) out[k] = (px[0][k] * (1 - fx) + px[1][k] * fx) * (1 - fy) + (px[2][k] * (1 - fx) + px[3][k] * fx) * fy;
}

void texture_gradient(const texture *t, float u, float v, const float w[3], float *du, float *dv) {
  *du = *dv = 0;
  if (t->smp.filter == TEX_NEAREST || !mapped_uv(t, &u, &v)) return;
  float px[4][4], f[4], fx, fy;
  bilinear_cell(t, u, v, px, &fx, &fy);
  for (int k = 0; k < 4; k++) f[k] = w[0] * px[k][0] + w[1] * px[k][1] + w[2] * px[k][2];
  float dfx = (f[1] - f[0]) * (1 - fy) + (f[3] - f[2]) * fy, dfy = (f[2] - f[0]) * (1 - fx) + (f[3] - f[1]) * fx;
  float dtu = dfx * (float)t->w, dtv = -dfy * (float)t->h; /* y runs down the image as v runs up */
  const float *m = t->smp.uvm;
  if (t->smp.has_uvm) {
    *du = m[0] * dtu + m[3] * dtv;
    *dv = m[1] * dtu + m[4] * dtv;
  } else {
    *du = dtu;
    *dv = dtv;
  }
}
