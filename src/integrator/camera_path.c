/* camera_path.c — see camera_path.h. */
#include "integrator/camera_path.h"
#include "core/sampling.h"

static int walk_max_depth(const render_ctx *c) { return c->max_depth >= 0 ? c->max_depth : CAMERA_PATH_MAX_DEPTH; }

void delta_walk_start(delta_walk *w, ray r, int depth) {
  w->r = r;
  w->beta = c3(1, 1, 1);
  w->L = c3(0, 0, 0);
  w->depth = depth;
  w->hit_any = 0;
}

/* Traces w->r: adds the emission found, and at a surface below the depth limit fills the
 * vertex and returns 1. */
static int walk_vertex(delta_walk *w, const render_ctx *c, thread_stats *ts) {
  rgb Le;
  float wgt;
  path_state st0 = path_state_start(w->r.o); /* emission along a delta chain counts fully */
  int surface = path_trace_vertex(c, &w->r, &st0, ts, &w->it, &Le, &wgt);
  if (w->depth > 0 || !c->hide_emitters) w->L = c3_add(w->L, c3_mul(w->beta, Le)); /* depth 0: the camera ray */
  if (surface && !w->hit_any) { w->first_p = w->it.p; w->hit_any = 1; }
  if (!surface || w->depth >= walk_max_depth(c)) return 0;
  w->wo = v3_neg(w->r.d);
  w->b = bsdf_at(c->s, &w->it);
  w->fr = shading_frame(&w->it, &w->b, w->wo);
  return 1;
}

int delta_walk_continue(delta_walk *w, const render_ctx *c, sampler *smp, thread_stats *ts) {
  (void)c;
  sampler_set_dim(smp, sdim_bounce(w->depth, SDIM_LOBE));
  path_state st = path_state_start(w->r.o);
  rgb wgt;
  if (!path_continue(&w->it, &w->b, &w->fr, w->wo, smp, ts, &st, &wgt, &w->r) || !st.specular) return 0;
  w->beta = c3_mul(w->beta, wgt);
  w->depth++;
  return !c3_black(w->beta) && c3_finite(w->beta);
}

int delta_walk_next(delta_walk *w, const render_ctx *c, sampler *smp, thread_stats *ts) {
  for (;;) {
    if (!walk_vertex(w, c, ts)) return 0;
    if (bsdf_has_smooth(&w->b)) return 1;
    if (!delta_walk_continue(w, c, smp, ts)) return 0;
  }
}

rgb li_shade_through_delta(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, surface_shade_fn shade) {
  delta_walk w;
  delta_walk_start(&w, r, 0);
  while (delta_walk_next(&w, c, smp, ts)) {
    w.L = c3_add(w.L, c3_mul(w.beta, shade(c, &w.it, &w.b, &w.fr, w.wo, w.depth, smp, ts)));
    if (!delta_walk_continue(&w, c, smp, ts)) break;
  }
  return w.L;
}
