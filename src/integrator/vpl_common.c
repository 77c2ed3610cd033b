/* vpl_common.c — see vpl_common.h. */
#include "integrator/vpl_common.h"
#include "integrator/lightpath.h"
#include "core/streams.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int visit(void *user, const lp_vertex *v, void *rec) {
  (void)user;
  if (!bsdf_has_smooth(v->b)) return 0; /* a blend that picked its delta material: no light to give */
  vpl l;
  memset(&l, 0, sizeof l);
  l.p = v->it->p;
  l.n = v->fr->n;
  l.ng = v3_dot(v->it->ng, v->fr->n) < 0 && !bsdf_transmits(v->b) ? v3_neg(v->it->ng) : v->it->ng;
  l.wi = v3_neg(v->d);
  l.power = v->power;
  l.b = *v->b;
  l.fr = *v->fr;
  memcpy(rec, &l, sizeof l);
  return 1;
}

valo_status vlight_shoot(vlight_set *s, const render_ctx *c, int sample_index, double count, valo_error *err) {
  vlight_free(s);
  uint64_t key = rng_mix64(c->seed * 0x9e3779b97f4a7c15ULL + (uint64_t)sample_index + STREAM_VPL);
  lp_set set;
  if (s->paths == 0) {
    valo_status st = lightpath_shoot_paths(c, rng_mix64(c->seed + STREAM_VPL_PILOT), 16384, sizeof(vpl), visit, NULL, &set, err);
    if (st) return st;
    free(set.rec);
    double per_path = set.emitted ? (double)set.n / (double)set.emitted : 0;
    s->paths = per_path > 0 ? (uint64_t)ceil(count / per_path) : (uint64_t)count;
    if (s->paths < 1) s->paths = 1;
  }
  valo_status st = lightpath_shoot_paths(c, key, s->paths, sizeof(vpl), visit, NULL, &set, err);
  if (st) return st;
  s->v = (vpl *)set.rec;
  s->n = set.n;
  float inv = set.emitted ? 1.0f / (float)set.emitted : 0;
  for (uint32_t i = 0; i < s->n; i++) s->v[i].power = c3_scale(s->v[i].power, inv);
  return VALO_OK;
}

void vlight_free(vlight_set *s) {
  free(s->v);
  s->v = NULL;
  s->n = 0;
}

rgb vpl_reflect(const vpl *l, vec3 w) {
  if (!bsdf_transmits(&l->b) && (v3_dot(w, l->n) <= 0 || v3_dot(w, l->ng) <= 0)) return c3(0, 0, 0);
  return bsdf_eval(&l->b, frame_to_local(&l->fr, w), frame_to_local(&l->fr, l->wi));
}

rgb vlight_gather_all(const render_ctx *c, const vlight_set *s, vlight_contrib_fn contrib, const isect *it, const bsdf *b, const frame *fr,
                      vec3 wo, sampler *smp, thread_stats *ts) {
  rgb sum = c3(0, 0, 0);
  vec3 wo_l = frame_to_local(fr, wo);
  for (uint32_t i = 0; i < s->n; i++) {
    const vpl *l = &s->v[i];
    rgb ct = contrib(c, s, i, it, b, fr, wo_l, smp);
    if (c3_black(ct) || !c3_finite(ct)) continue;
    if (ctx_segment_blocked(c, it, l->p, l->ng, ts)) continue;
    sum = c3_add(sum, ct);
  }
  return sum;
}

rgb vlight_direct(const render_ctx *c, int nd, const isect *it, const bsdf *b, const frame *fr, vec3 wo, int depth, sampler *smp,
                  thread_stats *ts) {
  rgb L = c3(0, 0, 0);
  for (int k = 0; k < nd; k++) {
    sampler ds = sampler_child(smp, (uint32_t)k, (uint32_t)nd);
    sampler_set_dim(&ds, sdim_bounce(depth, SDIM_LIGHT_PICK));
    L = c3_add(L, estimate_direct_nomis(c, it, b, fr, wo, &ds, ts));
  }
  return c3_scale(L, 1.0f / (float)nd);
}
