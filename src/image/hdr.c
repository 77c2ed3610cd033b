/* hdr.c — owns reading Radiance HDR (RGBE) images: the header (#?RADIANCE or #?RGBE,
 * FORMAT=32-bit_rle_rgbe, a "-Y H +X W" resolution), flat scanlines and the adaptive RLE
 * of Greg Ward's format, every read bounded by the file's size. valo decodes HDR itself
 * because Debian 12's stb_image (libstb0 0.0~git20220908.8b5f1f3+ds-1) loops forever on
 * a scanline cut off inside its RLE data: at the end of the file its byte reader returns
 * 0, a run length of 0 never advances, and stbi_loadf never returns. Pixels come out exactly as stb_image
 * made them (the same ldexp(1, e - 136) scaling), so valid maps render as before. */
#include "image/hdr.h"
#include "core/error.h"
#include "core/memlimit.h"
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HDR_MAX_DIM (1 << 24)   /* stb_image's limit too */
#define HDR_MAX_HEADER 8192

static void rgbe_to_rgb(const unsigned char *rgbe, float *out) {
  if (rgbe[3]) {
    float f = (float)ldexp(1.0f, (int)rgbe[3] - (128 + 8));
    out[0] = rgbe[0] * f;
    out[1] = rgbe[1] * f;
    out[2] = rgbe[2] * f;
  } else {
    out[0] = out[1] = out[2] = 0;
  }
}

/* One header line (without its '\n') into buf; returns the bytes consumed or 0 when no
 * line end comes within the header's limit. */
static size_t header_line(const unsigned char *p, size_t n, char *buf, size_t cap) {
  const unsigned char *nl = memchr(p, '\n', n);
  if (!nl) return 0;
  size_t len = (size_t)(nl - p);
  size_t keep = len < cap - 1 ? len : cap - 1;
  memcpy(buf, p, keep);
  buf[keep] = 0;
  return len + 1;
}

