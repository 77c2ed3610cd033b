/* path_common.c — see path_common.h. */
#include "integrator/direct.h"
#include "integrator/path_common.h"
#include "core/sampling.h"
#include <math.h>

int recursive_vertex(const render_ctx *c, const ray *r, sampler *smp, thread_stats *ts, int depth, int max_depth, int count_emission,
                     rgb *L, isect *it, bsdf *b, frame *fr, vec3 *wo) {
  hit h;
  int found = ctx_intersect(c, r, &h, ts);
  if (found) isect_from_hit(c->s, r, &h, it);
  *L = count_emission && (depth > 0 || !c->hide_emitters) ? emitted_along(c, r, &h, found, it) : c3(0, 0, 0);
  if (!found || depth >= max_depth) return 0;
  *b = bsdf_at(c->s, it);
  *wo = v3_neg(r->d);
  *fr = shading_frame(it, b, *wo);
  if (bsdf_has_smooth(b)) *L = c3_add(*L, estimate_direct_nomis(c, it, b, fr, *wo, smp, ts));
  return 1;
}

static float path_emission_weight(const render_ctx *c, const path_state *st, int env, vec3 d, int32_t lid, const isect *it) {
  if (st->specular) return 1;
  const scene *s = c->s;
  if (env) return power_heuristic(st->prev_pdf, ctx_light_pmf(c, (uint32_t)c->ls.env_index, st->prev_p) * light_pdf_env(s, &s->lights[c->ls.env_index], d));
  return power_heuristic(st->prev_pdf, ctx_light_pdf_area(c, (uint32_t)lid, st->prev_p, it->p, it->ng));
}

void path_vertex_emission(const render_ctx *c, const ray *r, const path_state *st, const hit *h, const isect *it, rgb *Le, float *w) {
  const scene *s = c->s;
  *Le = c3(0, 0, 0);
  *w = 1;
  if (!h) {
    if (c->ls.env_index >= 0) {
      *Le = light_env_radiance(s, &s->lights[c->ls.env_index], r->d);
      *w = path_emission_weight(c, st, 1, r->d, -1, NULL);
    }
    return;
  }
  int32_t lid;
  *Le = light_hit(s, h->tri, it->p, it->ng, v3_neg(r->d), it->u, it->v, &lid);
  if (lid >= 0 && !c3_black(*Le)) *w = path_emission_weight(c, st, 0, r->d, lid, it);
}

int path_hit_vertex(const render_ctx *c, const ray *r, const path_state *st, const hit *h, isect *it, rgb *Le, float *w) {
  if (!h) {
    path_vertex_emission(c, r, st, NULL, NULL, Le, w);
    return 0;
  }
  isect_from_hit(c->s, r, h, it);
  path_vertex_emission(c, r, st, h, it, Le, w);
  return 1;
}

int path_trace_vertex(const render_ctx *c, const ray *r, const path_state *st, thread_stats *ts, isect *it, rgb *Le, float *w) {
  hit h;
  return path_hit_vertex(c, r, st, ctx_intersect(c, r, &h, ts) ? &h : NULL, it, Le, w);
}

int sides_agree(const isect *it, vec3 wo_l, vec3 wi_l, vec3 wo, vec3 wi, thread_stats *ts) {
  int refl_l = (wi_l.z > 0) == (wo_l.z > 0), refl_g = (v3_dot(wi, it->ng) > 0) == (v3_dot(wo, it->ng) > 0);
  if (refl_l != refl_g) { ts->lost[VALO_LOSS_SHADING_NORMAL]++; return 0; }
  return 1;
}

int sample_bsdf_world_u(const isect *it, const bsdf *b, const frame *fr, vec3 wo, float ul, float u1, float u2, thread_stats *ts, bsdf_sample *bs,
                        vec3 *wi) {
  vec3 wo_l = frame_to_local(fr, wo);
  if (!bsdf_sample_dir(b, wo_l, ul, u1, u2, bs)) {
    if (bs->nonfinite) ts->lost[VALO_LOSS_BSDF_NONFINITE]++;
    return 0;
  }
  *wi = v3_norm(frame_to_world(fr, bs->wi));
  return sides_agree(it, wo_l, bs->wi, wo, *wi, ts);
}

int sample_bsdf_world(const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp, thread_stats *ts, bsdf_sample *bs, vec3 *wi) {
  float ul = sampler_1d(smp), u1, u2;
  sampler_2d(smp, &u1, &u2);
  ts->surface_samples++;
  return sample_bsdf_world_u(it, b, fr, wo, ul, u1, u2, ts, bs, wi);
}

int path_continue(const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp, thread_stats *ts, path_state *st, rgb *weight,
                  ray *r) {
  bsdf_sample bs;
  vec3 wi;
  if (!sample_bsdf_world(it, b, fr, wo, smp, ts, &bs, &wi)) return 0;
  *weight = bs.weight;
  st->specular = bs.delta;
  st->prev_pdf = bs.pdf;
  st->prev_p = it->p;
  st->eta_acc /= bs.eta_scale;
  *r = spawn_ray(it, wi);
  return 1;
}

float path_roulette(const path_state *st, float max_beta, int depth, int rr_depth, sampler *smp) {
  float rr = max_beta * st->eta_acc;
  if (depth < rr_depth || rr >= 1) return 1;
  float q = fmaxf(0.0f, 1 - rr);
  if (sampler_1d(smp) < q) return 0;
  return 1 / (1 - q);
}

