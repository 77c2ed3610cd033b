/* live.c — see live.h. */
#include "render/live.h"
#include "image/svgf.h"
#include "core/error.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

struct live_state {
  svgf *f;
  uint64_t restarts; /* the session's restarts at the last call */
  cam_view view;     /* and its camera */
  float *buf;        /* color 3, albedo 3, normal 3, depth 1, lum2 1, prev_xy 2, prev_d 1, emission 3 */
};

void live_reset(live_state *l) {
  if (l) svgf_reset(l->f);
}

void live_free(live_state *l) {
  if (!l) return;
  svgf_destroy(l->f);
  free(l->buf);
  free(l);
}

valo_status live_denoise(live_state **lp, const session *ss, float *out, valo_error *err) {
  const film *fm = &ss->film;
  if (!fm->aov) return err_set(err, VALO_ERR_INVALID, "the live denoiser needs the render's AOVs (valo_options.aovs)");
  int w = fm->width, h = fm->height;
  size_t np = (size_t)w * h;
  live_state *l = *lp;
  if (!l) {
    if (!(l = calloc(1, sizeof *l)) || !(l->f = svgf_create(w, h)) || !(l->buf = malloc(np * 17 * sizeof(float)))) {
      live_free(l);
      return err_set(err, VALO_ERR_NOMEM, "out of memory");
    }
    l->restarts = ss->restarts;
    l->view = ss->lens.view;
    *lp = l;
  }
  float *color = l->buf, *alb = color + 3 * np, *nrm = alb + 3 * np, *dep = nrm + 3 * np, *lum2 = dep + np, *pxy = lum2 + np, *pd = pxy + 2 * np, *emi = pd + np;
  film_resolve(fm, color);
  for (size_t i = 0; i < np; i++) {
    const float *a = &fm->aov[AOV_FLOATS * i];
    float n = (float)fm->count[i], inv = n > 0 ? 1 / n : 0;
    for (int c = 0; c < 3; c++) alb[3 * i + c] = a[AOV_ALBEDO + c] * inv;
    for (int c = 0; c < 3; c++) emi[3 * i + c] = a[AOV_EMIT + c] * inv;
    float nx = a[AOV_NORMAL], ny = a[AOV_NORMAL + 1], nz = a[AOV_NORMAL + 2], len = sqrtf(nx * nx + ny * ny + nz * nz);
    float k = len > 0 ? 1 / len : 0;
    nrm[3 * i] = nx * k; nrm[3 * i + 1] = ny * k; nrm[3 * i + 2] = nz * k;
    dep[i] = a[AOV_DEPTH] * inv;
    lum2[i] = fm->sq && n > 0 ? (float)(fm->sq[4 * i + 3] / n) : 0;
  }
  int fresh = ss->restarts != l->restarts;
  const cam_view *now = &ss->lens.view, *was = &l->view;
  int moved = fresh && memcmp(now, was, sizeof *now);
  for (int y = 0; moved && y < h; y++)
    for (int x = 0; x < w; x++) {
      size_t i = (size_t)y * w + x;
      pxy[2 * i] = pxy[2 * i + 1] = NAN;
      if (!(dep[i] > 0)) continue;
      vec3 o, d;
      cam_view_ray(now, (float)(x + now->x0) + 0.5f, (float)(y + now->y0) + 0.5f, &o, &d);
      vec3 p = v3_add(o, v3_scale(d, dep[i]));
      float fx, fy;
      if (!cam_view_project(was, p, &fx, &fy)) continue;
      pxy[2 * i] = fx;
      pxy[2 * i + 1] = fy;
      pd[i] = cam_view_depth(was, p);
    }
  svgf_frame f = {w, h, color, fm->sq ? lum2 : NULL, (float)ss->spp_done, alb, emi, nrm, dep, fresh, moved ? pxy : NULL, moved ? pd : NULL};
  if (!(f.n > 0)) f.n = 1;
  int rc = svgf_run(l->f, &f, out, ss->opt.threads);
  l->restarts = ss->restarts;
  l->view = *now;
  return rc ? err_set(err, VALO_ERR_NOMEM, "out of memory") : VALO_OK;
}
