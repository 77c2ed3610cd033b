/* test_image.c — image files and display transforms: EXR and PFM round-trips are exact;
 * a ZIP chunk that compresses to its own size survives (OpenEXR issue 2306);
 * PNG encodes sRGB (0 -> 0, 1 -> 255, 0.5 -> 188); the tone curves (log, Reinhard, ACES)
 * take known values and are monotone; writes are atomic (no temporary file left, an
 * existing file replaced whole); real EXRs (half-float DWAB, PIZ) decode. */
#include "harness.h"
#include "image/image_io.h"
#include "image/tonemap.h"
#include "image/denoise.h"
#include "image/svgf.h"
#include "core/rng.h"
#include <OpenEXR/openexr.h>
#include <OpenEXR/ImfCRgbaFile.h>
#include <stb_image.h>
#include <dirent.h>
#include <math.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <stdlib.h>
#include <string.h>

static float *test_pattern(int w, int h) {
  float *p = malloc((size_t)w * h * 3 * sizeof(float));
  for (int i = 0; i < w * h * 3; i++) p[i] = (float)((i * 7919) % 1000) * 0.013f + (i % 3) * 1e-3f;
  return p;
}

static int roundtrip(const char *ext) {
  int w = 37, h = 19;
  float *p = test_pattern(w, h);
  char path[1200];
  snprintf(path, sizeof path, "%s/rt.%s", scratch_dir(), ext);
  valo_error err;
  CHECK(image_write(path, w, h, p, NULL, &err) == VALO_OK, "%s", err.message);
  image im;
  CHECK(image_read(path, &im, &err) == VALO_OK, "%s", err.message);
  CHECK(im.w == w && im.h == h, "size %dx%d", im.w, im.h);
  CHECK(memcmp(im.rgb, p, (size_t)w * h * 3 * sizeof(float)) == 0, "%s round trip is not exact", ext);
  image_free(&im);
  free(p);
  return 0;
}
static int exr_roundtrip(void) { return roundtrip("exr"); }

/* 16 rows of a noisy restir-gi render whose ZIP chunk compresses to exactly its raw size:
 * OpenEXR 3.1 stores the zlib stream there, which every reader then takes for raw pixels
 * (openexr issue 2306; image_io.c stores the raw bytes). The EXR must come back exact. */
static int exr_zip_equal_size(void) {
  image src;
  valo_error err;
  CHECK(image_read(VALO_SOURCE_DIR "/tests/data/exr-zip-equal-size.pfm", &src, &err) == VALO_OK, "%s", err.message);
  char path[1200];
  snprintf(path, sizeof path, "%s/zip-equal.exr", scratch_dir());
  CHECK(image_write(path, src.w, src.h, src.rgb, NULL, &err) == VALO_OK, "%s", err.message);
  image im;
  CHECK(image_read(path, &im, &err) == VALO_OK, "%s", err.message);
  size_t bad = 0;
  for (size_t i = 0; i < (size_t)src.w * src.h * 3; i++) bad += im.rgb[i] != src.rgb[i];
  CHECK(bad == 0, "%zu of %d values differ after the EXR round trip", bad, src.w * src.h * 3);
  image_free(&im);
  image_free(&src);
  return 0;
}
static int pfm_roundtrip(void) { return roundtrip("pfm"); }

static int srgb_png(void) {
  float px[9] = {0, 0, 0, 1, 1, 1, 0.5f, 0.5f, 0.5f};
  unsigned char out[9];
  valo_output_options o;
  valo_output_options_init(&o);
  image_to_srgb8(3, 1, px, &o, out);
  CHECK(out[0] == 0 && out[3] == 255 && out[6] == 188, "sRGB bytes %d %d %d", out[0], out[3], out[6]);
  o.exposure = 1; /* 0.5 * 2 = 1 */
  image_to_srgb8(3, 1, px, &o, out);
  CHECK(out[6] == 255, "exposure +1 of 0.5 gives %d", out[6]);
  char path[1200];
  snprintf(path, sizeof path, "%s/x.png", scratch_dir());
  valo_error err;
  CHECK(image_write(path, 3, 1, px, NULL, &err) == VALO_OK, "%s", err.message);
  FILE *f = fopen(path, "rb");
  unsigned char sig[8] = {0};
  CHECK(f && fread(sig, 1, 8, f) == 8, "cannot read png");
  fclose(f);
  CHECK(sig[1] == 'P' && sig[2] == 'N' && sig[3] == 'G', "not a PNG");
  return 0;
}

/* .hdr: Radiance RGBE read back by valo's reader, each value within the shared
 * exponent's precision (2^-7 of the pixel's largest channel); .jpg: a JPEG that stb
 * decodes to the size written and, for flat linear 0.5, the sRGB byte 188 (within 1). */
