/* envmap.c — see envmap.h. */
#include "scene/envmap.h"
#include "image/image_io.h"
#include "image/texture.h"
#include "core/error.h"
#include <stdlib.h>
#include <string.h>

static vec3 to_map(const envmap *e, vec3 d) { /* world -> map frame: rotate by -rotation about y, or by the frame's transpose */
  if (e->has_frame) {
    const float *f = e->frame;
    return v3(f[0] * d.x + f[3] * d.y + f[6] * d.z, f[1] * d.x + f[4] * d.y + f[7] * d.z, f[2] * d.x + f[5] * d.y + f[8] * d.z);
  }
  return v3(e->rot_cos * d.x - e->rot_sin * d.z, d.y, e->rot_sin * d.x + e->rot_cos * d.z);
}
static vec3 from_map(const envmap *e, vec3 d) {
  if (e->has_frame) {
    const float *f = e->frame;
    return v3(f[0] * d.x + f[1] * d.y + f[2] * d.z, f[3] * d.x + f[4] * d.y + f[5] * d.z, f[6] * d.x + f[7] * d.y + f[8] * d.z);
  }
  return v3(e->rot_cos * d.x + e->rot_sin * d.z, d.y, -e->rot_sin * d.x + e->rot_cos * d.z);
}

int envmap_set_frame(envmap *e, const double m[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double dot = m[i] * m[j] + m[3 + i] * m[3 + j] + m[6 + i] * m[6 + j]; /* columns i and j */
      if (!isfinite(dot) || fabs(dot - (i == j)) > 1e-3) return -1;
    }
  for (int k = 0; k < 9; k++) e->frame[k] = (float)m[k];
  e->has_frame = 1;
  return 0;
}
static void dir_to_uv(vec3 d, float *u, float *v) {
  float phi = atan2f(d.x, -d.z);
  *u = 0.5f + phi * (0.5f * INV_PI_F);
  *v = acosf(clampf(d.y, -1, 1)) * INV_PI_F;
  if (*u >= 1) *u -= 1;
  if (*u < 0) *u += 1;
}
static vec3 uv_to_dir(float u, float v) {
  float phi = (u - 0.5f) * 2 * PI_F, th = v * PI_F;
  float st = sinf(th);
  return v3(st * sinf(phi), cosf(th), -st * cosf(phi));
}

static rgb texel(const envmap *e, int x, int y) {
  x %= e->w;
  if (x < 0) x += e->w;
  y = y < 0 ? 0 : (y >= e->h ? e->h - 1 : y);
  const float *p = &e->rgb[3 * ((size_t)y * e->w + x)];
  return c3(p[0], p[1], p[2]);
}

static rgb lookup(const envmap *e, float u, float v) {
  /* texel centres at ((x + 0.5)/w, (y + 0.5)/h); Mitsuba's rows at v = y/(h - 1) */
  float x = u * e->w - 0.5f, y = e->mitsuba_rows ? v * (e->h - 1) : v * e->h - 0.5f;
  int x0 = (int)floorf(x), y0 = (int)floorf(y);
  float fx = x - x0, fy = y - y0;
  rgb a = texel(e, x0, y0), b = texel(e, x0 + 1, y0), c = texel(e, x0, y0 + 1), d = texel(e, x0 + 1, y0 + 1);
  rgb top = c3_add(c3_scale(a, 1 - fx), c3_scale(b, fx)), bot = c3_add(c3_scale(c, 1 - fx), c3_scale(d, fx));
  return c3_add(c3_scale(top, 1 - fy), c3_scale(bot, fy));
}

/* The sampling density: the bilinear interpolant of each lookup's largest channel times
 * sin(theta), given at the lookup's own vertices (the texel centres, plus the seam at
 * u = 0 and 1 and the poles, where the lookup is clamped), so it is positive wherever the
 * radiance is and the ratio of radiance to density stays bounded next to small bright
 * texels. A floor of 1/1000 of the mean keeps every direction reachable. */
static int build_dist(envmap *e) {
  int w = e->w, h = e->h, mr = e->mitsuba_rows && h >= 2;
  uint32_t nx = (uint32_t)w + 2, ny = mr ? (uint32_t)h : (uint32_t)h + 2;
  float *xs = malloc(nx * sizeof(float)), *ys = malloc(ny * sizeof(float)), *f = malloc((size_t)nx * ny * sizeof(float));
  int rc = -1;
  if (xs && ys && f) {
    xs[0] = 0; xs[nx - 1] = 1;
    for (int x = 0; x < w; x++) xs[x + 1] = (x + 0.5f) / (float)w;
    if (mr)
      for (int y = 0; y < h; y++) ys[y] = y == h - 1 ? 1 : (float)y / (float)(h - 1);
    else {
      ys[0] = 0; ys[ny - 1] = 1;
      for (int y = 0; y < h; y++) ys[y + 1] = (y + 0.5f) / (float)h;
    }
    double sum = 0;
    for (uint32_t j = 0; j < ny; j++) {
      float st = sinf(PI_F * ys[j]);
      for (uint32_t i = 0; i < nx; i++) {
        float m = c3_max(lookup(e, xs[i], ys[j])) * st;
        f[(size_t)j * nx + i] = m;
        sum += m;
      }
    }
    float floor_w = (float)(sum / ((double)nx * ny) * 1e-3 + 1e-12);
    for (uint32_t j = 0; j < ny; j++)
      for (uint32_t i = 0; i < nx; i++) f[(size_t)j * nx + i] += floor_w * sinf(PI_F * ys[j]);
    bilin2d_free(&e->dist);
    rc = bilin2d_init(&e->dist, xs, nx, ys, ny, f);
  }
  free(xs); free(ys); free(f);
  return rc;
}

