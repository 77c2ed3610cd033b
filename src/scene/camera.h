/* camera.h — owns camera rays: the basis of one frame's perspective, orthographic or
 * spherical camera (cam_view: from the scene's camera, or its keyframes at frame f), the
 * ray through a film point, the film point where a world point is seen, the crop window
 * the film holds of the frame, and the thin lens and pixel filter (cam_lens) that every
 * integrator's camera rays go through — the per-ray tile loop's and ReSTIR's G-buffer
 * alike. It sits in the scene model, below both. Film and frame coordinates are pixels
 * from the top-left corner (x right, y down). */
#ifndef VALO_CAMERA_H
#define VALO_CAMERA_H
#include "core/rng.h"
#include "geometry/accel.h"
#include "scene/scene.h"
#include "scene/filter.h"

/* A camera on a film: unit basis and the film's aspect; a perspective camera's tangent of
 * half the vertical field of view, an orthographic camera's half height in scene units
 * (ortho_half > 0; then o is the centre of the plane the rays start from), or a spherical
 * camera (equirectangular: the film's x is the longitude from -180 to 180 degrees, 0
 * along fwd and growing toward right; its y the latitude from 90, along up, to -90). */
typedef struct cam_view {
  vec3 o, fwd, right, up;
  float tan_half, ortho_half, aspect;
  int spherical;
  int width, height;      /* the frame */
  int x0, y0, film_w, film_h; /* the window of it the film holds (a crop; else the frame) */
} cam_view;

/* A frame's camera with its lens: radius 0 is a pinhole; focus is the distance along the
 * view axis of the plane in focus; and the pixel filter its samples are drawn from (NULL:
 * the box of one pixel). */
typedef struct cam_lens {
  cam_view view;
  float aperture, focus;
  const pixel_filter *filter;
} cam_lens;

/* The basis of camera c on a width x height frame, all of it on the film; -1 when up is
 * parallel to the view direction. */
int cam_view_make(const camera *c, int width, int height, cam_view *v);

/* The pinhole ray through frame point (fx, fy): unit direction *d from *o. An
 * orthographic camera's rays all run along fwd, from the point of its plane that the frame
 * point covers; a spherical camera's leave o in every direction. */
static inline void cam_view_ray(const cam_view *v, float fx, float fy, vec3 *o, vec3 *d) {
  float ax = 2.0f * fx / (float)v->width - 1.0f, ay = 1.0f - 2.0f * fy / (float)v->height;
  if (v->spherical) {
    float phi = ax * PI_F, theta = ay * (0.5f * PI_F), c = cosf(theta);
    *o = v->o;
    *d = v3_add(v3_scale(v->up, sinf(theta)), v3_add(v3_scale(v->right, c * sinf(phi)), v3_scale(v->fwd, c * cosf(phi))));
    return;
  }
  if (v->ortho_half > 0) {
    *o = v3_add(v->o, v3_add(v3_scale(v->right, ax * v->ortho_half * v->aspect), v3_scale(v->up, ay * v->ortho_half)));
    *d = v->fwd;
    return;
  }
  float sx = ax * v->tan_half * v->aspect, sy = ay * v->tan_half;
  *o = v->o;
  *d = v3_norm(v3_add(v->fwd, v3_add(v3_scale(v->right, sx), v3_scale(v->up, sy))));
}
/* Frame point (fx, fy) to film point: 1 when it lies on the film. */
static inline int cam_view_window(const cam_view *v, float *fx, float *fy) {
  *fx -= (float)v->x0;
  *fy -= (float)v->y0;
  return *fx >= 0 && *fy >= 0 && *fx < (float)v->film_w && *fy < (float)v->film_h;
}
/* Film point where p is seen (the inverse of cam_view_ray, less the window's corner); 0
 * when p is behind the camera (or its plane) or off the film. */
static inline int cam_view_project(const cam_view *v, vec3 p, float *fx, float *fy) {
  vec3 d = v3_sub(p, v->o);
  if (v->spherical) {
    float len = v3_len(d);
    if (!(len > 0)) return 0;
    float phi = atan2f(v3_dot(d, v->right), v3_dot(d, v->fwd)), theta = asinf(clampf(v3_dot(d, v->up) / len, -1, 1));
    *fx = (phi / (2 * PI_F) + 0.5f) * (float)v->width;
    *fy = (0.5f - theta / PI_F) * (float)v->height;
    if (*fx >= (float)v->width) *fx = 0; /* longitude 180 degrees: the frame's left edge */
    return cam_view_window(v, fx, fy);
  }
  float z = v3_dot(d, v->fwd);
  if (!(z > 0)) return 0;
  float hs = v->ortho_half > 0 ? v->ortho_half : z * v->tan_half;
  float sx = v3_dot(d, v->right) / (hs * v->aspect), sy = v3_dot(d, v->up) / hs;
  *fx = (sx + 1.0f) * 0.5f * (float)v->width;
  *fy = (1.0f - sy) * 0.5f * (float)v->height;
  return cam_view_window(v, fx, fy);
}

/* How far the camera is from p: its distance from the pinhole, or from an orthographic
 * camera's plane (what ReSTIR compares between pixels and frames). */
static inline float cam_view_depth(const cam_view *v, vec3 p) {
  vec3 d = v3_sub(p, v->o);
  return v->ortho_half > 0 ? v3_dot(d, v->fwd) : v3_len(d);
}

/* The camera ray of film pixel (px, py) for one sample: the position in the pixel (or
 * around its centre, drawn from the lens's filter) from the sampler's SDIM_FILM
 * dimensions, the point on the lens from SDIM_LENS (drawn for a pinhole too, so streams
 * do not shift); leaves the sampler at SDIM_WAVELENGTH. *weight gets the sample's filter
 * weight (pixel_filter_sample's in x times in y: 1 but for a filter's negative lobes). */
ray camera_ray(const cam_lens *l, int px, int py, sampler *smp, float *weight);
#endif