static int hdr_jpeg_write(void) {
  int w = 37, h = 19;
  float *p = test_pattern(w, h);
  char path[1200];
  valo_error err;
  snprintf(path, sizeof path, "%s/rt.hdr", scratch_dir());
  CHECK(image_write(path, w, h, p, NULL, &err) == VALO_OK, "%s", err.message);
  image im;
  CHECK(image_read(path, &im, &err) == VALO_OK, "%s", err.message);
  CHECK(im.w == w && im.h == h, "size %dx%d", im.w, im.h);
  for (int i = 0; i < w * h; i++) {
    const float *a = p + 3 * i, *b = im.rgb + 3 * i;
    float m = fmaxf(a[0], fmaxf(a[1], a[2]));
    for (int c = 0; c < 3; c++) CHECK(fabsf(a[c] - b[c]) <= m / 128, "pixel %d channel %d: %g written, %g read", i, c, a[c], b[c]);
  }
  image_free(&im);
  free(p);
  float grey[16 * 8 * 3];
  for (int i = 0; i < 16 * 8 * 3; i++) grey[i] = 0.5f;
  snprintf(path, sizeof path, "%s/grey.jpg", scratch_dir());
  CHECK(image_write(path, 16, 8, grey, NULL, &err) == VALO_OK, "%s", err.message);
  int jw = 0, jh = 0, n = 0;
  unsigned char *j = stbi_load(path, &jw, &jh, &n, 3);
  CHECK(j && jw == 16 && jh == 8, "the JPEG decodes to %dx%d", jw, jh);
  for (int i = 0; i < 16 * 8 * 3; i++) CHECK(abs((int)j[i] - 188) <= 1, "byte %d is %d, not 188", i, j[i]);
  stbi_image_free(j);
  return 0;
}

static int tone_curves(void) {
  tonemap_kind k;
  CHECK(tonemap_parse("reinhard", &k) == 0, "reinhard");
  rgb g = tonemap_apply(k, c3(1, 1, 1));
  CHECK(fabsf(g.g - 0.5f) < 1e-6f, "reinhard(1) = %g", g.g);
  CHECK(tonemap_parse("log", &k) == 0, "log");
  g = tonemap_apply(k, c3(expf(1) - 1, 0, 0));
  CHECK(fabsf(g.r - 1) < 1e-6f, "log(e - 1) -> %g", g.r);
  CHECK(tonemap_parse("aces", &k) == 0, "aces");
  CHECK(tonemap_parse("nope", &k) != 0, "unknown name accepted");
  const char *names[3] = {"log", "reinhard", "aces"};
  for (int n = 0; n < 3; n++) {
    tonemap_parse(names[n], &k);
    float prev = -1;
    for (float v = 0; v < 100; v = v * 1.3f + 0.01f) {
      float y = tonemap_apply(k, c3(v, v, v)).g;
      CHECK(y >= prev && isfinite(y), "%s not monotone at %g", names[n], v);
      prev = y;
    }
  }
  return 0;
}