int envmap_init(envmap *e, int w, int h, float *px, float scale, float rotation_deg) {
  memset(e, 0, sizeof *e);
  e->w = w; e->h = h; e->rgb = px; e->scale = scale;
  float r = rotation_deg * PI_F / 180;
  e->rot_cos = cosf(r); e->rot_sin = sinf(r);
  for (size_t i = 0; i < (size_t)w * h * 3; i++)
    if (!(px[i] >= 0) || !isfinite(px[i])) px[i] = 0; /* negative/NaN texels carry no light */
  double avg[3] = {0, 0, 0}, solid = 0;
  for (int y = 0; y < h; y++) {
    float st = sinf(PI_F * (y + 0.5f) / h);
    for (int x = 0; x < w; x++) {
      rgb t = texel(e, x, y);
      avg[0] += t.r * st; avg[1] += t.g * st; avg[2] += t.b * st;
      solid += st;
    }
  }
  e->average = solid > 0 ? c3((float)(avg[0] / solid) * scale, (float)(avg[1] / solid) * scale, (float)(avg[2] / solid) * scale) : c3(0, 0, 0);
  return build_dist(e);
}

int envmap_set_mitsuba_rows(envmap *e, int on) {
  if (e->mitsuba_rows == !!on) return 0;
  e->mitsuba_rows = !!on;
  return build_dist(e);
}

/* The map's linear RGB: an HDR file (.exr, .hdr, .pfm) as it is, any other image (PNG,
 * JPEG, ...) through the texture loader, its 8-bit values decoded from sRGB. */
