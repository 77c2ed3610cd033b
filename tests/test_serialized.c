/* test_serialized.c — Mitsuba's .serialized meshes (src/load/serialized.c): files written
 * here in both versions (3 and 4; float and double; normals, texture coordinates and
 * colours each present or not; several shapes; one larger than the first decode's buffer)
 * read back as written; damaged files refused with a message naming the file and the
 * shape; and the real file of ../shared/scenes/torus, read through its own scene.xml, holds
 * the triangles of the OBJ another tool converted from it. Against Mitsuba's renders:
 * test_mitsuba sponza_serialized_xml. */
#include "harness.h"
#include "load/load.h"
#include "load/serialized.h"
#include "scene/scene.h"
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* stb_image_write's zlib compressor (exported by libstb; its header declares it only
 * inside the implementation). */
unsigned char *stbi_zlib_compress(unsigned char *data, int data_len, int *out_len, int quality);

typedef struct bytes { unsigned char *b; size_t n, cap; } bytes;
static void put(bytes *o, const void *p, size_t n) {
  if (o->n + n > o->cap) {
    o->cap = 2 * (o->n + n) + 64;
    o->b = realloc(o->b, o->cap);
  }
  memcpy(o->b + o->n, p, n);
  o->n += n;
}
static void put32(bytes *o, uint32_t v) { put(o, &v, 4); }
static void put64(bytes *o, uint64_t v) { put(o, &v, 8); }
static void put_reals(bytes *o, const double *v, size_t n, int dbl) {
  for (size_t k = 0; k < n; k++) {
    if (dbl) put(o, &v[k], 8);
    else { float f = (float)v[k]; put(o, &f, 4); }
  }
}

enum { F_NRM = 1, F_UV = 2, F_COL = 8, F_FACE = 0x10, F_DBL = 0x2000 };
typedef struct shape {
  uint32_t flags;
  const char *name;
  uint32_t nv, nt;
  const double *pos, *nrm, *uv, *col;
  const uint32_t *idx;
  uint64_t claim_nv; /* when set, the vertex count the header claims */
  size_t extra;      /* bytes of padding after the data */
} shape;

/* A shape's uncompressed stream. */
static void shape_raw(bytes *o, int version, const shape *s) {
  put32(o, s->flags);
  if (version == 4) put(o, s->name ? s->name : "", strlen(s->name ? s->name : "") + 1);
  put64(o, s->claim_nv ? s->claim_nv : s->nv);
  put64(o, s->nt);
  int d = (s->flags & F_DBL) != 0;
  put_reals(o, s->pos, 3 * (size_t)s->nv, d);
  if (s->flags & F_NRM) put_reals(o, s->nrm, 3 * (size_t)s->nv, d);
  if (s->flags & F_UV) put_reals(o, s->uv, 2 * (size_t)s->nv, d);
  if (s->flags & F_COL) put_reals(o, s->col, 3 * (size_t)s->nv, d);
  put(o, s->idx, 12 * (size_t)s->nt);
  for (size_t k = 0; k < s->extra; k++) put(o, "", 1);
}

/* Writes a file of n shapes to the scratch folder; returns its path. */
static const char *write_file(const char *name, int version, const shape *sh, int n) {
  bytes f = {0};
  uint64_t off[8];
  for (int i = 0; i < n; i++) {
    off[i] = f.n;
    uint16_t hdr[2] = {0x041C, (uint16_t)version};
    put(&f, hdr, 4);
    bytes raw = {0};
    shape_raw(&raw, version, &sh[i]);
    int zlen;
    unsigned char *z = stbi_zlib_compress(raw.b, (int)raw.n, &zlen, 8);
    put(&f, z, (size_t)zlen);
    free(z);
    free(raw.b);
  }
  for (int i = 0; i < n; i++) {
    if (version == 4) put64(&f, off[i]);
    else put32(&f, (uint32_t)off[i]);
  }
  put32(&f, (uint32_t)n);
  const char *path = scratch_path(name);
  FILE *fp = fopen(path, "wb");
  fwrite(f.b, 1, f.n, fp);
  fclose(fp);
  free(f.b);
  return path;
}

