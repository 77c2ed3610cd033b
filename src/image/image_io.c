/* image_io.c — see image_io.h. */
#include "image/image_io.h"
#include "image/hdr.h"
#include "core/atomicfile.h"
#include "core/error.h"
#include "core/memlimit.h"
#include "image/tonemap.h"
#include <OpenEXR/openexr.h>
#include <OpenEXR/ImfCRgbaFile.h>
#include <stb_image_write.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#define JPEG_QUALITY 95 /* stb_image_write's scale, 1-100 */

static void exr_quiet(exr_const_context_t ctxt, exr_result_t code, const char *msg);

static const char *ext_of(const char *path) {
  const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
  if (!dot || (slash && dot < slash)) return "";
  return dot + 1;
}

static valo_status commit_temp(const char *tmp, const char *path, valo_error *err) {
  if (atomic_commit(tmp, path) != 0) return err_set(err, VALO_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
  return VALO_OK;
}

static valo_status write_pfm(const char *tmp, int w, int h, const float *px) {
  FILE *f = fopen(tmp, "wb");
  if (!f) return VALO_ERR_IO;
  fprintf(f, "PF\n%d %d\n-1.0\n", w, h);
  int ok = 1;
  for (int y = h - 1; y >= 0 && ok; y--) ok = fwrite(&px[(size_t)y * w * 3], sizeof(float), (size_t)w * 3, f) == (size_t)w * 3;
  if (fclose(f) != 0) ok = 0;
  return ok ? VALO_OK : VALO_ERR_IO;
}

/* OpenEXR before 3.4.8 (Debian 12 has 3.1) stores the zlib stream of a chunk whose
 * compressed size equals its raw size, which readers then take for raw pixels
 * (openexr issue 2306): a noisy render came back with a garbled 16-line chunk. The
 * compressor is wrapped to store the raw bytes in that case, as the format asks. */
typedef struct zip_fix { exr_result_t (*orig)(exr_encode_pipeline_t *); } zip_fix;
static exr_result_t zip_checked(exr_encode_pipeline_t *e) {
  const zip_fix *z = e->encoding_user_data;
  exr_result_t rv = z->orig(e);
  if (rv == EXR_ERR_SUCCESS && e->compressed_bytes == e->packed_bytes && e->compressed_buffer != e->packed_buffer)
    memcpy(e->compressed_buffer, e->packed_buffer, e->packed_bytes);
  return rv;
}

static valo_status write_exr(const char *tmp, int w, int h, const float *px, char *msg, size_t msglen) {
  zip_fix zfix = {NULL};
  exr_context_t ctx = NULL;
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = exr_quiet;
  exr_result_t rv = exr_start_write(&ctx, tmp, EXR_WRITE_FILE_DIRECTLY, &init);
  int part = 0;
  if (rv == EXR_ERR_SUCCESS) rv = exr_add_part(ctx, "rgb", EXR_STORAGE_SCANLINE, &part);
  if (rv == EXR_ERR_SUCCESS) rv = exr_initialize_required_attr_simple(ctx, part, w, h, EXR_COMPRESSION_ZIP);
  const char *names[3] = {"B", "G", "R"};
  for (int c = 0; c < 3 && rv == EXR_ERR_SUCCESS; c++) {
    int r = exr_add_channel(ctx, part, names[c], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, 1, 1);
    if (r != EXR_ERR_SUCCESS) rv = r;
  }
  if (rv == EXR_ERR_SUCCESS) rv = exr_set_version(ctx, part, 1);
  if (rv == EXR_ERR_SUCCESS) rv = exr_write_header(ctx);
  int32_t lines = 1;
  if (rv == EXR_ERR_SUCCESS) rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
  exr_encode_pipeline_t enc;
  memset(&enc, 0, sizeof enc);
  int have_enc = 0;
  for (int y = 0; y < h && rv == EXR_ERR_SUCCESS; y += lines) {
    exr_chunk_info_t ci;
    rv = exr_write_scanline_chunk_info(ctx, part, y, &ci);
    if (rv != EXR_ERR_SUCCESS) break;
    if (!have_enc) { rv = exr_encoding_initialize(ctx, part, &ci, &enc); have_enc = rv == EXR_ERR_SUCCESS; }
    else rv = exr_encoding_update(ctx, part, &ci, &enc);
    if (rv != EXR_ERR_SUCCESS) break;
    for (int c = 0; c < enc.channel_count; c++) {
      const char *nm = enc.channels[c].channel_name;
      int off = nm[0] == 'R' ? 0 : (nm[0] == 'G' ? 1 : 2);
      enc.channels[c].user_pixel_stride = 3 * sizeof(float);
      enc.channels[c].user_line_stride = w * 3 * (int32_t)sizeof(float);
      enc.channels[c].user_bytes_per_element = sizeof(float);
      enc.channels[c].user_data_type = EXR_PIXEL_FLOAT;
      enc.channels[c].encode_from_ptr = (const uint8_t *)&px[(size_t)y * w * 3 + off];
    }
    if (y == 0) {
      rv = exr_encoding_choose_default_routines(ctx, part, &enc);
      if (rv == EXR_ERR_SUCCESS && enc.compress_fn) { zfix.orig = enc.compress_fn; enc.compress_fn = zip_checked; enc.encoding_user_data = &zfix; }
    }
    if (rv == EXR_ERR_SUCCESS) rv = exr_encoding_run(ctx, part, &enc);
  }
  if (have_enc) exr_encoding_destroy(ctx, &enc);
  if (rv != EXR_ERR_SUCCESS) snprintf(msg, msglen, "%s", exr_get_default_error_message(rv));
  exr_result_t fr = exr_finish(&ctx);
  if (rv == EXR_ERR_SUCCESS && fr != EXR_ERR_SUCCESS) { rv = fr; snprintf(msg, msglen, "%s", exr_get_default_error_message(fr)); }
  return rv == EXR_ERR_SUCCESS ? VALO_OK : VALO_ERR_IO;
}

void image_to_srgb8(int w, int h, const float *px, const valo_output_options *o, unsigned char *out) {
  float scale = exp2f(o ? o->exposure : 0);
  tonemap_kind k = TONEMAP_CLAMP;
  if (o && tonemap_parse(o->tonemap, &k)) k = TONEMAP_CLAMP;
  for (size_t i = 0; i < (size_t)w * h; i++) {
    rgb c = tonemap_apply(k, c3(px[3 * i] * scale, px[3 * i + 1] * scale, px[3 * i + 2] * scale));
    out[3 * i] = (unsigned char)lrintf(srgb_encode(c.r) * 255.0f);
    out[3 * i + 1] = (unsigned char)lrintf(srgb_encode(c.g) * 255.0f);
    out[3 * i + 2] = (unsigned char)lrintf(srgb_encode(c.b) * 255.0f);
  }
}

valo_status image_write(const char *path, int w, int h, const float *px, const valo_output_options *o, valo_error *err) {
  const char *ext = ext_of(path);
  /* 0 EXR, 1 PFM, 2 PNG, 3 JPEG, 4 Radiance HDR */
  int kind = !strcasecmp(ext, "exr") ? 0 : !strcasecmp(ext, "pfm") ? 1 : !strcasecmp(ext, "png") ? 2
           : !strcasecmp(ext, "jpg") || !strcasecmp(ext, "jpeg") ? 3 : !strcasecmp(ext, "hdr") ? 4 : -1;
  if (kind < 0)
    return err_set(err, VALO_ERR_UNSUPPORTED, "%s: unknown output format \".%s\" (use .exr, .pfm, .hdr, .png or .jpg)", path, ext);
  char tmp[4200];
  if (atomic_temp_name(path, tmp, sizeof tmp)) return err_set(err, VALO_ERR_INVALID, "%s: name too long", path);
  valo_status st = VALO_OK;
  char msg[256] = "";
  if (kind == 0) st = write_exr(tmp, w, h, px, msg, sizeof msg);
  else if (kind == 1) st = write_pfm(tmp, w, h, px);
  else if (kind == 4) st = stbi_write_hdr(tmp, w, h, 3, px) ? VALO_OK : VALO_ERR_IO; /* RGBE: 8-bit mantissas */
  else {
    unsigned char *bytes = malloc((size_t)w * h * 3);
    float *disp = NULL;
    if (o && o->bloom > 0) { /* bloom works on the display copy; linear files stay untouched */
      disp = malloc((size_t)w * h * 3 * sizeof(float));
      if (disp) {
        float ex = exp2f(o->exposure);
        for (size_t i = 0; i < (size_t)w * h * 3; i++) disp[i] = px[i] * ex;
        float radius = o->bloom_radius > 0 ? o->bloom_radius : 0.01f * (float)w;
        if (bloom_apply(w, h, disp, o->bloom_threshold, o->bloom, radius)) { free(disp); disp = NULL; }
      }
      if (!disp) { free(bytes); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
    }
    if (!bytes) { free(disp); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
    if (disp) {
      valo_output_options o2 = *o;
      o2.exposure = 0; /* already applied */
      image_to_srgb8(w, h, disp, &o2, bytes);
      free(disp);
    } else {
      image_to_srgb8(w, h, px, o, bytes);
    }
    int ok = kind == 2 ? stbi_write_png(tmp, w, h, 3, bytes, w * 3) : stbi_write_jpg(tmp, w, h, 3, bytes, JPEG_QUALITY);
    st = ok ? VALO_OK : VALO_ERR_IO;
    free(bytes);
  }
  if (st) {
    int e = errno;
    remove(tmp);
    return err_set(err, VALO_ERR_IO, "%s: cannot write: %s", path, msg[0] ? msg : strerror(e));
  }
  return commit_temp(tmp, path, err);
}

void image_free(image *im) { free(im->rgb); im->rgb = NULL; im->w = im->h = 0; }

static valo_status read_pfm(const char *path, image *out, valo_error *err) {
  FILE *f = fopen(path, "rb");
  if (!f) return err_set(err, VALO_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
  char magic[3] = {0};
  int w = 0, h = 0;
  float scale = 0;
  if (fscanf(f, "%2s %d %d %f", magic, &w, &h, &scale) != 4 || strcmp(magic, "PF") || w <= 0 || h <= 0 || w > 65536 || h > 65536 || scale >= 0) {
    fclose(f);
    return err_set(err, VALO_ERR_PARSE, "%s: not a little-endian RGB PFM file", path);
  }
  fgetc(f);
  valo_status mst = mem_check_pixels((uint64_t)w, (uint64_t)h, 12, path, err);
  if (mst) { fclose(f); return mst; }
  /* the pixels must be in the file before they are allocated (a 19-byte file claimed 5 GB) */
  long at = ftell(f), end = at >= 0 && fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
  if (end < 0 || fseek(f, at, SEEK_SET) || (uint64_t)(end - at) < (uint64_t)w * (uint64_t)h * 12u) {
    fclose(f);
    return err_set(err, VALO_ERR_PARSE, "%s: truncated PFM: %d x %d pixels need %llu bytes, the file holds %ld after its header", path, w, h,
                   (unsigned long long)w * (unsigned long long)h * 12u, end < 0 ? 0L : end - at);
  }
  out->w = w; out->h = h;
  out->rgb = malloc((size_t)w * h * 3 * sizeof(float));
  if (!out->rgb) { fclose(f); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  for (int y = h - 1; y >= 0; y--)
    if (fread(&out->rgb[(size_t)y * w * 3], sizeof(float), (size_t)w * 3, f) != (size_t)w * 3) {
      fclose(f); image_free(out);
      return err_set(err, VALO_ERR_PARSE, "%s: truncated PFM", path);
    }
  fclose(f);
  return VALO_OK;
}

/* OpenEXRCore reports errors through its context; valo reports them through valo_error. */
static void exr_quiet(exr_const_context_t ctxt, exr_result_t code, const char *msg) { (void)ctxt; (void)code; (void)msg; }

/* Debian 12's OpenEXRCore 3.1 cannot decompress DWAA/DWAB; OpenEXR's own C interface
 * (ImfCRgbaFile.h, same package) can. Used only when the core decoder says so. */
static valo_status read_exr_rgba(const char *path, image *out, valo_error *err) {
  ImfInputFile *in = ImfOpenInputFile(path);
  if (!in) return err_set(err, VALO_ERR_PARSE, "%s: cannot read EXR: %s", path, ImfErrorMessage());
  int xmin, ymin, xmax, ymax;
  ImfHeaderDataWindow(ImfInputHeader(in), &xmin, &ymin, &xmax, &ymax);
  int w = xmax - xmin + 1, h = ymax - ymin + 1;
  if (w <= 0 || h <= 0 || w > 65536 || h > 65536) { ImfCloseInputFile(in); return err_set(err, VALO_ERR_PARSE, "%s: bad data window", path); }
  ImfRgba *buf = malloc((size_t)w * h * sizeof *buf);
  float *rgbf = malloc((size_t)w * h * 3 * sizeof(float));
  if (!buf || !rgbf) { free(buf); free(rgbf); ImfCloseInputFile(in); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  /* The frame buffer base is addressed by absolute pixel coordinates. */
  ImfRgba *base = buf - xmin - (ptrdiff_t)ymin * w;
  int ok = ImfInputSetFrameBuffer(in, base, 1, (size_t)w) && ImfInputReadPixels(in, ymin, ymax);
  ImfCloseInputFile(in);
  if (!ok) { free(buf); free(rgbf); return err_set(err, VALO_ERR_PARSE, "%s: cannot decode EXR: %s", path, ImfErrorMessage()); }
  for (size_t i = 0; i < (size_t)w * h; i++) {
    rgbf[3 * i] = ImfHalfToFloat(buf[i].r);
    rgbf[3 * i + 1] = ImfHalfToFloat(buf[i].g);
    rgbf[3 * i + 2] = ImfHalfToFloat(buf[i].b);
  }
  free(buf);
  out->w = w; out->h = h; out->rgb = rgbf;
  return VALO_OK;
}

/* The layer of EXR channel `nm` ("diffuse.R" -> "diffuse", "R" -> "") into buf; returns
 * its colour offset (R 0, G 1, B 2, Y 3) or -1 for other channels. */
static int exr_channel(const char *nm, char *layer, size_t cap) {
  const char *dot = strrchr(nm, '.');
  const char *base = dot ? dot + 1 : nm;
  size_t n = dot ? (size_t)(dot - nm) : 0;
  if (n >= cap) n = cap - 1;
  memcpy(layer, nm, n);
  layer[n] = 0;
  return !strcmp(base, "R") ? 0 : !strcmp(base, "G") ? 1 : !strcmp(base, "B") ? 2 : !strcmp(base, "Y") ? 3 : -1;
}

/* The colour layer read from part 0: the unnamed one (R, G, B or Y) if present, else the
 * first named layer with colour channels; a warning names the layers left out and any
 * further parts. Fills `use` and sets *has_g when that layer has a G channel. */
static void exr_pick_layer(exr_context_t ctx, const char *path, char *use, size_t cap, int *has_g) {
  const exr_attr_chlist_t *cl = NULL;
  char layer[256], others[512] = "";
  int found = 0;
  use[0] = 0;
  *has_g = 0;
  if (exr_get_channels(ctx, 0, &cl) != EXR_ERR_SUCCESS) return;
  for (int pass = 0; pass < 2 && !found; pass++)
    for (int i = 0; i < cl->num_channels; i++) {
      if (exr_channel(cl->entries[i].name.str, layer, sizeof layer) < 0) continue;
      if (pass == 0 && layer[0]) continue; /* first look for the unnamed layer */
      snprintf(use, cap, "%s", layer);
      found = 1;
      break;
    }
  size_t n = 0;
  for (int i = 0; i < cl->num_channels; i++) {
    int off = exr_channel(cl->entries[i].name.str, layer, sizeof layer);
    if (off < 0) continue;
    if (!strcmp(layer, use)) { if (off == 1) *has_g = 1; continue; }
    char quoted[300];
    snprintf(quoted, sizeof quoted, "'%s'", layer);
    if (strstr(others, quoted) || n >= sizeof others) continue;
    n += (size_t)snprintf(others + n, sizeof others - n, "%s%s", n ? ", " : "", quoted);
  }
  if (others[0]) log_warning("%s: EXR with several colour layers: reading %s%s%s, ignoring %s", path, use[0] ? "'" : "the unnamed layer", use, use[0] ? "'" : "", others);
  int parts = 1;
  if (exr_get_count(ctx, &parts) == EXR_ERR_SUCCESS && parts > 1) log_warning("%s: EXR with %d parts: reading the first only", path, parts);
}

static valo_status read_exr(const char *path, image *out, valo_error *err) {
  exr_context_t ctx = NULL;
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.flags |= EXR_CONTEXT_FLAG_SILENT_HEADER_PARSE;
  init.error_handler_fn = exr_quiet;
  exr_result_t rv = exr_start_read(&ctx, path, &init);
  if (rv != EXR_ERR_SUCCESS) return err_set(err, VALO_ERR_PARSE, "%s: cannot read EXR: %s", path, exr_get_default_error_message(rv));
  valo_status st = VALO_OK;
  exr_attr_box2i_t dw;
  exr_storage_t storage;
  float *buf = NULL;
  exr_decode_pipeline_t dec;
  memset(&dec, 0, sizeof dec);
  int have_dec = 0;
  if (exr_get_storage(ctx, 0, &storage) != EXR_ERR_SUCCESS || storage != EXR_STORAGE_SCANLINE) {
    st = err_set(err, VALO_ERR_UNSUPPORTED, "%s: only scanline EXR images are supported", path);
    goto done;
  }
  exr_get_data_window(ctx, 0, &dw);
  int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
  if (w <= 0 || h <= 0 || w > 65536 || h > 65536) { st = err_set(err, VALO_ERR_PARSE, "%s: bad data window", path); goto done; }
  if ((st = mem_check_pixels((uint64_t)w, (uint64_t)h, 12, path, err))) goto done;
  buf = calloc((size_t)w * h * 3, sizeof(float));
  if (!buf) { st = err_set(err, VALO_ERR_NOMEM, "out of memory"); goto done; }
  char use[256];
  int has_g = 0;
  exr_pick_layer(ctx, path, use, sizeof use, &has_g);
  int32_t lines = 1;
  exr_get_scanlines_per_chunk(ctx, 0, &lines);
  for (int y = dw.min.y; y <= dw.max.y; y += lines) {
    exr_chunk_info_t ci;
    rv = exr_read_scanline_chunk_info(ctx, 0, y, &ci);
    if (rv == EXR_ERR_SUCCESS) {
      if (!have_dec) { rv = exr_decoding_initialize(ctx, 0, &ci, &dec); have_dec = rv == EXR_ERR_SUCCESS; }
      else rv = exr_decoding_update(ctx, 0, &ci, &dec);
    }
    if (rv != EXR_ERR_SUCCESS) break;
    int row = ci.start_y - dw.min.y;
    for (int c = 0; c < dec.channel_count; c++) {
      char layer[256];
      int off = exr_channel(dec.channels[c].channel_name, layer, sizeof layer);
      if (off < 0 || strcmp(layer, use) || dec.channels[c].height == 0) { dec.channels[c].decode_to_ptr = NULL; continue; }
      if (off == 3) off = 0; /* luminance: fill R, then copy below */
      dec.channels[c].user_pixel_stride = 3 * sizeof(float);
      dec.channels[c].user_line_stride = w * 3 * (int32_t)sizeof(float);
      dec.channels[c].user_bytes_per_element = sizeof(float);
      dec.channels[c].user_data_type = EXR_PIXEL_FLOAT;
      dec.channels[c].decode_to_ptr = (uint8_t *)&buf[((size_t)row * w) * 3 + off];
    }
    rv = exr_decoding_choose_default_routines(ctx, 0, &dec);
    if (rv == EXR_ERR_SUCCESS) rv = exr_decoding_run(ctx, 0, &dec);
    if (rv != EXR_ERR_SUCCESS) break;
  }
  if (rv == EXR_ERR_FEATURE_NOT_IMPLEMENTED) { st = VALO_ERR_UNSUPPORTED; goto done; }
  if (rv != EXR_ERR_SUCCESS) { st = err_set(err, VALO_ERR_PARSE, "%s: cannot decode EXR: %s", path, exr_get_default_error_message(rv)); goto done; }
  if (!has_g) /* a luminance (Y) or R-only image: grey */
    for (size_t i = 0; i < (size_t)w * h; i++) buf[3 * i + 1] = buf[3 * i + 2] = buf[3 * i];
  out->w = w; out->h = h; out->rgb = buf; buf = NULL;
done:
  if (have_dec) exr_decoding_destroy(ctx, &dec);
  free(buf);
  exr_finish(&ctx);
  if (st == VALO_ERR_UNSUPPORTED) return read_exr_rgba(path, out, err);
  return st;
}

int image_is_float_file(const char *path) {
  const char *ext = ext_of(path);
  return !strcasecmp(ext, "exr") || !strcasecmp(ext, "pfm") || !strcasecmp(ext, "hdr");
}

valo_status image_read(const char *path, image *out, valo_error *err) {
  out->w = out->h = 0; out->rgb = NULL;
  const char *ext = ext_of(path);
  if (!strcasecmp(ext, "exr")) return read_exr(path, out, err);
  if (!strcasecmp(ext, "pfm")) return read_pfm(path, out, err);
  if (!strcasecmp(ext, "hdr")) return hdr_read(path, out, err);
  if (!*ext) return err_set(err, VALO_ERR_UNSUPPORTED, "%s: no file extension; valo reads .exr, .hdr and .pfm images here", path);
  return err_set(err, VALO_ERR_UNSUPPORTED, "%s: cannot read \".%s\" images (exr, hdr, pfm)", path, ext);
}