static valo_status read_map(const char *path, image *im, valo_error *err) {
  if (image_is_float_file(path)) return image_read(path, im, err);
  texture t;
  valo_status st = texture_load_file_as(&t, path, 1, "it as an environment map (.exr, .hdr, .pfm, or an 8-bit image such as PNG or JPEG)", err);
  if (st) return st;
  im->w = t.w;
  im->h = t.h;
  im->rgb = malloc((size_t)t.w * t.h * 3 * sizeof(float));
  if (!im->rgb) { texture_free(&t); return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", path); }
  for (size_t i = 0; i < (size_t)t.w * t.h; i++)
    for (int c = 0; c < 3; c++) im->rgb[3 * i + c] = t.px[4 * i + c];
  texture_free(&t);
  return VALO_OK;
}

valo_status envmap_load(envmap *e, const char *path, float scale, float rotation_deg, valo_error *err) {
  image im;
  valo_status st = read_map(path, &im, err);
  if (st) return st;
  if (im.w < 2 || im.h < 1) { image_free(&im); return err_set(err, VALO_ERR_INVALID, "%s: environment map too small", path); }
  /* Lossy EXR compression (DWAA/DWAB) rings around a bright sun into negative texels;
   * they carry no light here (envmap_init), which a renderer that keeps them as negative
   * light would not do: say how much that is. */
  double neg = 0, pos = 0;
  for (size_t i = 0; i < (size_t)im.w * im.h * 3; i++) {
    if (im.rgb[i] < 0) neg -= im.rgb[i];
    else if (isfinite(im.rgb[i])) pos += im.rgb[i];
  }
  if (neg > 1e-3 * pos)
    log_warning("%s: negative texels (compression ringing?) summing to %.1f %% of the map's energy are taken as 0", path,
                100 * neg / (pos > 0 ? pos : 1));
  if (envmap_init(e, im.w, im.h, im.rgb, scale, rotation_deg)) { envmap_free(e); return err_set(err, VALO_ERR_NOMEM, "out of memory"); }
  return VALO_OK;
}

/* Radiance of the cube in direction d (map frame, right-handed y up): the face of the
 * major axis of the left-handed direction (x, y, -z), then the OpenGL face coordinates
 * (s right, t down) looked up bilinearly with clamping inside that face. */
static void cube_lookup(const texture *faces, vec3 d, float out[4]) {
  float x = d.x, y = d.y, z = -d.z, ax = fabsf(x), ay = fabsf(y), az = fabsf(z), sc, tc, ma;
  int f;
  if (ax >= ay && ax >= az) { f = x > 0 ? 0 : 1; ma = ax; sc = x > 0 ? -z : z; tc = -y; }
  else if (ay >= az) { f = y > 0 ? 2 : 3; ma = ay; sc = x; tc = y > 0 ? z : -z; }
  else { f = z > 0 ? 4 : 5; ma = az; sc = z > 0 ? x : -x; tc = -y; }
  float s = 0.5f * (sc / ma + 1), t = 0.5f * (tc / ma + 1);
  texture_lookup(&faces[f], s, 1 - t, out);
}

valo_status envmap_load_cube(envmap *e, const char *const paths[6], float scale, float rotation_deg, valo_error *err) {
  texture faces[6];
  memset(faces, 0, sizeof faces);
  valo_status st = VALO_OK;
  int n = 0;
  for (int i = 0; i < 6 && !st; i++) {
    st = texture_load_file(&faces[i], paths[i], 1, err);
    if (st) break;
    faces[i].smp.wrap = TEX_CLAMP;
    if (faces[i].w != faces[i].h || faces[i].w < 1)
      st = err_set(err, VALO_ERR_INVALID, "%s: a cube face must be square (it is %dx%d)", paths[i], faces[i].w, faces[i].h);
    else if (i > 0 && faces[i].w != faces[0].w)
      st = err_set(err, VALO_ERR_INVALID, "%s: cube faces differ in size (%d against %d in %s)", paths[i], faces[i].w, faces[0].w, paths[0]);
    n = faces[0].w;
  }
  if (!st) {
    /* Equirectangular resolution 4n x 2n (about the cube's own texel density at the
     * equator), at most 4096 x 2048, each texel the mean of 2x2 cube lookups. */
    int N = n < 1024 ? n : 1024, W = 4 * N, H = 2 * N;
    float *px = malloc((size_t)W * H * 3 * sizeof(float));
    if (!px) st = err_set(err, VALO_ERR_NOMEM, "out of memory for a %dx%d environment map", W, H);
    else {
      for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
          float acc[3] = {0, 0, 0}, v[4];
          for (int k = 0; k < 4; k++) {
            cube_lookup(faces, uv_to_dir((x + 0.25f + 0.5f * (k & 1)) / W, (y + 0.25f + 0.5f * (k >> 1)) / H), v);
            for (int c = 0; c < 3; c++) acc[c] += 0.25f * v[c];
          }
          for (int c = 0; c < 3; c++) px[3 * ((size_t)y * W + x) + c] = acc[c];
        }
      if (envmap_init(e, W, H, px, scale, rotation_deg)) { envmap_free(e); st = err_set(err, VALO_ERR_NOMEM, "out of memory"); }
    }
  }
  for (int i = 0; i < 6; i++) texture_free(&faces[i]);
  return st;
}

void envmap_free(envmap *e) {
  free(e->rgb);
  e->rgb = NULL;
  bilin2d_free(&e->dist);
}

rgb envmap_eval(const envmap *e, vec3 dir) {
  float u, v;
  dir_to_uv(to_map(e, dir), &u, &v);
  return c3_scale(lookup(e, u, v), e->scale);
}

int envmap_sample(const envmap *e, float u1, float u2, vec3 *dir, float *pdf) {
  float u, v, puv;
  bilin2d_sample(&e->dist, u1, u2, &u, &v, &puv);
  float st = sinf(v * PI_F);
  if (!(st > 0) || !(puv > 0)) return 0;
  *dir = from_map(e, uv_to_dir(u, v));
  *pdf = puv / (2 * PI_F * PI_F * st);
  return 1;
}

float envmap_pdf(const envmap *e, vec3 dir) {
  float u, v;
  dir_to_uv(to_map(e, dir), &u, &v);
  float st = sinf(v * PI_F);
  if (!(st > 0)) return 0;
  return bilin2d_pdf(&e->dist, u, v) / (2 * PI_F * PI_F * st);
}

static valo_status envmap_adopt(envmap *e, valo_status st, envmap **out) {
  if (st) { free(e); return st; }
  *out = e;
  return VALO_OK;
}
valo_status envmap_create(const char *path, float scale, float rotation_deg, envmap **out, valo_error *err) {
  *out = NULL;
  envmap *e = calloc(1, sizeof *e);
  if (!e) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  return envmap_adopt(e, envmap_load(e, path, scale, rotation_deg, err), out);
}
valo_status envmap_create_cube(const char *const faces[6], float scale, float rotation_deg, envmap **out, valo_error *err) {
  *out = NULL;
  envmap *e = calloc(1, sizeof *e);
  if (!e) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  return envmap_adopt(e, envmap_load_cube(e, faces, scale, rotation_deg, err), out);
}
void envmap_destroy(envmap *e) {
  if (!e) return;
  envmap_free(e);
  free(e);
}