/* A unit quad at z = 0 facing +z, and a triangle. */
static const double QP[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
static const double QN[] = {0, 0, 2, 0, 0, 2, 0, 0, 2, 0, 0, 2}; /* not unit: normalised on reading */
static const double QUV[] = {0, 0, 1, 0, 1, 1, 0.25, 0.75};
static const double QC[] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
static const uint32_t QI[] = {0, 1, 2, 0, 2, 3};
static const double TP[] = {0, 0, 5, 1, 0, 5, 0, 1, 5};
static const uint32_t TI[] = {0, 1, 2};

static int near1(double a, double x) { return fabs(a - x) < 1e-6 * (1 + fabs(x)); }
static int near3(vec3 a, double x, double y, double z) { return near1(a.x, x) && near1(a.y, y) && near1(a.z, z); }

static int load(const char *path, int index, const float *xf, int flat, scene **out, valo_error *err) {
  *out = scene_new(path);
  return load_serialized(*out, path, index, xf, UINT32_MAX, flat ? LOAD_MESH_FLAT : 0, err);
}

static int reads_shapes(void) {
  for (int version = 3; version <= 4; version++) {
    shape sh[2] = {{F_NRM | F_UV | F_COL, "quad", 4, 2, QP, QN, QUV, QC, QI, 0, 0}, {F_DBL, "tri", 3, 1, TP, NULL, NULL, NULL, TI, 0, 0}};
    const char *path = write_file(version == 4 ? "v4.serialized" : "v3.serialized", version, sh, 2);
    CHECK(serialized_count(path, NULL) == 2, "version %d: %u shapes", version, serialized_count(path, NULL));
    scene *s;
    valo_error err;
    /* Shape 0: colours skipped, normals normalised, v turned up. */
    CHECK(load(path, 0, NULL, 0, &s, &err) == VALO_OK, "%s", err.message);
    CHECK(s->ntris == 2 && s->nverts == 4, "version %d: %u triangles, %u vertices", version, s->ntris, s->nverts);
    CHECK(near3(s->pos[2], 1, 1, 0) && near3(s->nrm[1], 0, 0, 1), "version %d: vertex 2 or normal 1 wrong", version);
    CHECK(fabsf(s->uv[6] - 0.25f) < 1e-6f && fabsf(s->uv[7] - 0.25f) < 1e-6f, "version %d: uv of vertex 3 (%g %g), not (0.25, 1 - 0.75)", version,
          (double)s->uv[6], (double)s->uv[7]);
    CHECK(s->tri_flags[0] == (TRI_HAS_NORMALS | TRI_HAS_UVS) && s->idx[3] == 0 && s->idx[4] == 2 && s->idx[5] == 3, "version %d: flags %d, indices", version,
          s->tri_flags[0]);
    scene_free(s);
    /* Shape 1 (double precision) placed by a transform: x2, then moved by (1, 2, 3). */
    const float xf[12] = {2, 0, 0, 1, 0, 2, 0, 2, 0, 0, 2, 3};
    CHECK(load(path, 1, xf, 0, &s, &err) == VALO_OK, "%s", err.message);
    CHECK(s->ntris == 1 && near3(s->pos[1], 3, 2, 13) && s->tri_flags[0] == 0, "version %d: shape 1 placed wrong", version);
    scene_free(s);
    /* Every shape; a mirroring transform keeps each triangle's facing (winding swapped). */
    const float mirror[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0};
    CHECK(load(path, -1, mirror, 1, &s, &err) == VALO_OK, "%s", err.message);
    CHECK(s->ntris == 3 && s->tri_flags[0] == TRI_HAS_UVS, "version %d: %u triangles, flags %d (flat asked)", version, s->ntris, s->tri_flags[0]);
    vec3 ng = scene_tri_ng(s, 0);
    CHECK(ng.z < 0 && near3(s->nrm[0], 0, 0, -1), "version %d: the mirrored quad faces %g, its normal %g", version, (double)ng.z, (double)s->nrm[0].z);
    scene_free(s);
  }
  /* The file's face-normal flag; and a shape larger than the first decode (256 KiB). */
  enum { G = 160 };
  double *gp = malloc(sizeof(double) * 3 * G * G), *gn = malloc(sizeof(double) * 3 * G * G);
  uint32_t *gi = malloc(sizeof(uint32_t) * 6 * (G - 1) * (G - 1)), nt = 0;
  for (int y = 0; y < G; y++)
    for (int x = 0; x < G; x++) {
      double *p = &gp[3 * (y * G + x)], *n = &gn[3 * (y * G + x)];
      p[0] = x; p[1] = y; p[2] = 0.01 * x * y; n[0] = 0; n[1] = 0; n[2] = 1;
      if (x + 1 < G && y + 1 < G) {
        uint32_t a = (uint32_t)(y * G + x), q[6] = {a, a + 1, a + G + 1, a, a + G + 1, a + G};
        memcpy(&gi[3 * nt], q, sizeof q);
        nt += 2;
      }
    }
  shape big[2] = {{F_NRM | F_FACE, "faceted", 4, 2, QP, QN, NULL, NULL, QI, 0, 0}, {F_NRM | F_DBL, "grid", G * G, nt, gp, gn, NULL, NULL, gi, 0, 0}};
  const char *path = write_file("big.serialized", 4, big, 2);
  scene *s;
  valo_error err;
  CHECK(load(path, -1, NULL, 0, &s, &err) == VALO_OK, "%s", err.message);
  CHECK(s->ntris == 2 + nt && s->tri_flags[0] == 0 && s->tri_flags[2] == TRI_HAS_NORMALS, "%u triangles; flags %d %d", s->ntris, s->tri_flags[0],
        s->tri_flags[2]);
  CHECK(near3(s->pos[4 + G * G - 1], G - 1, G - 1, 0.01 * (G - 1) * (G - 1)), "the grid's last vertex");
  scene_free(s);
  free(gp); free(gn); free(gi);
  return 0;
}

static int bad_files(void) {
  shape ok = {F_NRM | F_UV, "quad", 4, 2, QP, QN, QUV, NULL, QI, 0, 0};
  const char *good = write_file("good.serialized", 4, &ok, 1);
  char *text = NULL;
  size_t len = 0;
  { FILE *f = fopen(good, "rb"); fseek(f, 0, SEEK_END); len = (size_t)ftell(f); fseek(f, 0, SEEK_SET); text = malloc(len); CHECK(fread(text, 1, len, f) == len, "read"); fclose(f); }
  /* Damaged copies of the good file. */
  struct { const char *name, *said; size_t at; unsigned char byte; size_t cut; } mut[] = {
      {"magic.serialized", "not a Mitsuba serialized mesh file", 0, 0x1D, 0},
      {"version.serialized", "version 5", 2, 5, 0},
      {"count.serialized", "table of shapes is damaged", len - 4, 0, 0},
      {"count-big.serialized", "table of shapes is damaged", len - 1, 0x7f, 0},
      {"offset.serialized", "does not lead to a shape's header", len - 12, 9, 0},
      {"zlib.serialized", "compressed data is damaged", 4, 0x00, 0},
      {"cut.serialized", "", 0, 0, len / 2},
  };
  for (size_t k = 0; k < sizeof mut / sizeof mut[0]; k++) {
    char *t = malloc(len);
    memcpy(t, text, len);
    size_t n = len - mut[k].cut;
    if (!mut[k].cut) t[mut[k].at] = (char)mut[k].byte;
    const char *p = scratch_path(mut[k].name);
    FILE *f = fopen(p, "wb");
    fwrite(t, 1, n, f);
    fclose(f);
    free(t);
    scene *s;
    valo_error err;
    int st = load(p, 0, NULL, 0, &s, &err);
    scene_free(s);
    CHECK(st != VALO_OK && strstr(err.message, mut[k].name) && strstr(err.message, mut[k].said), "%s: %s", mut[k].name, st ? err.message : "read");
  }
  free(text);
  /* Files whose streams say wrong things. */
  char longname[1500];
  memset(longname, 'n', sizeof longname - 1);
  longname[sizeof longname - 1] = 0;
  const double nanp[] = {0, 0, 0, 1, 0, 0, NAN, 1, 0, 0, 1, 0};
  const uint32_t far_idx[] = {0, 1, 2, 0, 2, 4};
  const double flat_p[] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0};
  struct { const char *name, *said; shape s; int index; } bad[] = {
      {"early.serialized", "ends early", {F_NRM, "q", 4, 2, QP, QN, NULL, NULL, QI, 6, 0}, 0},
      {"more.serialized", "more data than its header says", {F_NRM, "q", 4, 2, QP, QN, NULL, NULL, QI, 0, 300000}, 0},
      {"one-more.serialized", "more data than its header says", {F_NRM, "q", 4, 2, QP, QN, NULL, NULL, QI, 0, 1}, 0},
      {"huge.serialized", "up to 2^32 - 1", {0, "q", 4, 2, QP, NULL, NULL, NULL, QI, 1ull << 40, 0}, 0},
      {"ratio.serialized", "more than its", {0, "q", 4, 2, QP, NULL, NULL, NULL, QI, 1ull << 31, 0}, 0},
      {"index.serialized", "shape 0 'q' triangle 1 has a vertex index out of range (4 vertices)", {0, "q", 4, 2, QP, NULL, NULL, NULL, far_idx, 0, 0}, 0},
      {"nan.serialized", "shape 0 'q' vertex 2 is not finite", {0, "q", 4, 2, nanp, NULL, NULL, NULL, QI, 0, 0}, 0},
      {"name.serialized", "name is not ended", {0, longname, 4, 2, QP, NULL, NULL, NULL, QI, 0, 0}, 0},
      {"degenerate.serialized", "no usable triangles (2 degenerate)", {0, "q", 4, 2, flat_p, NULL, NULL, NULL, QI, 0, 0}, 0},
      {"index-of.serialized", "shape_index 3, but the file holds 1 shapes", {0, "q", 4, 2, QP, NULL, NULL, NULL, QI, 0, 0}, 3},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    const char *p = write_file(bad[k].name, 4, &bad[k].s, 1);
    scene *s;
    valo_error err;
    int st = load(p, bad[k].index, NULL, 0, &s, &err);
    scene_free(s);
    CHECK(st != VALO_OK && strstr(err.message, bad[k].name) && strstr(err.message, bad[k].said), "%s: %s", bad[k].name, st ? err.message : "read");
  }
  scene *s;
  valo_error err;
  CHECK(load(scratch_path("absent.serialized"), 0, NULL, 0, &s, &err) != VALO_OK && strstr(err.message, "cannot open"), "absent file");
  scene_free(s);
  return 0;
}