valo_status hdr_decode(const char *name, const unsigned char *d, size_t n, image *out, valo_error *err) {
  out->w = out->h = 0;
  out->rgb = NULL;
  size_t pos = 0, used, limit = n < HDR_MAX_HEADER ? n : HDR_MAX_HEADER;
  char line[256];
  used = header_line(d, limit, line, sizeof line);
  if (!used || (strcmp(line, "#?RADIANCE") && strcmp(line, "#?RGBE")))
    return err_set(err, VALO_ERR_PARSE, "%s: not a Radiance HDR file (no #?RADIANCE or #?RGBE line)", name);
  pos = used;
  int format = 0;
  for (;;) {
    used = header_line(d + pos, limit - pos, line, sizeof line);
    if (!used) return err_set(err, VALO_ERR_PARSE, "%s: the HDR header does not end (no blank line in its first %d bytes)", name, HDR_MAX_HEADER);
    pos += used;
    if (!line[0]) break;
    if (!strncmp(line, "FORMAT=", 7)) {
      if (strcmp(line, "FORMAT=32-bit_rle_rgbe"))
        return err_set(err, VALO_ERR_UNSUPPORTED, "%s: HDR pixel format '%s' is not supported (only 32-bit_rle_rgbe)", name, line + 7);
      format = 1;
    }
  }
  if (!format) return err_set(err, VALO_ERR_UNSUPPORTED, "%s: the HDR header names no FORMAT=32-bit_rle_rgbe", name);
  used = header_line(d + pos, (n - pos) < 256 ? n - pos : 256, line, sizeof line);
  long h = 0, w = 0;
  char tail = ' ';
  int got = used ? sscanf(line, "-Y %ld +X %ld%c", &h, &w, &tail) : 0;
  if (got < 2 || !isspace((unsigned char)tail))
    return err_set(err, VALO_ERR_UNSUPPORTED, "%s: HDR resolution line '%s' is not '-Y H +X W' (the only layout supported)", name, used ? line : "");
  pos += used;
  if (w < 1 || h < 1 || w > HDR_MAX_DIM || h > HDR_MAX_DIM)
    return err_set(err, VALO_ERR_PARSE, "%s: HDR size %ld x %ld is out of range (1 to %d)", name, w, h, HDR_MAX_DIM);
  /* The smallest a scanline can be: flat, 4 bytes a pixel; RLE, a 4-byte start and runs of
   * at most 128 (2 bytes each) for each of 4 channels. A size the data cannot hold is
   * refused before anything is allocated. */
  int rle = w >= 8 && w < 32768;
  uint64_t row_min = rle ? 4 + 4 * 2 * (uint64_t)((w + 127) / 128) : 4 * (uint64_t)w;
  uint64_t left = n - pos;
  if ((uint64_t)h > left / row_min)
    return err_set(err, VALO_ERR_PARSE, "%s: HDR header says %ld x %ld pixels, which need at least %llu bytes; the file has %llu after its header",
                   name, w, h, (unsigned long long)(row_min * (uint64_t)h), (unsigned long long)left);
  /* A first scanline without the RLE mark (2, 2, width) means flat pixels throughout. */
  if (rle && !(d[pos] == 2 && d[pos + 1] == 2 && !(d[pos + 2] & 0x80))) rle = 0;
  if (!rle && (uint64_t)h * w * 4 > left)
    return err_set(err, VALO_ERR_PARSE, "%s: HDR pixels end early: %ld x %ld flat pixels need %llu bytes; the file has %llu",
                   name, w, h, (unsigned long long)((uint64_t)h * w * 4), (unsigned long long)left);
  valo_status mst = mem_check_pixels((uint64_t)w, (uint64_t)h, 12, name, err);
  if (mst) return mst;
  float *rgb = malloc((size_t)w * (size_t)h * 3 * sizeof(float));
  unsigned char *scan = rle ? malloc((size_t)w * 4) : NULL;
  if (!rgb || (rle && !scan)) {
    free(rgb); free(scan);
    return err_set(err, VALO_ERR_NOMEM, "%s: out of memory for %ld x %ld HDR pixels", name, w, h);
  }
  if (!rle) {
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++) rgbe_to_rgb(d + pos + 4 * i, rgb + 3 * i);
  } else {
    for (long y = 0; y < h; y++) {
      if (n - pos < 4) goto cut;
      const unsigned char *s = d + pos;
      if (s[0] != 2 || s[1] != 2 || (s[2] & 0x80) || ((long)s[2] << 8 | s[3]) != w) {
        free(rgb); free(scan);
        return err_set(err, VALO_ERR_PARSE, "%s: HDR scanline %ld of %ld does not start with the run-length mark for width %ld (byte %zu)",
                       name, y + 1, h, w, pos);
      }
      pos += 4;
      for (int k = 0; k < 4; k++) {
        long x = 0;
        while (x < w) {
          if (pos >= n) goto cut;
          unsigned c = d[pos++];
          int run = c > 128;
          long count = run ? (long)c - 128 : (long)c;
          if (count == 0 || count > w - x) {
            free(rgb); free(scan);
            return err_set(err, VALO_ERR_PARSE, "%s: HDR scanline %ld: a run of %ld where %ld pixels are left (byte %zu)",
                           name, y + 1, count, w - x, pos - 1);
          }
          if (run) {
            if (pos >= n) goto cut;
            unsigned char v = d[pos++];
            for (long z = 0; z < count; z++) scan[4 * (x + z) + k] = v;
          } else {
            if ((size_t)count > n - pos) goto cut;
            for (long z = 0; z < count; z++) scan[4 * (x + z) + k] = d[pos + (size_t)z];
            pos += (size_t)count;
          }
          x += count;
        }
      }
      for (long x = 0; x < w; x++) rgbe_to_rgb(scan + 4 * x, rgb + 3 * ((size_t)y * w + x));
      continue;
    cut:
      free(rgb); free(scan);
      return err_set(err, VALO_ERR_PARSE, "%s: the file ends inside HDR scanline %ld of %ld", name, y + 1, h);
    }
  }
  free(scan);
  out->w = (int)w;
  out->h = (int)h;
  out->rgb = rgb;
  return VALO_OK;
}

valo_status hdr_read(const char *path, image *out, valo_error *err) {
  out->w = out->h = 0;
  out->rgb = NULL;
  FILE *f = fopen(path, "rb");
  if (!f) return err_set(err, VALO_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
  long len = -1;
  if (!fseek(f, 0, SEEK_END)) len = ftell(f);
  if (len < 0 || fseek(f, 0, SEEK_SET)) { fclose(f); return err_set(err, VALO_ERR_IO, "%s: cannot read", path); }
  unsigned char *buf = malloc(len ? (size_t)len : 1);
  if (!buf) { fclose(f); return err_set(err, VALO_ERR_NOMEM, "%s: out of memory (%ld bytes)", path, len); }
  size_t got = fread(buf, 1, (size_t)len, f);
  fclose(f);
  valo_status st = got == (size_t)len ? hdr_decode(path, buf, (size_t)len, out, err)
                                      : err_set(err, VALO_ERR_IO, "%s: cannot read", path);
  free(buf);
  return st;
}
