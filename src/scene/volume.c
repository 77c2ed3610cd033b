/* volume.c — see volume.h. */
#include "scene/volume.h"
#include "core/error.h"
#include "core/memlimit.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int read_i32(FILE *f, int32_t *v) { return fread(v, 4, 1, f) == 1; }
static int clamp_index(int i, int n) { return i < 0 ? 0 : i > n - 1 ? n - 1 : i; }

valo_status density_grid_load(const char *path, density_grid **out, valo_error *err) {
  *out = NULL;
  FILE *f = fopen(path, "rb");
  if (!f) return err_set(err, VALO_ERR_IO, "%s: cannot open the density grid", path);
  char magic[4];
  int32_t enc, n[3], ch;
  float box[6];
  valo_status st = VALO_OK;
  density_grid *g = NULL;
  unsigned char *raw = NULL;
  if (fread(magic, 1, 4, f) != 4 || memcmp(magic, "VOL", 3) || magic[3] != 3) {
    st = err_set(err, VALO_ERR_PARSE, "%s: not a version 3 .vol grid (Mitsuba's format: \"VOL\" and the byte 3)", path);
    goto done;
  }
  if (!read_i32(f, &enc) || !read_i32(f, &n[0]) || !read_i32(f, &n[1]) || !read_i32(f, &n[2]) || !read_i32(f, &ch) ||
      fread(box, 4, 6, f) != 6) {
    st = err_set(err, VALO_ERR_PARSE, "%s: the .vol header is truncated", path);
    goto done;
  }
  if (enc != 1 && enc != 3) {
    st = err_set(err, VALO_ERR_UNSUPPORTED, "%s: .vol encoding %d (valo reads 1, float32, and 3, uint8)", path, (int)enc);
    goto done;
  }
  if (ch != 1) {
    st = err_set(err, VALO_ERR_UNSUPPORTED, "%s: %d channels (a density grid has one)", path, (int)ch);
    goto done;
  }
  if (n[0] < 1 || n[1] < 1 || n[2] < 1 || n[0] > 4096 || n[1] > 4096 || n[2] > 4096) {
    st = err_set(err, VALO_ERR_PARSE, "%s: grid size %d x %d x %d (each 1 to 4096)", path, (int)n[0], (int)n[1], (int)n[2]);
    goto done;
  }
  for (int k = 0; k < 6; k++)
    if (!isfinite(box[k])) { st = err_set(err, VALO_ERR_PARSE, "%s: the grid's box is not finite", path); goto done; }
  uint64_t count = (uint64_t)n[0] * n[1] * n[2];
  if ((st = mem_check(count * 4, path, "density grid", err))) goto done;
  /* float32 values are read straight into the grid, uint8 ones through a byte buffer */
  g = calloc(1, sizeof *g);
  if (!g || !(g->d = malloc(count * sizeof(float))) || (enc == 3 && !(raw = malloc(count)))) {
    st = err_set(err, VALO_ERR_NOMEM, "%s: out of memory", path);
    goto done;
  }
  if (fread(enc == 1 ? (void *)g->d : (void *)raw, enc == 1 ? 4 : 1, count, f) != count) {
    st = err_set(err, VALO_ERR_PARSE, "%s: the file ends before its %d x %d x %d values", path, (int)n[0], (int)n[1], (int)n[2]);
    goto done;
  }
  g->nx = n[0]; g->ny = n[1]; g->nz = n[2];
  g->box.lo = v3(box[0], box[1], box[2]);
  g->box.hi = v3(box[3], box[4], box[5]);
  g->dmax = 0;
  for (uint64_t i = 0; i < count; i++) {
    float v = enc == 1 ? g->d[i] : raw[i] / 255.0f;
    if (!isfinite(v) || v < 0) {
      st = err_set(err, VALO_ERR_PARSE, "%s: value %llu is %g (densities are finite and not negative)", path, (unsigned long long)i, (double)v);
      goto done;
    }
    g->d[i] = v;
    if (v > g->dmax) g->dmax = v;
  }
done:
  fclose(f);
  free(raw);
  if (st) density_grid_free(g);
  else *out = g;
  return st;
}

void density_grid_free(density_grid *g) {
  if (!g) return;
  free(g->d);
  free(g);
}

float density_grid_at(const density_grid *g, vec3 p) {
  vec3 e = v3_sub(g->box.hi, g->box.lo);
  float u[3] = {(p.x - g->box.lo.x) / e.x, (p.y - g->box.lo.y) / e.y, (p.z - g->box.lo.z) / e.z};
  if (!(u[0] >= 0 && u[0] <= 1 && u[1] >= 0 && u[1] <= 1 && u[2] >= 0 && u[2] <= 1)) return 0;
  int n[3] = {g->nx, g->ny, g->nz}, i0[3], i1[3];
  float w[3];
  for (int k = 0; k < 3; k++) {
    float x = u[k] * n[k] - 0.5f, fl = floorf(x);
    w[k] = x - fl;
    i0[k] = clamp_index((int)fl, n[k]);
    i1[k] = clamp_index((int)fl + 1, n[k]);
  }
#define D(x, y, z) g->d[((size_t)(z) * g->ny + (y)) * g->nx + (x)]
  float c00 = D(i0[0], i0[1], i0[2]) * (1 - w[0]) + D(i1[0], i0[1], i0[2]) * w[0];
  float c10 = D(i0[0], i1[1], i0[2]) * (1 - w[0]) + D(i1[0], i1[1], i0[2]) * w[0];
  float c01 = D(i0[0], i0[1], i1[2]) * (1 - w[0]) + D(i1[0], i0[1], i1[2]) * w[0];
  float c11 = D(i0[0], i1[1], i1[2]) * (1 - w[0]) + D(i1[0], i1[1], i1[2]) * w[0];
#undef D
  float c0 = c00 * (1 - w[1]) + c10 * w[1], c1 = c01 * (1 - w[1]) + c11 * w[1];
  return c0 * (1 - w[2]) + c1 * w[2];
}
