/* test_badinput.c — damaged files never crash or hang valo: Radiance HDR maps (header cut,
 * scanline cut, bad run lengths, absurd sizes), PLY meshes (ASCII and binary: face counts,
 * indices, truncated element lists), glTF files (.gltf and .glb: references, lengths,
 * strict JSON; gltf_check.h), other mesh formats Assimp crashes or stalls on
 * (import_probe.h), PNG/JPEG textures and EXR maps, truncated and corrupted.
 * Each file is made here from a valid one, handed to the real `valo` binary (ASan+UBSan
 * in CI), and must be refused with exit 1, a message naming the file, in well under a
 * second; a run still alive after 10 s is killed and fails the case. Valid files of each
 * kind still load, and valo's HDR decoder gives stb_image's pixels bit for bit. */
#include "harness.h"
#include "image/hdr.h"
#include "image/image_io.h"
#include <stb_image.h>
#include <stb_image_write.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#ifndef VALO_SOURCE_DIR
#define VALO_SOURCE_DIR "."
#endif

#define REFUSE_SECONDS 2.0 /* "well under a second", with room for a loaded CI machine and ASan */
#define HANG_SECONDS 10

static char g_out[65536];

typedef struct buf { unsigned char *d; size_t n, cap; } buf;
static void put(buf *b, const void *p, size_t n) {
  if (!n) return;
  if (b->n + n > b->cap) {
    b->cap = 2 * (b->n + n) + 64;
    b->d = realloc(b->d, b->cap);
  }
  memcpy(b->d + b->n, p, n);
  b->n += n;
}
static void puts_(buf *b, const char *s) { put(b, s, strlen(s)); }
static void put8(buf *b, unsigned v) { unsigned char c = (unsigned char)v; put(b, &c, 1); }

static const char *write_bytes(const char *name, const void *d, size_t n) {
  static char path[8][1200];
  static int slot;
  char *p = path[slot++ & 7];
  snprintf(p, 1200, "%s/%s", scratch_dir(), name);
  FILE *f = fopen(p, "wb");
  if (!f) return NULL;
  if (n) fwrite(d, 1, n, f);
  fclose(f);
  return p;
}

/* Runs valo; the file must be refused (exit 1) quickly, naming `name` and saying `what`. */
static int refused(const char *const *args, const char *name, const char *what) {
  int rc = run_cli(args, 0, HANG_SECONDS, g_out, sizeof g_out);
  CHECK(rc != 999, "valo hung on %s", name);
  CHECK(rc == 1, "%s: exit code %d, expected 1", name, rc);
  CHECK(run_cli_seconds < REFUSE_SECONDS, "%s: refused after %.2f s", name, run_cli_seconds);
  CHECK(strstr(g_out, name) != NULL, "the message does not name %s", name);
  CHECK(!what || strstr(g_out, what) != NULL, "%s: the message lacks \"%s\"", name, what);
  CHECK(strstr(g_out, "Sanitizer") == NULL, "%s: a sanitizer report", name);
  return 0;
}
static int accepted(const char *const *args, const char *name) {
  int rc = run_cli(args, 0, 120, g_out, sizeof g_out);
  CHECK(rc == 0, "%s: exit code %d, expected 0", name, rc);
  CHECK(strstr(g_out, "Sanitizer") == NULL, "%s: a sanitizer report", name);
  return 0;
}
static const char *out_png(void) {
  static char p[1200];
  snprintf(p, sizeof p, "%s/out.png", scratch_dir());
  return p;
}
#define DEFAULT_SCENE VALO_SOURCE_DIR "/scenes/default.json"
#define ENV_ARGS(file) {"render", DEFAULT_SCENE, "--env", file, "--spp", "1", "--res", "16x16", "-q", "-o", out_png(), NULL}
#define MESH_ARGS(file) {"render", file, "--spp", "1", "--res", "16x16", "-q", "-o", out_png(), NULL}

/* The mesh file `name` (n bytes) written to the scratch folder, then loaded by valo:
 * mesh_loads must render it, mesh_refused must see it refused saying `what`. */
static int mesh_loads(const char *name, const void *d, size_t n) {
  const char *a[] = MESH_ARGS(write_bytes(name, d, n));
  return accepted(a, name);
}
static int mesh_refused(const char *name, const void *d, size_t n, const char *what) {
  const char *a[] = MESH_ARGS(write_bytes(name, d, n));
  return refused(a, name, what);
}

/* ---- Radiance HDR ---- */

/* A w x h RGBE image in the adaptive RLE (w in 8..32767) or flat; pixels with runs. */
static unsigned char px_byte(int x, int y, int k) { return k == 3 ? (unsigned char)(128 + (y % 3)) : (unsigned char)(((x / 5) * 37 + y * 11 + k * 60) & 255); }
static void make_hdr(buf *b, int w, int h, int rle) {
  char head[160];
  snprintf(head, sizeof head, "#?RADIANCE\n# made by test_badinput\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n\n-Y %d +X %d\n", h, w);
  puts_(b, head);
  for (int y = 0; y < h; y++) {
    if (!rle) {
      for (int x = 0; x < w; x++)
        for (int k = 0; k < 4; k++) put8(b, px_byte(x, y, k));
      continue;
    }
    put8(b, 2); put8(b, 2); put8(b, (unsigned)w >> 8); put8(b, (unsigned)w & 255);
    for (int k = 0; k < 4; k++) {
      int x = 0;
      while (x < w) {
        int r = 1;
        while (x + r < w && r < 127 && px_byte(x + r, y, k) == px_byte(x, y, k)) r++;
        if (r >= 3) { put8(b, 128 + (unsigned)r); put8(b, px_byte(x, y, k)); x += r; continue; }
        int d = 0;
        while (x + d < w && d < 128 && !(x + d + 2 < w && px_byte(x + d, y, k) == px_byte(x + d + 1, y, k) &&
                                        px_byte(x + d, y, k) == px_byte(x + d + 2, y, k))) d++;
        if (d == 0) d = 1;
        put8(b, (unsigned)d);
        for (int i = 0; i < d; i++) put8(b, px_byte(x + i, y, k));
        x += d;
      }
    }
  }
}
static size_t hdr_header_len(const buf *b) {
  for (size_t i = 0; i + 3 < b->n; i++)
    if (!memcmp(b->d + i, "+X ", 3)) {
      const unsigned char *nl = memchr(b->d + i, '\n', b->n - i);
      return nl ? (size_t)(nl + 1 - b->d) : b->n;
    }
  return b->n;
}