static int atomic_write(void) {
  char path[1200];
  snprintf(path, sizeof path, "%s/atomic.exr", scratch_dir());
  float *a = test_pattern(64, 64), b[3] = {1, 2, 3};
  valo_error err;
  CHECK(image_write(path, 64, 64, a, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(image_write(path, 1, 1, b, NULL, &err) == VALO_OK, "%s", err.message);
  image im;
  CHECK(image_read(path, &im, &err) == VALO_OK, "%s", err.message);
  CHECK(im.w == 1 && im.rgb[2] == 3, "the second write did not replace the first whole");
  image_free(&im);
  free(a);
  DIR *d = opendir(scratch_dir());
  struct dirent *e;
  while ((e = readdir(d))) CHECK(!strstr(e->d_name, ".tmp"), "temporary file %s left behind", e->d_name);
  closedir(d);
  /* A failed write leaves nothing and says why. */
  CHECK(image_write("/no/such/dir/x.exr", 1, 1, b, NULL, &err) != VALO_OK, "write to a missing folder succeeded");
  CHECK(strstr(err.message, "/no/such/dir/x.exr") != NULL, "message: %s", err.message);
  /* A symbolic link is followed: the file it names is replaced (made, when it dangles) and
   * the link stays a link. */
  char real[1200], link[1200], made[1200], dangling[1200];
  snprintf(real, sizeof real, "%s/real.pfm", scratch_dir());
  snprintf(link, sizeof link, "%s/link.pfm", scratch_dir());
  snprintf(made, sizeof made, "%s/made.pfm", scratch_dir());
  snprintf(dangling, sizeof dangling, "%s/dangling.pfm", scratch_dir());
  CHECK(image_write(real, 1, 1, b, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(symlink("real.pfm", link) == 0 && symlink("made.pfm", dangling) == 0, "symlink");
  float c[3] = {4, 5, 6};
  CHECK(image_write(link, 1, 1, c, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(image_write(dangling, 1, 1, c, NULL, &err) == VALO_OK, "%s", err.message);
  struct stat st;
  CHECK(lstat(link, &st) == 0 && S_ISLNK(st.st_mode) && lstat(dangling, &st) == 0 && S_ISLNK(st.st_mode),
        "a symbolic link was replaced by a file");
  const char *through[2] = {real, made};
  for (int i = 0; i < 2; i++) {
    CHECK(image_read(through[i], &im, &err) == VALO_OK, "%s", err.message);
    CHECK(im.rgb[0] == 4 && im.rgb[2] == 6, "%s does not hold what was written through its link", through[i]);
    image_free(&im);
  }
  /* A FIFO is written in place, not replaced: a child process reads it into a file. */
  char fifo[1200], copy[1200];
  snprintf(fifo, sizeof fifo, "%s/fifo.pfm", scratch_dir());
  snprintf(copy, sizeof copy, "%s/fifo-copy.pfm", scratch_dir());
  CHECK(mkfifo(fifo, 0600) == 0, "mkfifo");
  pid_t pid = fork();
  if (pid == 0) {
    FILE *in = fopen(fifo, "rb"), *out = fopen(copy, "wb");
    char buf[4096];
    size_t k;
    while (in && out && (k = fread(buf, 1, sizeof buf, in)) > 0) fwrite(buf, 1, k, out);
    _exit(in && out && fclose(out) == 0 ? 0 : 1);
  }
  CHECK(pid > 0, "fork");
  valo_status ws = image_write(fifo, 1, 1, c, NULL, &err);
  int status = 0;
  waitpid(pid, &status, 0);
  CHECK(ws == VALO_OK, "%s", err.message);
  CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0, "the FIFO's reader failed");
  CHECK(lstat(fifo, &st) == 0 && S_ISFIFO(st.st_mode), "the FIFO was replaced by a file");
  CHECK(image_read(copy, &im, &err) == VALO_OK, "%s", err.message);
  CHECK(im.w == 1 && im.rgb[1] == 5, "the FIFO's reader did not get the image");
  image_free(&im);
  return 0;
}

static int real_exr_files(void) {
  const char *dwab = shared_file("scenes/envmaps/venice.exr"), *piz = shared_file("scenes/envmaps/piz_compressed.exr");
  if (!dwab || !piz) return TEST_SKIP;
  const char *files[2] = {dwab, piz};
  for (int i = 0; i < 2; i++) {
    image im;
    valo_error err;
    CHECK(image_read(files[i], &im, &err) == VALO_OK, "%s", err.message);
    double sum = 0;
    for (int k = 0; k < im.w * im.h * 3; k++) { CHECK(isfinite(im.rgb[k]), "non-finite texel"); sum += im.rgb[k]; }
    fprintf(stderr, "%s: %dx%d, mean %.4f\n", files[i], im.w, im.h, sum / (im.w * im.h * 3));
    CHECK(im.w == 2 * im.h, "an equirectangular map is 2:1, got %dx%d", im.w, im.h);
    CHECK(sum > 0, "all black");
    image_free(&im);
  }
  return 0;
}

/* Writes a w x h EXR (no compression) whose channels `names` hold the constants `vals`,
 * through OpenEXRCore directly (valo's writer makes only R, G, B). 0 on success. */
static int write_layered_exr(const char *path, int w, int h, int n, const char *const *names, const float *vals) {
  exr_context_t ctx = NULL;
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  int part = 0;
  exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
  if (rv == EXR_ERR_SUCCESS) rv = exr_add_part(ctx, "layers", EXR_STORAGE_SCANLINE, &part);
  if (rv == EXR_ERR_SUCCESS) rv = exr_initialize_required_attr_simple(ctx, part, w, h, EXR_COMPRESSION_NONE);
  for (int c = 0; c < n && rv == EXR_ERR_SUCCESS; c++) rv = exr_add_channel(ctx, part, names[c], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, 1, 1);
  if (rv == EXR_ERR_SUCCESS) rv = exr_set_version(ctx, part, 1);
  if (rv == EXR_ERR_SUCCESS) rv = exr_write_header(ctx);
  float *planes = malloc((size_t)n * w * h * sizeof(float));
  for (int c = 0; c < n; c++)
    for (int i = 0; i < w * h; i++) planes[(size_t)c * w * h + i] = vals[c];
  exr_encode_pipeline_t enc;
  memset(&enc, 0, sizeof enc);
  int have = 0;
  for (int y = 0; y < h && rv == EXR_ERR_SUCCESS; y++) { /* uncompressed: one line per chunk */
    exr_chunk_info_t ci;
    rv = exr_write_scanline_chunk_info(ctx, part, y, &ci);
    if (rv == EXR_ERR_SUCCESS) {
      if (!have) { rv = exr_encoding_initialize(ctx, part, &ci, &enc); have = rv == EXR_ERR_SUCCESS; }
      else rv = exr_encoding_update(ctx, part, &ci, &enc);
    }
    for (int c = 0; c < enc.channel_count && rv == EXR_ERR_SUCCESS; c++) {
      int k = 0;
      while (k < n && strcmp(names[k], enc.channels[c].channel_name)) k++;
      enc.channels[c].user_pixel_stride = sizeof(float);
      enc.channels[c].user_line_stride = w * (int32_t)sizeof(float);
      enc.channels[c].user_bytes_per_element = sizeof(float);
      enc.channels[c].user_data_type = EXR_PIXEL_FLOAT;
      enc.channels[c].encode_from_ptr = (const uint8_t *)&planes[(size_t)k * w * h + (size_t)y * w];
    }
    if (rv == EXR_ERR_SUCCESS && y == 0) rv = exr_encoding_choose_default_routines(ctx, part, &enc);
    if (rv == EXR_ERR_SUCCESS) rv = exr_encoding_run(ctx, part, &enc);
  }
  if (have) exr_encoding_destroy(ctx, &enc);
  exr_result_t fr = exr_finish(&ctx);
  free(planes);
  return rv == EXR_ERR_SUCCESS && fr == EXR_ERR_SUCCESS ? 0 : -1;
}

/* An EXR with several colour layers is read as one layer, not a mix of all of them, and
 * the others are named in a warning: the unnamed layer when there is one, else the first. */
static int exr_layers(void) {
  static const char *const named[6] = {"diffuse.B", "diffuse.G", "diffuse.R", "specular.B", "specular.G", "specular.R"};
  static const char *const mixed[6] = {"B", "G", "R", "albedo.B", "albedo.G", "albedo.R"};
  const float vals[6] = {0.3f, 0.2f, 0.1f, 0.9f, 0.8f, 0.7f};
  const char *const *sets[2] = {named, mixed};
  const char *ignored[2] = {"'specular'", "'albedo'"};
  for (int k = 0; k < 2; k++) {
    char path[1200];
    snprintf(path, sizeof path, "%s/layers%d.exr", scratch_dir(), k);
    CHECK(write_layered_exr(path, 4, 3, 6, sets[k], vals) == 0, "could not write %s", path);
    image im;
    valo_error err;
    warnings_capture(1);
    valo_status st = image_read(path, &im, &err);
    char said[1024];
    snprintf(said, sizeof said, "%s", warnings_text());
    warnings_capture(0);
    CHECK(st == VALO_OK, "%s", err.message);
    for (int i = 0; i < 12; i++)
      CHECK(im.rgb[3 * i] == 0.1f && im.rgb[3 * i + 1] == 0.2f && im.rgb[3 * i + 2] == 0.3f, "pixel %d is (%g %g %g), expected the first layer's (0.1 0.2 0.3)", i,
            im.rgb[3 * i], im.rgb[3 * i + 1], im.rgb[3 * i + 2]);
    image_free(&im);
    CHECK(strstr(said, "several colour layers") && strstr(said, ignored[k]), "no warning naming the ignored layer %s: \"%s\"", ignored[k], said);
  }
  return 0;
}

/* Writers checked by readers valo does not use for them: valo's EXR through OpenEXR's
 * RGBA interface (ImfCRgbaFile, half precision), its PNG through stb_image (bytes against
 * the sRGB formula computed here); and a PFM written byte by byte here, bottom row first
 * with a negative scale (little-endian), read by valo. */
static int independent_readers(void) {
  int w = 5, h = 3;
  float *p = test_pattern(w, h);
  for (int i = 0; i < w * h * 3; i++) p[i] *= 0.08f; /* 0 .. 1.04: some clip in the PNG */
  char exr[1200], png[1200], pfm[1200];
  snprintf(exr, sizeof exr, "%s/ind.exr", scratch_dir());
  snprintf(png, sizeof png, "%s/ind.png", scratch_dir());
  snprintf(pfm, sizeof pfm, "%s/hand.pfm", scratch_dir());
  valo_error err;
  CHECK(image_write(exr, w, h, p, NULL, &err) == VALO_OK, "%s", err.message);
  CHECK(image_write(png, w, h, p, NULL, &err) == VALO_OK, "%s", err.message);
  ImfInputFile *in = ImfOpenInputFile(exr);
  CHECK(in, "OpenEXR cannot open valo's EXR: %s", ImfErrorMessage());
  int x0, y0, x1, y1;
  ImfHeaderDataWindow(ImfInputHeader(in), &x0, &y0, &x1, &y1);
  CHECK(x0 == 0 && y0 == 0 && x1 == w - 1 && y1 == h - 1, "data window (%d %d)-(%d %d)", x0, y0, x1, y1);
  ImfRgba px[15];
  CHECK(ImfInputSetFrameBuffer(in, px, 1, (size_t)w) && ImfInputReadPixels(in, 0, h - 1), "%s", ImfErrorMessage());
  ImfCloseInputFile(in);
  for (int i = 0; i < w * h; i++) {
    float got[3] = {ImfHalfToFloat(px[i].r), ImfHalfToFloat(px[i].g), ImfHalfToFloat(px[i].b)};
    for (int c = 0; c < 3; c++) CHECK(fabsf(got[c] - p[3 * i + c]) <= 1e-3f * fmaxf(p[3 * i + c], 1e-2f), "EXR pixel %d channel %d: %g, wrote %g", i, c, got[c], p[3 * i + c]);
    CHECK(ImfHalfToFloat(px[i].a) == 1.0f, "EXR alpha %g (no alpha channel reads as 1)", ImfHalfToFloat(px[i].a));
  }
  int pw, ph, pn;
  unsigned char *bytes = stbi_load(png, &pw, &ph, &pn, 3);
  CHECK(bytes && pw == w && ph == h, "stb cannot read valo's PNG");
  for (int i = 0; i < w * h * 3; i++) {
    double v = fmin(fmax(p[i], 0), 1), e = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1 / 2.4) - 0.055;
    CHECK(abs(bytes[i] - (int)lrint(e * 255)) <= 0, "PNG byte %d: %d, expected %ld", i, bytes[i], lrint(e * 255));
  }
  stbi_image_free(bytes);
  /* PFM by hand: 2x2, rows bottom to top, little-endian floats */
  FILE *f = fopen(pfm, "wb");
  CHECK(f, "cannot write %s", pfm);
  fprintf(f, "PF\n2 2\n-1.0\n");
  const float bottom_top[12] = {1, 2, 3, 4, 5, 6, /* bottom row: (0,1) (1,1) */ 7, 8, 9, 10, 11, 12};
  for (int i = 0; i < 12; i++) {
    uint32_t u;
    memcpy(&u, &bottom_top[i], 4);
    unsigned char le[4] = {(unsigned char)u, (unsigned char)(u >> 8), (unsigned char)(u >> 16), (unsigned char)(u >> 24)};
    fwrite(le, 1, 4, f);
  }
  fclose(f);
  image im;
  CHECK(image_read(pfm, &im, &err) == VALO_OK, "%s", err.message);
  CHECK(im.w == 2 && im.h == 2, "PFM size %dx%d", im.w, im.h);
  const float top_first[12] = {7, 8, 9, 10, 11, 12, 1, 2, 3, 4, 5, 6};
  for (int i = 0; i < 12; i++) CHECK(im.rgb[i] == top_first[i], "PFM value %d: %g, expected %g (top row first)", i, im.rgb[i], top_first[i]);
  image_free(&im);
  free(p);
  return 0;
}

/* Bloom spreads only what exceeds the threshold, by a normalised Gaussian: a single
 * pixel of 101 on black adds 100 x strength in total, symmetrically, and leaves pixels
 * below the threshold alone when nothing bright is near. */
static int bloom(void) {
  int w = 41, h = 41;
  float *px = calloc((size_t)w * h * 3, sizeof(float));
  for (int c = 0; c < 3; c++) px[3 * (20 * w + 20) + c] = 101;
  px[3 * (0 * w + 0)] = 0.5f; /* far corner, below threshold */
  CHECK(bloom_apply(w, h, px, 1.0f, 0.1f, 2.0f) == 0, "bloom failed");
  double added = 0;
  for (int i = 0; i < w * h; i++) added += px[3 * i + 1];
  added -= 101;
  CHECK(fabs(added - 10.0) < 1e-3, "bloom added %g, expected 10", added);
  CHECK(px[3 * (20 * w + 22) + 1] > 0 && fabsf(px[3 * (20 * w + 22) + 1] - px[3 * (22 * w + 20) + 1]) < 1e-6f, "not symmetric");
  CHECK(px[0] == 0.5f, "a pixel far from bright ones changed: %g", px[0]);
  free(px);
  return 0;
}

/* The denoisers' shared measures. The contrast of an 8-pixel checkerboard (light squares
 * over dark ones, green) in the window x 32..63, y 16..47 of a W-wide image, and the
 * truth's. */
static void checker_contrast(const float *out, const float *truth, int W, double *con, double *con_t) {
  double hi[2] = {0, 0}, lo[2] = {0, 0};
  for (int y = 16; y < 48; y++)
    for (int x = 32; x < 64; x++) {
      int i = 3 * (y * W + x) + 1, dark = !((x / 8 + y / 8) & 1);
      (dark ? lo : hi)[0] += out[i];
      (dark ? lo : hi)[1] += truth[i];
    }
  *con = hi[0] / lo[0];
  *con_t = hi[1] / lo[1];
}
/* The mean red of the columns either side of x = W/2 (the normal edge). */
static void edge_means(const float *out, int W, int H, double *l, double *r) {
  *l = *r = 0;
  for (int y = 0; y < H; y++) { *l += out[3 * (y * W + W / 2 - 1)]; *r += out[3 * (y * W + W / 2)]; }
  *l /= H;
  *r /= H;
}

/* ---- the still-image denoiser (image/denoise.h) on images whose truth is known: a
 * constant image stays constant; a noisy smooth ramp (Gaussian noise of known variance)
 * comes at least 4x closer to it in relMSE; a checkerboard in albedo under a smooth
 * light keeps its contrast within 2 %; two surfaces that differ in normal and radiance
 * keep their values beside the edge within 2 %; the result is the same for 1 and 3
 * threads. */
static float gauss(uint64_t k) { /* a standard normal number, Box-Muller on hashed bits */
  float u1 = ((float)(rng_mix64(2 * k) >> 40) + 0.5f) * 0x1p-24f, u2 = (float)(rng_mix64(2 * k + 1) >> 40) * 0x1p-24f;
  return sqrtf(-2 * logf(u1)) * cosf(6.2831853f * u2);
}
static int denoiser(void) {
  enum { W = 96, H = 64, N = W * H };
  float *col = malloc(sizeof(float) * 3 * N), *var = malloc(sizeof(float) * 3 * N), *alb = malloc(sizeof(float) * 3 * N),
        *nrm = malloc(sizeof(float) * 3 * N), *dep = malloc(sizeof(float) * N), *out = malloc(sizeof(float) * 3 * N),
        *out3 = malloc(sizeof(float) * 3 * N), *truth = malloc(sizeof(float) * 3 * N);
  CHECK(col && var && alb && nrm && dep && out && out3 && truth, "memory");
  for (int i = 0; i < N; i++) {
    for (int c = 0; c < 3; c++) { alb[3 * i + c] = 0.5f; nrm[3 * i + c] = c == 2; col[3 * i + c] = 0.7f; var[3 * i + c] = 0; }
    dep[i] = 2;
  }
  denoise_in in = {W, H, col, var, alb, nrm, dep};
  /* constant */
  CHECK(denoise_image(&in, out, 2) == 0, "denoise");
  for (int i = 0; i < 3 * N; i++) CHECK(fabsf(out[i] - 0.7f) < 1e-5f, "a constant image changed: %g at %d", out[i], i);
  /* a noisy ramp */
  double e_raw = 0, e_dn = 0;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++)
      for (int c = 0; c < 3; c++) {
        int i = 3 * (y * W + x) + c;
        truth[i] = 0.2f + 0.6f * (float)x / W + 0.2f * (float)y / H;
        var[i] = 0.01f;
        col[i] = truth[i] + 0.1f * gauss((uint64_t)i);
      }
  CHECK(denoise_image(&in, out, 2) == 0 && denoise_image(&in, out3, 3) == 0, "denoise");
  CHECK(!memcmp(out, out3, sizeof(float) * 3 * N), "2 and 3 threads give different images");
  for (int i = 0; i < 3 * N; i++) {
    e_raw += (col[i] - truth[i]) * (col[i] - truth[i]) / (truth[i] * truth[i]);
    e_dn += (out[i] - truth[i]) * (out[i] - truth[i]) / (truth[i] * truth[i]);
  }
  fprintf(stderr, "denoiser: noisy ramp relMSE %.5f -> %.5f\n", e_raw / (3 * N), e_dn / (3 * N));
  CHECK(e_dn * 4 < e_raw, "the ramp came only %.1fx closer", e_raw / e_dn);
  /* a checkerboard in albedo (8-pixel squares, 0.2 and 0.8) under light 1 + x/W, noisy */
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      float a = ((x / 8 + y / 8) & 1) ? 0.8f : 0.2f, E = 1 + (float)x / W;
      for (int c = 0; c < 3; c++) {
        int i = 3 * (y * W + x) + c;
        alb[i] = a;
        truth[i] = a * E;
        var[i] = 0.0025f * a * a;
        col[i] = truth[i] * (1 + 0.05f * gauss((uint64_t)i + 7777777));
      }
    }
  CHECK(denoise_image(&in, out, 2) == 0, "denoise");
  double con, con_t;
  checker_contrast(out, truth, W, &con, &con_t);
  fprintf(stderr, "denoiser: checkerboard contrast %.4f (truth %.4f)\n", con, con_t);
  CHECK(fabs(con / con_t - 1) < 0.02, "checkerboard contrast %.4f against %.4f", con, con_t);
  /* two surfaces: normals +z on the left half (radiance 0.3), +x on the right (0.9) */
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      int right = x >= W / 2;
      for (int c = 0; c < 3; c++) {
        int i = 3 * (y * W + x) + c;
        alb[i] = 0.5f;
        nrm[i] = right ? c == 0 : c == 2;
        truth[i] = right ? 0.9f : 0.3f;
        var[i] = 0.0004f;
        col[i] = truth[i] + 0.02f * gauss((uint64_t)i + 99999999);
      }
    }
  CHECK(denoise_image(&in, out, 2) == 0, "denoise");
  double l, r;
  edge_means(out, W, H, &l, &r);
  fprintf(stderr, "denoiser: beside the normal edge %.4f | %.4f (truth 0.3 | 0.9)\n", l, r);
  CHECK(fabs(l / 0.3 - 1) < 0.02 && fabs(r / 0.9 - 1) < 0.02, "the edge bled: %.4f | %.4f", l, r);
  free(col); free(var); free(alb); free(nrm); free(dep); free(out); free(out3); free(truth);
  return 0;
}

/* ---- the real-time denoiser (image/svgf.h) on frames whose truth is known: a constant
 * frame stays constant; a still camera's noisy frames of a smooth ramp come closer to it
 * (the first frame by the spatial filter alone, later ones with history too); a
 * checkerboard in albedo keeps its contrast within 2 %; a normal edge does not bleed; a
 * jump of the camera (no pixel reprojects) gives exactly the frame filtered without
 * history; a shift by one pixel carries the history along; 1 and 3 threads the same. */
static double ramp_err(const float *a, const float *t, int n) {
  double e = 0;
  for (int i = 0; i < 3 * n; i++) e += (double)(a[i] - t[i]) * (a[i] - t[i]) / ((double)t[i] * t[i]);
  return e / (3 * n);
}
static int svgf_filter(void) {
  enum { W = 96, H = 64, N = W * H };
  float *col = malloc(sizeof(float) * 3 * N), *alb = malloc(sizeof(float) * 3 * N), *nrm = malloc(sizeof(float) * 3 * N),
        *dep = malloc(sizeof(float) * N), *out = malloc(sizeof(float) * 3 * N), *out3 = malloc(sizeof(float) * 3 * N),
        *truth = malloc(sizeof(float) * 3 * N), *pxy = malloc(sizeof(float) * 2 * N), *pd = malloc(sizeof(float) * N);
  svgf *s = svgf_create(W, H), *s3 = svgf_create(W, H);
  CHECK(col && alb && nrm && dep && out && out3 && truth && pxy && pd && s && s3, "memory");
  for (int i = 0; i < N; i++) {
    for (int c = 0; c < 3; c++) { alb[3 * i + c] = 0.5f; nrm[3 * i + c] = c == 2; col[3 * i + c] = 0.7f; }
    dep[i] = 2;
  }
  svgf_frame f = {W, H, col, NULL, 1, alb, NULL, nrm, dep, 1, NULL, NULL};
  for (int k = 0; k < 3; k++) {
    CHECK(svgf_run(s, &f, out, 2) == 0, "svgf");
    for (int i = 0; i < 3 * N; i++) CHECK(fabsf(out[i] - 0.7f) < 1e-5f, "a constant frame changed: %g at %d (frame %d)", out[i], i, k);
  }
  /* a still camera's noisy frames (one sample each) of a smooth ramp */
  svgf_reset(s);
  double e1 = 0, e16 = 0, raw = 0;
  for (int k = 0; k < 16; k++) {
    for (int y = 0; y < H; y++)
      for (int x = 0; x < W; x++)
        for (int c = 0; c < 3; c++) {
          int i = 3 * (y * W + x) + c;
          truth[i] = 0.2f + 0.6f * (float)x / W + 0.2f * (float)y / H;
          col[i] = truth[i] * (1 + 0.3f * gauss((uint64_t)(i + 3 * N * k) + 5555));
          if (col[i] < 0) col[i] = 0;
        }
    CHECK(svgf_run(s, &f, out, 2) == 0 && svgf_run(s3, &f, out3, 3) == 0, "svgf");
    CHECK(!memcmp(out, out3, sizeof(float) * 3 * N), "2 and 3 threads give different frames (frame %d)", k);
    if (k == 0) { e1 = ramp_err(out, truth, N); raw = ramp_err(col, truth, N); }
    if (k == 15) e16 = ramp_err(out, truth, N);
  }
  fprintf(stderr, "svgf: noisy ramp relMSE %.5f -> %.5f (first frame) -> %.5f (sixteenth)\n", raw, e1, e16);
  CHECK(e1 * 4 < raw, "the first frame came only %.1fx closer", raw / e1);
  CHECK(e16 * 2 < e1, "history brought the error only from %.5f to %.5f", e1, e16);
  CHECK(svgf_history(s, W / 2, H / 2) == 16, "the history holds %g samples, not 16", (double)svgf_history(s, W / 2, H / 2));
  /* a camera jump: no pixel reprojects, so the frame is filtered as if alone */
  for (int i = 0; i < N; i++) pxy[2 * i] = pxy[2 * i + 1] = NAN;
  f.prev_xy = pxy;
  f.prev_d = pd;
  CHECK(svgf_run(s, &f, out, 2) == 0, "svgf");
  svgf_reset(s3);
  f.prev_xy = NULL;
  CHECK(svgf_run(s3, &f, out3, 2) == 0, "svgf");
  CHECK(!memcmp(out, out3, sizeof(float) * 3 * N), "after a camera jump the frame still used its history");
  CHECK(svgf_history(s, W / 2, H / 2) == 1, "after a jump the history holds %g samples", (double)svgf_history(s, W / 2, H / 2));
  /* a shift by one pixel: pixel x was at x + 1 on the last frame, at the same depth */
  for (int k = 0; k < 3; k++) CHECK(svgf_run(s, &f, out, 2) == 0, "svgf"); /* 4 samples of history */
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) { pxy[2 * (y * W + x)] = (float)x + 1.5f; pxy[2 * (y * W + x) + 1] = (float)y + 0.5f; pd[y * W + x] = 2; }
  f.prev_xy = pxy;
  CHECK(svgf_run(s, &f, out, 2) == 0, "svgf");
  CHECK(svgf_history(s, 10, 10) == 5 && svgf_history(s, W - 1, 10) == 1, "a shifted history: %g samples inside, %g at the edge it came from nothing",
        (double)svgf_history(s, 10, 10), (double)svgf_history(s, W - 1, 10));
  /* a moved camera's history counts for at most SVGF_MOVING_CAP frames (16 still ones here) */
  for (int k = 0; k < 16; k++) { f.prev_xy = NULL; CHECK(svgf_run(s, &f, out, 2) == 0, "svgf"); }
  f.prev_xy = pxy;
  CHECK(svgf_run(s, &f, out, 2) == 0, "svgf");
  CHECK(svgf_history(s, 10, 10) == SVGF_MOVING_CAP + 1, "after a move the history holds %g samples", (double)svgf_history(s, 10, 10));
  /* nor where the albedo differs by more than REPROJ_ALBEDO (a lamp beside a wall) */
  for (int k = 0; k < 3; k++) { f.prev_xy = NULL; CHECK(svgf_run(s, &f, out, 2) == 0, "svgf"); }
  for (int i = 0; i < 3 * N; i++) alb[i] = 0.7f;
  f.prev_xy = pxy;
  CHECK(svgf_run(s, &f, out, 2) == 0, "svgf");
  CHECK(svgf_history(s, 10, 10) == 1, "history taken across an albedo change of 0.2 per channel");
  for (int i = 0; i < 3 * N; i++) alb[i] = 0.5f;
  /* ... but not where the depth disagrees (another surface there now) */
  for (int k = 0; k < 3; k++) { f.prev_xy = NULL; CHECK(svgf_run(s, &f, out, 2) == 0, "svgf"); }
  for (int i = 0; i < N; i++) pd[i] = 2.5f;
  f.prev_xy = pxy;
  CHECK(svgf_run(s, &f, out, 2) == 0, "svgf");
  CHECK(svgf_history(s, 10, 10) == 1, "history taken from a surface 25 %% further away");
  f.prev_xy = NULL;
  f.prev_d = NULL;
  /* a checkerboard in albedo (8-pixel squares, 0.2 and 0.8) under light 1 + x/W, noisy, one frame */
  svgf_reset(s);
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      float a = ((x / 8 + y / 8) & 1) ? 0.8f : 0.2f, E = 1 + (float)x / W;
      for (int c = 0; c < 3; c++) {
        int i = 3 * (y * W + x) + c;
        alb[i] = a;
        truth[i] = a * E;
        col[i] = truth[i] * (1 + 0.05f * gauss((uint64_t)i + 7777777));
      }
    }
  CHECK(svgf_run(s, &f, out, 2) == 0, "svgf");
  double con, con_t;
  checker_contrast(out, truth, W, &con, &con_t);
  fprintf(stderr, "svgf: checkerboard contrast %.4f (truth %.4f)\n", con, con_t);
  CHECK(fabs(con / con_t - 1) < 0.02, "checkerboard contrast %.4f against %.4f", con, con_t);
  /* two surfaces: normals +z on the left half (radiance 0.3), +x on the right (0.9) */
  svgf_reset(s);
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      int right = x >= W / 2;
      for (int c = 0; c < 3; c++) {
        int i = 3 * (y * W + x) + c;
        alb[i] = 0.5f;
        nrm[i] = right ? c == 0 : c == 2;
        truth[i] = right ? 0.9f : 0.3f;
        col[i] = truth[i] * (1 + 0.1f * gauss((uint64_t)i + 99999999));
      }
    }
  CHECK(svgf_run(s, &f, out, 2) == 0, "svgf");
  double l, r;
  edge_means(out, W, H, &l, &r);
  fprintf(stderr, "svgf: beside the normal edge %.4f | %.4f (truth 0.3 | 0.9)\n", l, r);
  CHECK(fabs(l / 0.3 - 1) < 0.02 && fabs(r / 0.9 - 1) < 0.02, "the edge bled: %.4f | %.4f", l, r);
  svgf_destroy(s); svgf_destroy(s3);
  free(col); free(alb); free(nrm); free(dep); free(out); free(out3); free(truth); free(pxy); free(pd);
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"exr_roundtrip", exr_roundtrip}, {"exr_zip_equal_size", exr_zip_equal_size}, {"pfm_roundtrip", pfm_roundtrip}, {"srgb_png", srgb_png},
                                    {"tone_curves", tone_curves},     {"hdr_jpeg_write", hdr_jpeg_write},     {"atomic_write", atomic_write},   {"real_exr_files", real_exr_files}, {"exr_layers", exr_layers}, {"independent_readers", independent_readers}, {"bloom", bloom}, {"denoiser", denoiser}, {"svgf_filter", svgf_filter},
                                    {NULL, NULL}};
  return test_main(argc, argv, cases);
}