/* A small file whose table lists one shape many times (a 1 MB file listing a 20 000-
 * triangle shape 100 000 times once made 5 GB before failing): refused at once, naming the
 * two entries, through the Mitsuba reader and as a file of its own; every listed shape
 * read, and each decoded once, when they are apart. */
static int repeated_table(void) {
  enum { NT = 2000, REPEAT = 100000 };
  double *p = malloc(9 * NT * sizeof *p);
  uint32_t *idx = malloc(3 * NT * sizeof *idx);
  CHECK(p && idx, "memory");
  for (int t = 0; t < NT; t++) {
    for (int k = 0; k < 9; k++) p[9 * t + k] = (k % 3 == 2 ? 0 : t % 7) + (k == 3 || k == 7);
    for (int k = 0; k < 3; k++) idx[3 * t + k] = (uint32_t)(3 * t + k);
  }
  shape sh = {0, "many", 3 * NT, NT, p, NULL, NULL, NULL, idx, 0, 0};
  const char *one = write_file("repeat-one.serialized", 4, &sh, 1);
  /* the same file with its one-entry table replaced by REPEAT entries of offset 0 */
  FILE *in = fopen(one, "rb");
  CHECK(in, "%s", one);
  fseek(in, 0, SEEK_END);
  long n = ftell(in) - 12;
  fseek(in, 0, SEEK_SET);
  unsigned char *b = malloc((size_t)n);
  CHECK(b && fread(b, 1, (size_t)n, in) == (size_t)n, "read");
  fclose(in);
  const char *many = scratch_path("repeat-many.serialized");
  FILE *out = fopen(many, "wb");
  CHECK(out, "%s", many);
  fwrite(b, 1, (size_t)n, out);
  uint64_t zero = 0;
  for (int i = 0; i < REPEAT; i++) fwrite(&zero, 8, 1, out);
  uint32_t cnt = REPEAT;
  fwrite(&cnt, 4, 1, out);
  fclose(out);
  free(b); free(p); free(idx);
  valo_error err;
  valo_scene *sc;
  CHECK(valo_scene_load(many, &sc, &err) != VALO_OK, "a table repeating one shape %d times loaded", REPEAT);
  CHECK(strstr(err.message, "repeat-many.serialized") && strstr(err.message, "shapes 0 and 1 both start at offset 0"), "said: %s", err.message);
  char xml[2048];
  snprintf(xml, sizeof xml, "<scene version=\"3.0.0\"><sensor type=\"perspective\"/>\n<shape type=\"serialized\">"
                            "<string name=\"filename\" value=\"repeat-many.serialized\"/><integer name=\"shape_index\" value=\"7\"/></shape>\n</scene>\n");
  CHECK(valo_scene_load(scratch_file("repeat.xml", xml), &sc, &err) != VALO_OK, "the Mitsuba scene loaded");
  CHECK(strstr(err.message, "both start at offset 0") && strstr(err.message, "line 2"), "said: %s", err.message);
  CHECK(valo_scene_load(one, &sc, &err) == VALO_OK, "%s", err.message);
  valo_scene_destroy(sc);
  return 0;
}