static int hdr_decoder_matches_stb(void) {
  /* Made here (RLE and flat), and the shared maps when present: the same floats as stb. */
  const char *files[8];
  int nf = 0;
  buf b = {0};
  make_hdr(&b, 40, 7, 1);
  files[nf++] = write_bytes("rle.hdr", b.d, b.n);
  b.n = 0;
  make_hdr(&b, 5, 3, 0);
  files[nf++] = write_bytes("flat.hdr", b.d, b.n);
  free(b.d);
  const char *shared[] = {"scenes/envmaps/moonless_golf_1k.hdr", "scenes/envmaps/venice_sunset_1k.hdr"};
  for (int i = 0; i < 2; i++) {
    const char *p = shared_file(shared[i]);
    if (!p) return TEST_SKIP;
    files[nf++] = p;
  }
  for (int i = 0; i < nf; i++) {
    int w, h, n;
    float *ref = stbi_loadf(files[i], &w, &h, &n, 3);
    CHECK(ref, "stb cannot read %s", files[i]);
    image im;
    valo_error err;
    CHECK(hdr_read(files[i], &im, &err) == VALO_OK, "%s", err.message);
    CHECK(im.w == w && im.h == h, "%s: %dx%d against stb's %dx%d", files[i], im.w, im.h, w, h);
    CHECK(!memcmp(im.rgb, ref, (size_t)w * h * 3 * sizeof(float)), "%s: pixels differ from stb's", files[i]);
    /* and the bytes made here decode to what was written */
    if (i == 0)
      for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
          float f = (float)ldexp(1.0, px_byte(x, y, 3) - 136);
          CHECK(im.rgb[3 * (y * w + x)] == px_byte(x, y, 0) * f, "pixel %d,%d", x, y);
        }
    stbi_image_free(ref);
    image_free(&im);
    fprintf(stderr, "%s: %dx%d identical to stb_image\n", files[i], w, h);
  }
  const char *a[] = ENV_ARGS(files[0]);
  return accepted(a, "rle.hdr");
}

