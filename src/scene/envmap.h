/* envmap.h — owns equirectangular environment maps as lights: bilinear radiance lookup,
 * importance sampling by the piecewise-bilinear density of the lookup's largest channel
 * times sin(theta) (core/distrib.h, sampled exactly as Mitsuba's envmap does), and the
 * matching solid-angle density pdf(w) = pdf(u,v) / (2 pi^2 sin theta) (pbrt-v3 §14.2.4).
 * Convention: y is up; direction -z maps to the image centre (u = 0.5); the top row is
 * straight up. `rotation` turns the map about +y (degrees); envmap_set_frame turns it any
 * way (an orthonormal matrix from the map's frame to the world's).
 * Cube maps (six face images) are resampled into an equirectangular map at load time
 * (envmap_load_cube), so they share the lookup, sampling and MIS code. Face convention:
 * the OpenGL/DirectX cube-map layout of a left-handed world, as skybox packs are made
 * for it, brought into valo's right-handed y-up world by flipping z: each face image
 * is what a viewer at the centre sees facing it (side faces upright; the +y face seen
 * looking up from facing -z, the -y face looking down), and the "+z" image lies straight
 * ahead of a camera looking down -z. */
#ifndef VALO_ENVMAP_H
#define VALO_ENVMAP_H
#include "core/vec.h"
#include "core/distrib.h"
#include "valo/valo.h"

typedef struct envmap {
  int w, h;
  float *rgb;        /* w*h*3, linear */
  float scale;
  float rot_cos, rot_sin;
  int has_frame;     /* 1: frame (row-major) turns map directions into world ones, not rotation */
  int mitsuba_rows;  /* 1: row y is looked up at v = y/(h - 1), as Mitsuba's envmap does, not (y + 1/2)/h
                        (set through envmap_set_mitsuba_rows, which moves the sampling with it) */
  float frame[9];
  bilin2d dist;
  rgb average;       /* mean radiance over the sphere (for light selection) */
} envmap;

/* Takes ownership of rgb (w*h*3 floats). */
int envmap_init(envmap *e, int w, int h, float *rgb, float scale, float rotation_deg);
valo_status envmap_load(envmap *e, const char *path, float scale, float rotation_deg, valo_error *err);
/* faces: +x, -x, +y, -y, +z, -z image files (any texture format; 8-bit decoded from sRGB),
 * square and of one size. */
valo_status envmap_load_cube(envmap *e, const char *const faces[6], float scale, float rotation_deg, valo_error *err);
void envmap_free(envmap *e);
/* Map directions become world ones by m (row-major, orthonormal within 1e-3: a turn or a
 * mirror), in place of the rotation; -1 (nothing set) when m is not orthonormal. */
int envmap_set_frame(envmap *e, const double m[9]);
/* Mitsuba's row convention on or off; rebuilds the sampling density (0, or -1 on OOM). */
int envmap_set_mitsuba_rows(envmap *e, int on);
/* The same as heap objects the scene owns: *out is a new map (NULL on error);
 * envmap_destroy frees one (NULL is fine). */
valo_status envmap_create(const char *path, float scale, float rotation_deg, envmap **out, valo_error *err);
valo_status envmap_create_cube(const char *const faces[6], float scale, float rotation_deg, envmap **out, valo_error *err);
void envmap_destroy(envmap *e);
rgb envmap_eval(const envmap *e, vec3 dir);
/* Samples a unit direction; returns 0 if the density there is zero. */
int envmap_sample(const envmap *e, float u1, float u2, vec3 *dir, float *pdf);
float envmap_pdf(const envmap *e, vec3 dir);
#endif