/* The cube [-1, 1]^3, each face split along a diagonal, so that a corner meets one
 * triangle of one face and two of another. */
static const double CP[] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1};
static const uint32_t CI[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 3, 6, 2, 3, 7, 6, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};

/* A mesh without normals, shaded smooth as Mitsuba shades it: at each vertex the mean of
 * its faces' normals weighted by their angles there, so a cube's corner points along the
 * diagonal however its faces are split (weights by area or by count would tilt it). */
static int computed_normals(void) {
  shape cube = {0, "cube", 8, 12, CP, NULL, NULL, NULL, CI, 0, 0};
  const char *path = write_file("cube.serialized", 4, &cube, 1);
  const float mirror[12] = {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  for (int m = 0; m < 2; m++) {
    scene *s = scene_new(path);
    valo_error err;
    CHECK(load_serialized(s, path, 0, m ? mirror : NULL, UINT32_MAX, LOAD_MESH_SMOOTH, &err) == VALO_OK, "%s", err.message);
    for (uint32_t v = 0; v < 8; v++) {
      vec3 p = s->pos[v], n = s->nrm[v];
      double k = 1 / sqrt(3.0);
      CHECK(near1(n.x, k * p.x) && near1(n.y, k * p.y) && near1(n.z, k * p.z), "%s: vertex %u at (%g %g %g): normal (%g %g %g)", m ? "mirrored" : "as written",
            v, (double)p.x, (double)p.y, (double)p.z, (double)n.x, (double)n.y, (double)n.z);
    }
    for (uint32_t t = 0; t < 12; t++) CHECK(s->tri_flags[t] == TRI_HAS_NORMALS, "triangle %u flags %d", t, s->tri_flags[t]);
    scene_free(s);
  }
  /* An OBJ's corners are separate vertices until joined: the same normals through the JSON
   * key and through a Mitsuba scene; none without the key or with face_normals. */
  char obj[1024] = "", *o = obj;
  for (int v = 0; v < 8; v++) o += sprintf(o, "v %g %g %g\n", CP[3 * v], CP[3 * v + 1], CP[3 * v + 2]);
  for (int t = 0; t < 12; t++) o += sprintf(o, "f %u %u %u\n", CI[3 * t] + 1, CI[3 * t + 1] + 1, CI[3 * t + 2] + 1);
  scratch_file("cube.obj", obj);
  static const char *const scenes[][2] = {
      {"cube-smooth.json", "{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0]}, \"shapes\": [{\"file\": \"cube.obj\", \"smooth_normals\": true}]}"},
      {"cube-flat.json", "{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0]}, \"shapes\": [{\"file\": \"cube.obj\"}]}"},
      {"cube-smooth.xml", "<scene version=\"3.0.0\"><sensor type=\"perspective\"/><shape type=\"obj\"><string name=\"filename\" value=\"cube.obj\"/></shape></scene>"},
      {"cube-flat.xml", "<scene version=\"3.0.0\"><sensor type=\"perspective\"/><shape type=\"obj\"><string name=\"filename\" value=\"cube.obj\"/>"
                        "<boolean name=\"face_normals\" value=\"true\"/></shape></scene>"}};
  for (int k = 0; k < 4; k++) {
    const char *sp = scratch_file(scenes[k][0], scenes[k][1]);
    scene *s;
    valo_options f;
    valo_options_init(&f);
    valo_error err;
    CHECK(scene_load(sp, NULL, &s, &f, &err) == VALO_OK, "%s: %s", scenes[k][0], err.message);
    int smooth = strstr(scenes[k][0], "smooth") != NULL;
    CHECK(s->ntris == 12, "%s: %u triangles", scenes[k][0], s->ntris);
    for (uint32_t t = 0; t < 12; t++) {
      CHECK((s->tri_flags[t] & TRI_HAS_NORMALS) == (smooth ? TRI_HAS_NORMALS : 0), "%s: triangle %u flags %d", scenes[k][0], t, s->tri_flags[t]);
      for (int c = 0; c < 3 && smooth; c++) {
        uint32_t v = s->idx[3 * t + c];
        vec3 p = s->pos[v], n = s->nrm[v];
        double q = 1 / sqrt(3.0);
        CHECK(near1(n.x, q * p.x) && near1(n.y, q * p.y) && near1(n.z, q * p.z), "%s: corner at (%g %g %g): normal (%g %g %g)", scenes[k][0], (double)p.x,
              (double)p.y, (double)p.z, (double)n.x, (double)n.y, (double)n.z);
      }
    }
    scene_free(s);
  }
  return 0;
}

/* A triangle's corners: position, normal, uv. */
typedef struct tri_rec { float v[3][8]; } tri_rec;
static void tri_of(const scene *s, uint32_t t, tri_rec *r) {
  for (int k = 0; k < 3; k++) {
    uint32_t i = s->idx[3 * t + k];
    float row[8] = {s->pos[i].x, s->pos[i].y, s->pos[i].z, s->nrm[i].x, s->nrm[i].y, s->nrm[i].z, s->uv[2 * i], s->uv[2 * i + 1]};
    memcpy(r->v[k], row, sizeof row);
  }
}

static int torus_matches_obj(void) {
  const char *xml = shared_file("scenes/torus/mitsuba-source/scene.xml"), *obj = shared_file("scenes/torus/torus.obj");
  if (!xml || !obj) return TEST_SKIP;
  valo_load_options lo;
  valo_load_options_init(&lo);
  snprintf(lo.defines, sizeof lo.defines, "integrator=path");
  scene *a, *b;
  valo_options fa, fb;
  valo_options_init(&fa);
  valo_options_init(&fb);
  valo_error err;
  CHECK(scene_load(xml, &lo, &a, &fa, &err) == VALO_OK, "%s", err.message);
  CHECK(scene_load(obj, NULL, &b, &fb, &err) == VALO_OK, "%s", err.message);
  CHECK(a->ntris == 23614 && b->ntris == a->ntris, "%u and %u triangles, not 23614", a->ntris, b->ntris);
  /* In the same order: the OBJ's objects are the XML's shapes, its faces theirs. */
  double worst[3] = {0, 0, 0};
  uint32_t smooth = 0;
  for (uint32_t t = 0; t < a->ntris; t++) {
    tri_rec ra, rb;
    tri_of(a, t, &ra);
    tri_of(b, t, &rb);
    for (int k = 0; k < 3; k++)
      for (int j = 0; j < 8; j++) {
        double d = fabs(ra.v[k][j] - rb.v[k][j]) / (j < 3 ? 1 + fabs(rb.v[k][j]) : 1);
        if (d > worst[j < 3 ? 0 : j < 6 ? 1 : 2]) worst[j < 3 ? 0 : j < 6 ? 1 : 2] = d;
      }
    smooth += (a->tri_flags[t] & TRI_HAS_NORMALS) != 0;
    CHECK(a->tri_flags[t] == b->tri_flags[t], "triangle %u: flags %d (xml) and %d (obj)", t, a->tri_flags[t], b->tri_flags[t]);
  }
  fprintf(stderr, "torus: %u triangles (%u smooth); largest differences from the OBJ: positions %.2g (relative), normals %.2g, uv %.2g\n", a->ntris,
          smooth, worst[0], worst[1], worst[2]);
  scene_free(a);
  scene_free(b);
  CHECK(worst[0] < 1e-5 && worst[1] < 1e-4 && worst[2] < 1e-5, "the meshes differ");
  return 0;
}

int main(int argc, char **argv) {
  static const test_case cases[] = {{"reads_shapes", reads_shapes}, {"bad_files", bad_files}, {"computed_normals", computed_normals}, {"torus_matches_obj", torus_matches_obj}, {"repeated_table", repeated_table}, {NULL, NULL}};
  return test_main(argc, argv, cases);
}
