/* camera.c — see camera.h. */
#include "scene/camera.h"
#include "core/sampling.h"
#include <math.h>

int cam_view_make(const camera *c, int width, int height, cam_view *v) {
  v->o = c->pos;
  v->fwd = v3_norm(v3_sub(c->look_at, c->pos));
  v->right = v3_norm(v3_cross(v->fwd, c->up));
  v->up = v3_cross(v->right, v->fwd);
  v->tan_half = tanf(0.5f * c->fov_deg * PI_F / 180.0f);
  v->ortho_half = c->ortho_height > 0 ? 0.5f * c->ortho_height : 0;
  v->spherical = c->spherical;
  v->width = v->film_w = width;
  v->height = v->film_h = height;
  v->x0 = v->y0 = 0;
  v->aspect = (float)width / (float)height;
  return (!v3_finite(v->right) || !(v3_len2(v->right) > 0.5f)) ? -1 : 0;
}

ray camera_ray(const cam_lens *l, int px, int py, sampler *smp, float *weight) {
  const cam_view *v = &l->view;
  float jx, jy;
  sampler_set_dim(smp, SDIM_FILM);
  sampler_2d(smp, &jx, &jy);
  px += v->x0;
  py += v->y0;
  float fx = (float)px + jx, fy = (float)py + jy, wx = 1, wy = 1;
  if (l->filter) {
    fx = (float)px + 0.5f + pixel_filter_sample(l->filter, jx, &wx);
    fy = (float)py + 0.5f + pixel_filter_sample(l->filter, jy, &wy);
  }
  *weight = wx * wy;
  ray ry;
  vec3 d;
  cam_view_ray(v, fx, fy, &ry.o, &d);
  ry.tmax = INFINITY;
  if (l->aperture > 0) {
    float lu, lv;
    sampler_set_dim(smp, SDIM_LENS);
    sampler_2d(smp, &lu, &lv);
    /* Thin lens: every ray through the lens meets at the plane of focus (an orthographic
     * camera's lens sits around the ray's own point of the camera plane). */
    float ft = l->focus / v3_dot(d, v->fwd);
    vec3 pf = v3_add(ry.o, v3_scale(d, ft));
    float dx, dy;
    sample_concentric_disk(lu, lv, &dx, &dy);
    ry.o = v3_add(ry.o, v3_add(v3_scale(v->right, dx * l->aperture), v3_scale(v->up, dy * l->aperture)));
    d = v3_norm(v3_sub(pf, ry.o));
  }
  sampler_set_dim(smp, SDIM_WAVELENGTH); /* what follows draws from its own dimensions */
  ry.d = d;
  return ry;
}