static int hdr_damaged(void) {
  buf good = {0};
  make_hdr(&good, 64, 9, 1);
  size_t hl = hdr_header_len(&good);
  struct { const char *name, *what; size_t cut; int patch_at; int patch_val; const char *header; } cases[] = {
      {"h_header_cut.hdr", "header", 30, -1, 0, NULL},               /* inside the header lines */
      {"h_no_resolution.hdr", "resolution", 0, -1, 0, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n"},
      {"h_scanline_cut.hdr", "ends inside HDR scanline 1 of 1", 0, -1, 0, NULL}, /* the hang: cut inside an RLE scanline */
      {"h_late_cut.hdr", "scanline", 0, -1, 0, NULL},                /* cut in a later scanline */
      {"h_run_zero.hdr", "a run of 0", 0, 0, 0, NULL},              /* count byte 0: a dump of length 0 */
      {"h_run_long.hdr", "a run of", 0, 0, 255, NULL},              /* a run of 127 in a 64-pixel row */
      {"h_dump_long.hdr", "a run of", 0, 0, 100, NULL},             /* a dump of 100 in a 64-pixel row */
      {"h_bad_mark.hdr", "run-length mark", 0, -2, 0, NULL},        /* scanline width disagrees */
      {"h_absurd.hdr", "need at least", 0, -1, 0, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n"},
      {"h_zero.hdr", "out of range", 0, -1, 0, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 64\n"},
      {"h_negative.hdr", "out of range", 0, -1, 0, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y -5 +X 64\n"},
      {"h_huge_width.hdr", "out of range", 0, -1, 0, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 99999999999\n"},
      {"h_xyze.hdr", "not supported", 0, -1, 0, "#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n\x80\x80\x80\x80"},
      {"h_not_hdr.hdr", "not a Radiance HDR", 0, -1, 0, "P6\n1 1\n255\n\0\0\0"},
      {"h_empty.hdr", "not a Radiance HDR", 0, -1, 0, ""},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    buf b = {0};
    if (cases[i].header) {
      puts_(&b, cases[i].header);
    } else if (!strcmp(cases[i].name, "h_scanline_cut.hdr")) {
      make_hdr(&b, 64, 1, 1); /* one row, so the cut passes the size check and reaches the RLE decoder */
    } else {
      put(&b, good.d, good.n);
    }
    if (!strcmp(cases[i].name, "h_header_cut.hdr")) b.n = cases[i].cut;
    if (!strcmp(cases[i].name, "h_scanline_cut.hdr")) b.n = hl + 40;
    if (!strcmp(cases[i].name, "h_late_cut.hdr")) b.n = good.n - 17;
    if (cases[i].patch_at == 0) b.d[hl + 4] = (unsigned char)cases[i].patch_val; /* first count byte of scanline 1 */
    if (cases[i].patch_at == -2) b.d[hl + 3] = 63;
    const char *p = write_bytes(cases[i].name, b.d, b.n);
    free(b.d);
    const char *a[] = ENV_ARGS(p);
    if (refused(a, cases[i].name, cases[i].what)) return 1;
  }
  /* The shared map cut 100 bytes into its pixels, as the hang was found. */
  const char *golf = shared_file("scenes/envmaps/moonless_golf_1k.hdr");
  if (!golf) { free(good.d); return TEST_SKIP; }
  FILE *f = fopen(golf, "rb");
  unsigned char *d = malloc(4096);
  size_t n = fread(d, 1, 4096, f);
  fclose(f);
  buf g = {d, n, 4096};
  const char *p = write_bytes("golf_cut.hdr", d, hdr_header_len(&g) + 100);
  free(d);
  free(good.d);
  const char *a[] = ENV_ARGS(p);
  return refused(a, "golf_cut.hdr", "HDR");
}

/* ---- PLY ---- */

static const float QUAD_V[4][3] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
static const int QUAD_F[2][3] = {{0, 1, 2}, {0, 2, 3}};

static void ply_header(buf *b, const char *fmt, long nv, long nf, const char *count_type) {
  char h[400];
  snprintf(h, sizeof h, "ply\nformat %s 1.0\ncomment test_badinput\nelement vertex %ld\nproperty float x\nproperty float y\nproperty float z\n"
                        "element face %ld\nproperty list %s int vertex_indices\nend_header\n", fmt, nv, nf, count_type);
  puts_(b, h);
}
static void put_bin(buf *b, const void *v, size_t n, int be) {
  unsigned char t[8];
  memcpy(t, v, n);
  if (be)
    for (size_t i = 0; i < n / 2; i++) { unsigned char c = t[i]; t[i] = t[n - 1 - i]; t[n - 1 - i] = c; }
  put(b, t, n);
}
/* A quad as a binary PLY; faces[i][0] < 0 writes that face's count as -faces[i][0]. */
static void ply_binary(buf *b, int be, long nv, long nf, const int (*faces)[4], int nfaces_written) {
  ply_header(b, be ? "binary_big_endian" : "binary_little_endian", nv, nf, "uchar");
  for (int i = 0; i < 4; i++)
    for (int k = 0; k < 3; k++) put_bin(b, &QUAD_V[i][k], 4, be);
  for (int i = 0; i < nfaces_written; i++) {
    put8(b, (unsigned)faces[i][0]);
    for (int k = 0; k < faces[i][0] && k < 3; k++) put_bin(b, &faces[i][1 + k], 4, be);
  }
}

static int ply_valid_forms(void) {
  const int f[2][4] = {{3, 0, 1, 2}, {3, 0, 2, 3}};
  for (int be = 0; be < 2; be++) {
    buf b = {0};
    ply_binary(&b, be, 4, 2, f, 2);
    const char *p = write_bytes(be ? "quad_be.ply" : "quad_le.ply", b.d, b.n);
    free(b.d);
    const char *a[] = MESH_ARGS(p);
    if (accepted(a, p)) return 1;
  }
  buf b = {0};
  ply_header(&b, "ascii", 4, 2, "uchar");
  puts_(&b, "-1.0e0 -1 0\n+1 -1. 0\n1 1 -.0\n-1 1E+0 0\n3 0 1 2\n4 0 1 2 3\r\n\n"); /* the number forms valo and Assimp share */
  const char *p = write_bytes("quad_ascii.ply", b.d, b.n);
  free(b.d);
  const char *a[] = MESH_ARGS(p);
  (void)QUAD_F;
  return accepted(a, "quad_ascii.ply");
}

static int ply_ascii_damaged(void) {
  struct { const char *name, *what; long nv, nf; const char *body; } cases[] = {
      {"a_truncated_faces.ply", "ends after 2 of 3 'face'", 4, 3, "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2 3\n"},
      {"a_truncated_vertices.ply", "'vertex'", 4, 2, "-1 -1 0\n1 -1 0\n1 1 0\n"},
      {"a_cut_line.ply", "missing", 4, 2, "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2"},
      {"a_index_high.ply", "vertex index 4 is out of range", 4, 2, "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2 4\n"},
      {"a_index_negative.ply", "out of range", 4, 2, "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 -1 3\n"},
      {"a_two_vertices.ply", "lists 2 vertices", 4, 2, "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n2 0 2\n"},
      {"a_zero_vertices.ply", "lists 0 vertices", 4, 2, "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n0\n3 0 2 3\n"},
      {"a_count_over_line.ply", "missing", 4, 2, "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n9 0 2 3\n"},
      {"a_extra_values.ply", "more values", 4, 2, "-1 -1 0 7\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2 3\n"},
      {"a_not_number.ply", "not a number", 4, 2, "-1 -1 0\n1 x -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2 3\n"},
      {"a_blank_line.ply", ":12: a blank line in the data (element 'vertex' 2 of 4)", 4, 2, "-1 -1 0\n\n\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2 3\n"},
      {"a_space_line.ply", ":16: a blank line in the data (element 'face' 2 of 2)", 4, 2, "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n \r\n3 0 2 3\n"},
      {"a_plus_count.ply", ":16: list", 4, 2, "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n+3 0 2 3\n"},
      {"a_hex_float.ply", ":12: ", 4, 2, "-1 -1 0\n1 0x1p0 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2 3\n"},
      {"a_count_over_type.ply", ":15: list", 4, 2, "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n259 0 1 2\n3 0 2 3\n"},
      {"a_trailing.ply", "after the last element", 4, 2, "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2 3\n3 0 1 3\n"},
      {"a_absurd_count.ply", "more than the file", 4000000000L, 2, "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2 3\n"},
      {"a_absurd_faces.ply", "more than the file", 4, 3000000000L, "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2 3\n"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    buf b = {0};
    ply_header(&b, "ascii", cases[i].nv, cases[i].nf, "uchar");
    puts_(&b, cases[i].body);
    int rc = mesh_refused(cases[i].name, b.d, b.n, cases[i].what);
    free(b.d);
    if (rc) return 1;
  }
  /* Headers. */
  struct { const char *name, *what, *text; } heads[] = {
      {"a_no_end_header.ply", "end_header", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"},
      {"a_bad_format.ply", "unknown PLY format", "ply\nformat binary_middle_endian 1.0\nend_header\n"},
      {"a_bad_type.ply", "bad property", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float3 x\nend_header\n0\n"},
      {"a_float_indices.ply", "list of integers", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                                                 "element face 1\nproperty list uchar float vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
      {"a_no_xyz.ply", "no x, y and z", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n"},
      {"a_strips.ply", "strips", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                                 "element tristrips 1\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
      {"a_two_formats.ply", ":3: a second format line", "ply\nformat ascii 1.0\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
                                                   "property float y\nproperty float z\nend_header\n0 0 0\n"},
      {"a_two_vertex_elements.ply", ":7: a second 'vertex' element",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement vertex 1\nproperty float x\n"
       "property float y\nproperty float z\nproperty uchar red\nend_header\n0 0 0\n1 0 0 9\n"},
      {"a_blank_header_line.ply", ":6: a blank line in the PLY header", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\nproperty float z\nend_header\n0 0 0\n"},
      {"a_obj_info_in_props.ply", ":6: a property after an obj_info", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nobj_info made by hand\nproperty float y\nproperty float z\nend_header\n0 0 0\n"},
      {"a_unknown_element.ply", ":3: element 'vertices' is not one", "ply\nformat ascii 1.0\nelement vertices 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n"},
      {"a_digit_element.ply", ":3: element '12' is not one", "ply\nformat ascii 1.0\nelement 12 0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n"},
      {"a_two_face_elements.ply", ":9: a second 'face' element",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
       "property list uchar int vertex_indices\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n"},
  };
  for (size_t i = 0; i < sizeof heads / sizeof heads[0]; i++) {
    if (mesh_refused(heads[i].name, heads[i].text, strlen(heads[i].text), heads[i].what)) return 1;
  }
  return 0;
}

static int ply_binary_damaged(void) {
  const int ok2[2][4] = {{3, 0, 1, 2}, {3, 0, 2, 3}};
  const int high[2][4] = {{3, 0, 1, 2}, {3, 0, 2, 9}};
  const int neg[2][4] = {{3, 0, 1, 2}, {3, -7, 2, 3}};
  const int two[2][4] = {{3, 0, 1, 2}, {2, 0, 2, 0}};
  for (int be = 0; be < 2; be++) {
    struct { const char *name, *what; long nv, nf; const int (*faces)[4]; int written; size_t cut; } cases[] = {
        {"b_truncated_faces.ply", "ends after 2 of 3 'face'", 4, 3, ok2, 2, 0},
        {"b_cut_in_face.ply", "runs past the end", 4, 2, ok2, 2, 5},
        {"b_cut_in_vertex.ply", "vertex", 4, 2, ok2, 0, 20},
        {"b_index_high.ply", "vertex index 9 is out of range", 4, 2, high, 2, 0},
        {"b_index_negative.ply", "out of range", 4, 2, neg, 2, 0},
        {"b_two_vertices.ply", "lists 2 vertices", 4, 2, two, 2, 0},
        {"b_absurd_faces.ply", "more than the file", 4, 4000000000L, ok2, 2, 0},
        {"b_absurd_vertices.ply", "more than the file", 1000000000L, 2, ok2, 2, 0},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
      buf b = {0};
      ply_binary(&b, be, cases[i].nv, cases[i].nf, cases[i].faces, cases[i].written);
      if (cases[i].cut) b.n -= cases[i].cut;
      char name[64];
      snprintf(name, sizeof name, "%s_%s", be ? "be" : "le", cases[i].name);
      int rc = mesh_refused(name, b.d, b.n, cases[i].what);
      free(b.d);
      if (rc) return 1;
    }
    /* A face list whose uchar count says 255 items: runs past the end. */
    buf b = {0};
    ply_binary(&b, be, 4, 2, ok2, 2);
    b.d[b.n - 13] = 255;
    int rc = mesh_refused(be ? "be_list_255.ply" : "le_list_255.ply", b.d, b.n, "past the end");
    free(b.d);
    if (rc) return 1;
  }
  return 0;
}

/* The shared dragon, cut and spliced as the fuzzing that found Assimp's abort did. */
static int ply_dragon_mutations(void) {
  const char *src = shared_file("scenes/dragon/dragon_vrip_res4.ply");
  if (!src) return TEST_SKIP;
  FILE *f = fopen(src, "rb");
  CHECK(f, "cannot open %s", src);
  unsigned char *d = malloc(1 << 20);
  size_t n = fread(d, 1, 1 << 20, f);
  fclose(f);
  const size_t cuts[] = {100000, 200000, n - 1000};
  for (int i = 0; i < 3; i++) {
    char name[64];
    snprintf(name, sizeof name, "dragon_cut%d.ply", i);
    if (mesh_refused(name, d, cuts[i], NULL)) { free(d); return 1; }
  }
  /* 2000 bytes of the vertex list spliced into the face list. */
  buf b = {0};
  put(&b, d, 250000);
  put(&b, d + 1000, 2000);
  put(&b, d + 250000, n - 250000);
  int rc = mesh_refused("dragon_splice.ply", b.d, b.n, NULL);
  free(b.d);
  free(d);
  return rc;
}

/* ---- PNG, JPEG, EXR ---- */

static const char *texture_scene(const char *tex_name) {
  char json[2048];
  snprintf(json, sizeof json,
           "{ \"camera\": {\"position\": [0,0,3.2], \"look_at\": [0,0,0], \"fov\": 40}, \"film\": {\"width\": 16, \"height\": 16},\n"
           "  \"materials\": {\"tex\": {\"type\": \"diffuse\", \"reflectance\": \"%s\"}},\n"
           "  \"shapes\": [{\"file\": \"%s/tests/data/materials/quad-uv.obj\", \"material\": \"tex\"}],\n"
           "  \"environment\": {\"type\": \"constant\", \"radiance\": 1} }\n", tex_name, VALO_SOURCE_DIR);
  char name[80];
  snprintf(name, sizeof name, "scene_%s.json", tex_name);
  return scratch_file(name, json);
}
static int texture_refused(const char *name, const unsigned char *d, size_t n, const char *what) {
  write_bytes(name, d, n);
  const char *a[] = {"render", texture_scene(name), "--spp", "1", "-q", "-o", out_png(), NULL};
  return refused(a, name, what);
}
static void be32(unsigned char *p, uint32_t v) { p[0] = v >> 24; p[1] = v >> 16; p[2] = v >> 8; p[3] = (unsigned char)v; }

static unsigned char *read_all(const char *path, size_t *n) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  unsigned char *d = malloc(1 << 22);
  *n = d ? fread(d, 1, 1 << 22, f) : 0;
  fclose(f);
  return d;
}

static int png_jpeg_damaged(void) {
  size_t n = 0;
  unsigned char *png = read_all(VALO_SOURCE_DIR "/tests/data/materials/quad-texture.png", &n);
  CHECK(png, "no quad-texture.png");
  {
    write_bytes("good.png", png, n);
    const char *a[] = {"render", texture_scene("good.png"), "--spp", "1", "-q", "-o", out_png(), NULL};
    if (accepted(a, "good.png")) return 1;
  }
  if (texture_refused("cut.png", png, n / 2, "decoded")) return 1;
  if (texture_refused("cut_header.png", png, 20, "decoded")) return 1;
  unsigned char *m = malloc(n);
  memcpy(m, png, n);
  be32(m + 16, 100000); be32(m + 20, 100000); /* IHDR width and height */
  if (texture_refused("huge.png", m, n, "decoded")) return 1;
  memcpy(m, png, n);
  for (size_t i = 40; i < n; i += 7) m[i] ^= 0x5a; /* the compressed data */
  if (texture_refused("scrambled.png", m, n, "decoded")) return 1;
  free(m);
  free(png);
  /* A JPEG made here (stb's writer), then cut, scrambled and given an absurd size. */
  unsigned char rgb[64 * 64 * 3];
  for (int i = 0; i < 64 * 64 * 3; i++) rgb[i] = (unsigned char)(i * 7);
  char jp[1200];
  snprintf(jp, sizeof jp, "%s/good.jpg", scratch_dir());
  CHECK(stbi_write_jpg(jp, 64, 64, 3, rgb, 90), "cannot write a JPEG");
  unsigned char *jpg = read_all(jp, &n);
  {
    const char *a[] = {"render", texture_scene("good.jpg"), "--spp", "1", "-q", "-o", out_png(), NULL};
    if (accepted(a, "good.jpg")) return 1;
  }
  if (texture_refused("cut.jpg", jpg, n / 3, "decoded")) return 1;
  /* Walk the markers to the frame header (SOF0) and claim 65520 x 65520. */
  size_t at = 2;
  while (at + 4 < n && !(jpg[at] == 0xff && jpg[at + 1] == 0xc0)) at += 2 + ((size_t)jpg[at + 2] << 8 | jpg[at + 3]);
  CHECK(at + 9 < n, "no SOF0 in the JPEG");
  jpg[at + 5] = jpg[at + 7] = 0xff;
  jpg[at + 6] = jpg[at + 8] = 0xf0;
  if (texture_refused("huge.jpg", jpg, n, "texture limit")) return 1;
  free(jpg);
  return 0;
}

/* PFM maps whose header claims more pixels than the file holds: refused before the
 * pixels are allocated (CI's fuzzer found a 19-byte file claiming 8505 x 52777, 5 GB;
 * 8505 x 5277 here, well within the memory check, so the file's size refuses it). */
static int pfm_damaged(void) {
#define PFM_CASE(name, bytes, what) {name, bytes, sizeof bytes - 1, what}
  struct { const char *name, *bytes; size_t n; const char *what; } cases[] = {
      PFM_CASE("claims_500mb.pfm", "PF\n8505 5277\n-1\n\x1e\x38", "8505 x 5277 pixels need 538570620 bytes, the file holds 2"),
      PFM_CASE("short_row.pfm", "PF\n2 1\n-1\n\0\0\0\0\0\0\0\0", "2 x 1 pixels need 24 bytes, the file holds 8"),
  };
#undef PFM_CASE
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    const char *p = write_bytes(cases[i].name, cases[i].bytes, cases[i].n);
    const char *a[] = ENV_ARGS(p);
    if (refused(a, cases[i].name, cases[i].what)) return 1;
  }
  return 0;
}

static int exr_damaged(void) {
  float px[32 * 16 * 3];
  for (int i = 0; i < 32 * 16 * 3; i++) px[i] = (float)(i % 17) / 8.0f;
  char p[1200];
  snprintf(p, sizeof p, "%s/good.exr", scratch_dir());
  valo_output_options o;
  valo_output_options_init(&o);
  valo_error err;
  CHECK(image_write(p, 32, 16, px, &o, &err) == VALO_OK, "%s", err.message);
  size_t n = 0;
  unsigned char *exr = read_all(p, &n);
  {
    const char *a[] = ENV_ARGS(p);
    if (accepted(a, "good.exr")) { free(exr); return 1; }
  }
  const size_t cuts[] = {n / 2, n - 3, 40, 4};
  for (int i = 0; i < 4; i++) {
    char name[32];
    snprintf(name, sizeof name, "cut%d.exr", i);
    const char *q = write_bytes(name, exr, cuts[i]);
    const char *a[] = ENV_ARGS(q);
    if (refused(a, name, "EXR")) { free(exr); return 1; }
  }
  unsigned char *m = malloc(n);
  for (int k = 0; k < 3; k++) {
    memcpy(m, exr, n);
    size_t from = k == 0 ? 8 : k == 1 ? n / 2 : n - 60; /* header, pixel data, last chunk */
    for (size_t i = from; i < n && i < from + 40; i += 3) m[i] ^= 0xa5;
    char name[32];
    snprintf(name, sizeof name, "scrambled%d.exr", k);
    const char *q = write_bytes(name, m, n);
    const char *a[] = ENV_ARGS(q);
    int rc = run_cli(a, 0, HANG_SECONDS, g_out, sizeof g_out);
    /* A flipped byte may land where it changes only a value: a render is fine then; a crash or hang is not. */
    CHECK(rc == 0 || rc == 1, "%s: exit code %d", name, rc);
    CHECK(rc == 0 || strstr(g_out, name), "%s: the message does not name the file", name);
    CHECK(strstr(g_out, "Sanitizer") == NULL, "%s: a sanitizer report", name);
  }
  free(m);
  free(exr);
  return 0;
}

/* ---- glTF ---- */

/* A quad: 4 float positions (48 bytes), then 6 unsigned-short indices (12 bytes). */
#define QUAD_B64 "AACAvwAAgL8AAAAAAACAPwAAgL8AAAAAAACAPwAAgD8AAAAAAACAvwAAgD8AAAAAAAABAAIAAAACAAMA"
#define QUAD_B64_INDEX_4 "AACAvwAAgL8AAAAAAACAPwAAgL8AAAAAAACAPwAAgD8AAAAAAACAvwAAgD8AAAAAAAABAAIAAAACAAQA"
static const char GLTF_QUAD[] =
    "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}],\n"
    " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1}]}],\n"
    " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", \"min\": [-1,-1,0], \"max\": [1,1,0]},\n"
    "               {\"bufferView\": 1, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}],\n"
    " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 12}],\n"
    " \"buffers\": [{\"byteLength\": 60, \"uri\": \"data:application/octet-stream;base64," QUAD_B64 "\"}]}\n";

/* The template with its first `find` replaced by `repl` (static storage). */
static const char *subst(const char *t, const char *find, const char *repl) {
  static char out[8192];
  const char *at = strstr(t, find);
  if (!at) return NULL;
  snprintf(out, sizeof out, "%.*s%s%s", (int)(at - t), t, repl, at + strlen(find));
  return out;
}

/* A .glb holding json and bin (each chunk padded to 4 bytes). */
static void make_glb(buf *b, const char *json, const unsigned char *bin, size_t nbin) {
  size_t nj = (strlen(json) + 3) & ~(size_t)3, nb = (nbin + 3) & ~(size_t)3;
  uint32_t w[5] = {0x46546C67u, 2, (uint32_t)(12 + 8 + nj + (nbin ? 8 + nb : 0)), (uint32_t)nj, 0x4E4F534Au};
  for (int i = 0; i < 5; i++)
    for (int k = 0; k < 4; k++) put8(b, w[i] >> (8 * k) & 255);
  puts_(b, json);
  for (size_t i = strlen(json); i < nj; i++) put8(b, ' ');
  if (!nbin) return;
  uint32_t c[2] = {(uint32_t)nb, 0x004E4942u};
  for (int i = 0; i < 2; i++)
    for (int k = 0; k < 4; k++) put8(b, c[i] >> (8 * k) & 255);
  put(b, bin, nbin);
  for (size_t i = nbin; i < nb; i++) put8(b, 0);
}

static int gltf_valid_forms(void) {
  if (mesh_loads("quad.gltf", GLTF_QUAD, strlen(GLTF_QUAD))) return 1;
  /* the buffer in a file beside it, and the same in a .glb */
  static const float pos[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  static const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
  unsigned char bin[60];
  memcpy(bin, pos, 48);
  memcpy(bin + 48, idx, 12);
  write_bytes("quad.bin", bin, sizeof bin);
  const char *t = subst(GLTF_QUAD, "data:application/octet-stream;base64," QUAD_B64, "quad.bin");
  CHECK(t, "template");
  if (mesh_loads("quad_file.gltf", t, strlen(t))) return 1;
  /* a buffer file named with a URI's escape (Assimp 5.2 opened "quad%20file.bin" as written) */
  write_bytes("quad file.bin", bin, sizeof bin);
  t = subst(GLTF_QUAD, "data:application/octet-stream;base64," QUAD_B64, "quad%20file.bin");
  if (mesh_loads("quad_escaped.gltf", t, strlen(t))) return 1;
  /* a UTF-8 byte-order mark before the JSON (Assimp 5.2 read no glTF after one) */
  char bom[4096];
  snprintf(bom, sizeof bom, "\xef\xbb\xbf%s", GLTF_QUAD);
  if (mesh_loads("quad_bom.gltf", bom, strlen(bom))) return 1;
  /* an application's "...Texture" member inside a material's extras is not a texture reference */
  t = subst(GLTF_QUAD, "\"scene\": 0", "\"materials\": [{\"extras\": {\"myTexture\": {\"file\": \"x.png\"}}}], \"scene\": 0");
  if (mesh_loads("quad_extras.gltf", t, strlen(t))) return 1;
  /* a skin without inverseBindMatrices (valid glTF; Assimp 5.2 crashed on it: valo hides skins from it) */
  t = subst(GLTF_QUAD, "[{\"mesh\": 0}]", "[{\"mesh\": 0, \"skin\": 0}], \"skins\": [{\"joints\": [0]}]");
  CHECK(t, "template");
  if (mesh_loads("quad_skin.gltf", t, strlen(t))) return 1;
  /* sparse accessors: a morph target, and POSITION itself */
  const char *sp1[] = MESH_ARGS(VALO_SOURCE_DIR "/fuzz/seeds/gltf/sparse-morph-target.gltf");
  const char *sp2[] = MESH_ARGS(VALO_SOURCE_DIR "/fuzz/seeds/gltf/sparse-position.gltf");
  if (accepted(sp1, "sparse-morph-target.gltf") || accepted(sp2, "sparse-position.gltf")) return 1;
  /* sparse indices (on a base whose last triangle is 0 0 0, and with no base at all) give
   * the quad's image byte for byte */
  static const char *const sparse_ix[3] = {NULL, VALO_SOURCE_DIR "/fuzz/seeds/gltf/sparse-indices.gltf",
                                           VALO_SOURCE_DIR "/fuzz/seeds/gltf/sparse-indices-no-base.gltf"};
  char exr[3][1200];
  for (int i = 0; i < 3; i++) {
    snprintf(exr[i], sizeof exr[i], "%s/sparse%d.exr", scratch_dir(), i);
    const char *file = sparse_ix[i] ? sparse_ix[i] : write_bytes("quad_ref.gltf", GLTF_QUAD, strlen(GLTF_QUAD));
    const char *a[] = {"render", file, "--spp", "4", "--res", "32x32", "--seed", "3", "-q", "-o", exr[i], NULL};
    if (accepted(a, file)) return 1;
  }
  CHECK(same_bytes(exr[0], exr[1]) && same_bytes(exr[0], exr[2]), "sparse indices do not give the quad's image");
  char json[2048];
  snprintf(json, sizeof json, "%s", subst(GLTF_QUAD, ", \"uri\": \"data:application/octet-stream;base64," QUAD_B64 "\"", ""));
  buf g = {0};
  make_glb(&g, json, bin, sizeof bin);
  int rc = mesh_loads("quad.glb", g.d, g.n);
  free(g.d);
  return rc;
}

/* Each refused in valo's words: those Assimp 5.2.5 crashed on (a sparse accessor, an
 * image type without '/' once a material uses it, a .glb chunk past the file: 4 GB and a
 * hang), read otherwise than the file says or read at all (an attribute count unlike
 * POSITION's, an index past the vertices, deep nesting), and those it refused in its own
 * words or with "No suitable reader". */
static int gltf_damaged(void) {
  char deep[1300] = "[";
  for (int i = 1; i < 600; i++) strcat(deep, "[");
  for (int i = 0; i < 600; i++) strcat(deep, "]");
  char deep_extras[1400];
  snprintf(deep_extras, sizeof deep_extras, "\"extras\": %s, \"scene\": 0", deep);
  struct { const char *name, *what, *find, *repl; } cases[] = {
      {"g_version.gltf", "version 1.0 is not read", "\"2.0\"", "\"1.0\""},
      {"g_count.gltf", "accessor 1: 7 elements from byte 0 do not fit in buffer view 1", "\"count\": 6", "\"count\": 7"},
      {"g_view.gltf", "buffer view 1: bytes 48 to 61 are outside buffer 0", "\"byteLength\": 12", "\"byteLength\": 13"},
      {"g_buffer_ref.gltf", "buffer view 1: \"buffer\" names no buffer", "\"buffer\": 0, \"byteOffset\": 48", "\"buffer\": 1, \"byteOffset\": 48"},
      {"g_float_index.gltf", "\"indices\" names no accessor", "\"indices\": 1", "\"indices\": 1.0"},
      {"g_buffer_len.gltf", "holds 60 bytes, \"byteLength\" says 64", "\"byteLength\": 60", "\"byteLength\": 64"},
      {"g_cycle.gltf", "form a cycle", "[{\"mesh\": 0}]", "[{\"mesh\": 0, \"children\": [1]}, {\"children\": [0]}]"},
      {"g_self.gltf", "node 0 is a child of two nodes, or of itself", "[{\"mesh\": 0}]", "[{\"mesh\": 0, \"children\": [0]}]"},
      {"g_index.gltf", "index 5 is 4, past the 4 vertices", QUAD_B64, QUAD_B64_INDEX_4},
      {"g_attribute.gltf", "attribute NORMAL has 6 elements, POSITION 4", "\"POSITION\": 0}", "\"POSITION\": 0, \"NORMAL\": 1}"},
      {"g_comma.gltf", "g_comma.gltf:3: glTF: a member name", "\"max\": [1,1,0]}", "\"max\": [1,1,0],}"},
      {"g_nan.gltf", ":3: glTF: a value expected", "[-1,-1,0]", "[-1,-1,NaN]"},
      {"g_huge.gltf", "past the range of a double", "[-1,-1,0]", "[-1,-1,1e999]"},
      {"g_deep.gltf", "nested more than 512 deep", "\"scene\": 0", deep_extras},
      {"g_scene.gltf", "\"scene\" names no scene", "\"scene\": 0", "\"scene\": 2"},
      {"g_surrogate.gltf", "a lone surrogate", "\"asset\"", "\"\\uD800\", \"asset\""},
      {"g_image_type.gltf", "TYPE/SUBTYPE", "\"scene\": 0", "\"images\": [{\"uri\": \"data:image;base64,AAAA\"}], \"scene\": 0"},
      {"g_image_view.gltf", "needs a \"mimeType\"", "\"scene\": 0", "\"images\": [{\"bufferView\": 0, \"mimeType\": \"png\"}], \"scene\": 0"},
      {"g_sparse.gltf", "accessor 1 sparse must be an object with \"indices\" and \"values\"", "\"count\": 6,", "\"count\": 6, \"sparse\": {},"},
      {"g_ortho.gltf", "camera 0: \"xmag\" must be a number other than 0", "\"scene\": 0",
       "\"cameras\": [{\"type\": \"orthographic\", \"orthographic\": {\"xmag\": 0, \"ymag\": 1, \"znear\": 0.1, \"zfar\": 9}}], \"scene\": 0"},
      {"g_not_json.gltf", "g_not_json.gltf:1: glTF: a value expected", NULL, "ogeometrynodeff{"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    const char *t = cases[i].find ? subst(GLTF_QUAD, cases[i].find, cases[i].repl) : cases[i].repl;
    CHECK(t, "%s: the template lacks %s", cases[i].name, cases[i].find);
    if (mesh_refused(cases[i].name, t, strlen(t), cases[i].what)) return 1;
  }
  /* a triangle strip of 2 indices (Assimp counted 2 - 2 - 1 triangles: an allocation of 2^64 bytes) */
  char two[8192];
  snprintf(two, sizeof two, "%s", subst(GLTF_QUAD, "\"count\": 6", "\"count\": 2"));
  const char *st = subst(two, "\"indices\": 1}", "\"indices\": 1, \"mode\": 5}");
  CHECK(st, "template");
  if (mesh_refused("g_strip.gltf", st, strlen(st), "2 vertices are too few for its mode 5")) return 1;
  /* a sparse index value past the vertices (the short 49024 at byte 2, in -1.0f) */
  char sp[8192];
  snprintf(sp, sizeof sp, "%s", subst(GLTF_QUAD, "\"count\": 6, \"type\": \"SCALAR\"}", "\"count\": 6, \"type\": \"SCALAR\", "
       "\"sparse\": {\"count\": 1, \"indices\": {\"bufferView\": 2, \"componentType\": 5123}, \"values\": {\"bufferView\": 3}}}"));
  const char *spv = subst(sp, "\"byteLength\": 12}]", "\"byteLength\": 12}, {\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 2}, "
                                                   "{\"buffer\": 0, \"byteOffset\": 2, \"byteLength\": 2}]");
  CHECK(spv, "template");
  if (mesh_refused("g_sparse_index.gltf", spv, strlen(spv), "sparse index value 0 is 49024, past the 4 vertices")) return 1;
  /* .glb containers */
  buf g = {0};
  make_glb(&g, GLTF_QUAD, NULL, 0);
  unsigned char *c = malloc(g.n + 8);
  struct { const char *name, *what; size_t at, len; uint32_t word; } glbs[] = {
      {"g_length.glb", "the header gives the length", 8, g.n, (uint32_t)g.n + 4},
      {"g_chunk.glb", "the first chunk must be JSON and fit", 12, g.n, 0xfffffbb7u},
      {"g_v1.glb", "binary glTF version 1 is not read", 4, g.n, 1},
      {"g_tail.glb", "are not a chunk", 8, g.n + 4, (uint32_t)g.n + 4},
      {"g_magic.gltf", "rename it .glb", 8, g.n, (uint32_t)g.n},
  };
  for (size_t i = 0; i < sizeof glbs / sizeof glbs[0]; i++) {
    memcpy(c, g.d, g.n);
    memset(c + g.n, 0, 8);
    for (int k = 0; k < 4; k++) c[glbs[i].at + (size_t)k] = (unsigned char)(glbs[i].word >> (8 * k));
    if (mesh_refused(glbs[i].name, c, glbs[i].len, glbs[i].what)) { free(c); free(g.d); return 1; }
  }
  free(c);
  free(g.d);
  return 0;
}

/* Formats valo does not check itself go to Assimp in a child process first
 * (import_probe.h): valid STL, OFF, Collada and DirectX files load; a Collada file that
 * crashed Assimp (a float_array whose count is 0 but which holds nine numbers: a
 * segfault), an OFF header claiming billions of vertices (a 22 GB allocation, then more
 * than 30 s filling it) and an import past VALO_IMPORT_TIMEOUT are refused in valo's
 * words, with no crash and no sanitizer report. */
#define DAE_TRIANGLE                                                                                                 \
  "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"                                                                     \
  "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"                             \
  "<library_geometries><geometry id=\"g\"><mesh>\n"                                                                  \
  "<source id=\"p\"><float_array id=\"pa\" count=\"9\">0 0 0 1 0 0 0 1 0</float_array>\n"                            \
  "<technique_common><accessor source=\"#pa\" count=\"3\" stride=\"3\"><param name=\"X\" type=\"float\"/>"           \
  "<param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/></accessor></technique_common></source>\n"    \
  "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>\n"                                     \
  "<triangles count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/><p>0 1 2</p></triangles>\n"         \
  "</mesh></geometry></library_geometries>\n"                                                                        \
  "<library_visual_scenes><visual_scene id=\"s\"><node id=\"n\"><instance_geometry url=\"#g\"/></node>"              \
  "</visual_scene></library_visual_scenes>\n<scene><instance_visual_scene url=\"#s\"/></scene>\n</COLLADA>\n"
static int other_formats(void) {
  static const char stl[] = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                            "endloop\nendfacet\nendsolid t\n";
  static const char off[] = "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3 2\n";
  static const char x[] = "xof 0302txt 0032\nMesh m {\n3;\n0;0;0;,\n1;0;0;,\n0;1;0;;\n1;\n3;0,1,2;;\n}\n";
  unsigned char bstl[84 + 50] = {0};
  bstl[80] = 1; /* one triangle: normal, three vertices, attribute bytes */
  const float tri[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
  memcpy(bstl + 84, tri, sizeof tri);
  if (mesh_loads("o_ascii.stl", stl, strlen(stl)) || mesh_loads("o_binary.stl", bstl, sizeof bstl) ||
      mesh_loads("o_quad.off", off, strlen(off)) || mesh_loads("o_triangle.dae", DAE_TRIANGLE, strlen(DAE_TRIANGLE)) ||
      mesh_loads("o_triangle.x", x, strlen(x)))
    return 1;
  const char *dae = subst(DAE_TRIANGLE, "count=\"9\"", "count=\"0\"");
  CHECK(dae, "template");
  if (mesh_refused("o_crash.dae", dae, strlen(dae), "Assimp crashed reading the file")) return 1;
  char huge[128];
  snprintf(huge, sizeof huge, "OFF%s\n4 21 0\n1  2\n", "7777777777777777777777777777777777777777777777777777777777");
  /* Assimp's std::bad_alloc at valo's limit; under the sanitizers their allocator ends
   * the child first, reported as a crash */
#if defined(__SANITIZE_ADDRESS__)
#define HUGE_SAYS "Assimp crashed reading the file"
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define HUGE_SAYS "Assimp crashed reading the file"
#endif
#endif
#ifndef HUGE_SAYS
#define HUGE_SAYS "Assimp ran out of memory reading the file (std::bad_alloc): it may use 1.0 GiB"
#endif
  if (mesh_refused("o_huge.off", huge, strlen(huge), HUGE_SAYS)) return 1;
  /* the time limit: a valid OFF of 200 000 vertices, which takes Assimp far longer than 1 ms */
  buf b = {0};
  puts_(&b, "OFF\n200000 1 0\n");
  for (int i = 0; i < 200000; i++) puts_(&b, "0.125 0.25 0.5\n");
  puts_(&b, "3 0 1 2\n");
  setenv("VALO_IMPORT_TIMEOUT", "0.001", 1);
  int rc = mesh_refused("o_slow.off", b.d, b.n, "did not finish reading the file within 0.001 s");
  unsetenv("VALO_IMPORT_TIMEOUT");
  free(b.d);
  return rc;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"hdr_decoder_matches_stb", hdr_decoder_matches_stb},
                                    {"hdr_damaged", hdr_damaged},
                                    {"ply_valid_forms", ply_valid_forms},
                                    {"ply_ascii_damaged", ply_ascii_damaged},
                                    {"ply_binary_damaged", ply_binary_damaged},
                                    {"ply_dragon_mutations", ply_dragon_mutations},
                                    {"png_jpeg_damaged", png_jpeg_damaged},
                                    {"exr_damaged", exr_damaged},
                                    {"pfm_damaged", pfm_damaged},
                                    {"gltf_valid_forms", gltf_valid_forms},
                                    {"gltf_damaged", gltf_damaged},
                                    {"other_formats", other_formats},
                                    {NULL, NULL}};
  return test_main(argc, argv, cases);
}
