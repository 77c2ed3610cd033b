/* integrator.c — owns the integrator registry and the shared helpers declared in
 * integrator.h (surface interactions, shadow segments, next-event estimation + MIS). */
#include "integrator/integrator.h"
#include "core/sampling.h"
#include "image/texture.h"
#include "core/error.h"
#include <string.h>
#include <stdio.h>
#include <stdlib.h>
#include <math.h>

/* Bump mapping (Blinn 1978, as pbrt's BumpMap): the surface displaced along the
 * shading normal n by d(u,v) = scale * height(u,v) has tangents dp/du + d_u n and
 * dp/dv + d_v n (the d dn/du terms are dropped), whose cross product is the new shading
 * normal. dp/du and dp/dv are the triangle's own UV derivatives, made orthogonal to n so
 * that a flat height map leaves n unchanged; d_u and d_v are central differences over
 * half a texel of the bilinearly filtered map, so the slope of a linear ramp is exact. */
static void apply_bump(const scene *s, isect *it, const uint32_t *ix) {
  const texture *tx = &s->tex[it->m->tex_bump];
  vec3 e1 = v3_sub(s->pos[ix[1]], s->pos[ix[0]]), e2 = v3_sub(s->pos[ix[2]], s->pos[ix[0]]);
  float du1 = s->uv[2 * ix[1]] - s->uv[2 * ix[0]], dv1 = s->uv[2 * ix[1] + 1] - s->uv[2 * ix[0] + 1];
  float du2 = s->uv[2 * ix[2]] - s->uv[2 * ix[0]], dv2 = s->uv[2 * ix[2] + 1] - s->uv[2 * ix[0] + 1];
  float det = du1 * dv2 - du2 * dv1;
  if (!(fabsf(det) > 1e-20f) || tx->w < 1 || tx->h < 1) return;
  float r = 1 / det;
  vec3 n = it->ns;
  vec3 dpdu = v3_scale(v3_sub(v3_scale(e1, dv2), v3_scale(e2, dv1)), r);
  vec3 dpdv = v3_scale(v3_sub(v3_scale(e2, du1), v3_scale(e1, du2)), r);
  dpdu = v3_sub(dpdu, v3_scale(n, v3_dot(n, dpdu)));
  dpdv = v3_sub(dpdv, v3_scale(n, v3_dot(n, dpdv)));
  float hu = 0.5f / (float)tx->w, hv = 0.5f / (float)tx->h, px[4], a, b;
  texture_lookup(tx, it->u + hu, it->v, px); a = px[0] + px[1] + px[2];
  texture_lookup(tx, it->u - hu, it->v, px); b = px[0] + px[1] + px[2];
  float d_u = it->m->bump_scale * (a - b) / (3 * 2 * hu);
  texture_lookup(tx, it->u, it->v + hv, px); a = px[0] + px[1] + px[2];
  texture_lookup(tx, it->u, it->v - hv, px); b = px[0] + px[1] + px[2];
  float d_v = it->m->bump_scale * (a - b) / (3 * 2 * hv);
  vec3 nb = v3_cross(v3_add(dpdu, v3_scale(n, d_u)), v3_add(dpdv, v3_scale(n, d_v)));
  if (v3_dot(nb, n) < 0) nb = v3_neg(nb);
  if (v3_len2(nb) > 1e-30f && v3_finite(nb)) it->ns = v3_norm(nb);
}

void isect_from_hit(const scene *s, const ray *r, const hit *h, isect *it) {
  (void)r;
  const uint32_t *ix = &s->idx[3 * h->tri];
  vec3 p0 = s->pos[ix[0]], p1 = s->pos[ix[1]], p2 = s->pos[ix[2]];
  it->p = tri_point(p0, p1, p2, h->b1, h->b2, &it->perr);
  it->ng = v3_norm(v3_cross(v3_sub(p1, p0), v3_sub(p2, p0)));
  it->tri = h->tri;
  it->m = &s->mats[s->tri_mat[h->tri]];
  float b0 = 1 - h->b1 - h->b2;
  it->ns = it->ng;
  if (s->tri_flags[h->tri] & TRI_HAS_NORMALS) {
    vec3 n = v3_add(v3_add(v3_scale(s->nrm[ix[0]], b0), v3_scale(s->nrm[ix[1]], h->b1)), v3_scale(s->nrm[ix[2]], h->b2));
    float l2 = v3_len2(n);
    if (l2 > 0 && isfinite(l2)) it->ns = v3_scale(n, 1 / sqrtf(l2));
  }
  it->u = b0 * s->uv[2 * ix[0]] + h->b1 * s->uv[2 * ix[1]] + h->b2 * s->uv[2 * ix[2]];
  it->v = b0 * s->uv[2 * ix[0] + 1] + h->b1 * s->uv[2 * ix[1] + 1] + h->b2 * s->uv[2 * ix[2] + 1];
  if (it->m->tex_normal >= 0 && s->tan && (s->tri_flags[h->tri] & TRI_HAS_UVS)) {
    /* Tangent-space normal map: n = 2 rgb - 1 in the (T, B, N) frame at the hit. */
    const float *t0 = &s->tan[4 * ix[0]], *t1 = &s->tan[4 * ix[1]], *t2 = &s->tan[4 * ix[2]];
    vec3 T = v3(b0 * t0[0] + h->b1 * t1[0] + h->b2 * t2[0], b0 * t0[1] + h->b1 * t1[1] + h->b2 * t2[1],
                b0 * t0[2] + h->b1 * t1[2] + h->b2 * t2[2]);
    vec3 N = it->ns;
    T = v3_sub(T, v3_scale(N, v3_dot(N, T)));
    if (v3_len2(T) > 1e-12f) {
      T = v3_norm(T);
      vec3 B = v3_scale(v3_cross(N, T), t0[3]);
      float px[4];
      texture_lookup(&s->tex[it->m->tex_normal], it->u, it->v, px);
      vec3 nm = v3(2 * px[0] - 1, 2 * px[1] - 1, 2 * px[2] - 1);
      vec3 n2 = v3_add(v3_add(v3_scale(T, nm.x), v3_scale(B, nm.y)), v3_scale(N, nm.z));
      if (v3_len2(n2) > 1e-12f && v3_finite(n2)) it->ns = v3_norm(n2);
    }
  }
  if (it->m->tex_bump >= 0 && (s->tri_flags[h->tri] & TRI_HAS_UVS)) apply_bump(s, it, ix);
}

bsdf bsdf_at(const scene *s, const isect *it) {
  const material *m = it->m;
  if (m->tex_kd < 0 && m->tex_ks < 0 && m->tex_mr < 0 && m->tex_ns < 0 && m->tex_rough < 0 && m->tex_metal < 0) return bsdf_from_material(m);
  material mm = *m;
  float px[4];
  if (m->tex_kd >= 0) { texture_lookup(&s->tex[m->tex_kd], it->u, it->v, px); mm.kd = c3_mul(mm.kd, c3(px[0], px[1], px[2])); }
  if (m->tex_ks >= 0) { texture_lookup(&s->tex[m->tex_ks], it->u, it->v, px); mm.ks = c3_mul(mm.ks, c3(px[0], px[1], px[2])); }
  if (m->tex_ns >= 0) { texture_lookup(&s->tex[m->tex_ns], it->u, it->v, px); mm.exponent *= (px[0] + px[1] + px[2]) / 3; }
  if (m->tex_mr >= 0) { texture_lookup(&s->tex[m->tex_mr], it->u, it->v, px); mm.roughness *= px[1]; mm.metallic *= px[2]; }
  if (m->tex_rough >= 0) { texture_lookup(&s->tex[m->tex_rough], it->u, it->v, px); mm.roughness *= sqrtf(fmaxf((px[0] + px[1] + px[2]) / 3, 0)); }
  if (m->tex_metal >= 0) { texture_lookup(&s->tex[m->tex_metal], it->u, it->v, px); mm.metallic *= (px[0] + px[1] + px[2]) / 3; }
  return bsdf_from_material(&mm);
}

int ctx_segment_blocked(const render_ctx *c, const isect *it, vec3 p_to, vec3 n_to, thread_stats *ts) {
  vec3 d0 = v3_sub(p_to, it->p);
  vec3 o = offset_origin_isect(it, d0);
  vec3 target = p_to;
  if (v3_len2(n_to) > 0) {
    vec3 err = v3_scale(v3_abs(p_to), fp_gamma(7));
    target = offset_origin(p_to, err, n_to, v3_neg(d0));
  }
  ray r;
  r.o = o;
  r.d = v3_sub(target, o);
  r.tmax = 1 - 1e-4f;
  ts->rays++;
  return accel_occluded(c->acc, &r);
}

int sample_direct(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                  thread_stats *ts, int mis, direct_sample *out) {
  float ul = sampler_1d(smp), u1, u2;
  sampler_2d(smp, &u1, &u2);
  float pmf;
  uint32_t li = light_select(&c->ls, c->s, it->p, ul, &pmf);
  if (li == UINT32_MAX) return 0;
  const light *l = &c->s->lights[li];
  light_li ls;
  if (!light_sample(c->s, l, it->p, u1, u2, &ls)) return 0;
  vec3 wi_l = frame_to_local(fr, ls.wi), wo_l = frame_to_local(fr, wo);
  rgb f = bsdf_eval(b, wo_l, wi_l);
  ts->surface_samples++;
  if (!c3_finite(f)) { ts->lost[VALO_LOSS_BSDF_NONFINITE]++; return 0; }
  if (c3_black(f)) return 0;
  /* Reflection vs transmission must agree between the shading frame and the true
   * surface (no leaks through shading normals). */
  int refl_l = (wi_l.z > 0) == (wo_l.z > 0), refl_g = (v3_dot(ls.wi, it->ng) > 0) == (v3_dot(wo, it->ng) > 0);
  if (refl_l != refl_g || v3_dot(ls.wi, it->ng) == 0) { ts->lost[VALO_LOSS_SHADING_NORMAL]++; return 0; }
  float bpdf = (ls.delta || !mis) ? 0 : bsdf_pdf(b, wo_l, wi_l);
  if (!isfinite(bpdf)) { ts->lost[VALO_LOSS_BSDF_NONFINITE]++; return 0; }
  if (ctx_segment_blocked(c, it, ls.p_light, ls.n_light, ts)) return 0;
  float light_pdf = pmf * ls.pdf;
  float w = (ls.delta || !mis) ? 1.0f : power_heuristic(light_pdf, bpdf);
  out->f_cos = c3_scale(f, fabsf(wi_l.z));
  out->Li = ls.L;
  out->scale = w / light_pdf;
  out->wi = ls.wi;
  return 1;
}

static rgb direct_rgb(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                      thread_stats *ts, int mis) {
  direct_sample d;
  if (!sample_direct(c, it, b, fr, wo, smp, ts, mis, &d)) return c3(0, 0, 0);
  return c3_scale(c3_mul(d.f_cos, d.Li), d.scale);
}

rgb estimate_direct(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                    thread_stats *ts) {
  return direct_rgb(c, it, b, fr, wo, smp, ts, 1);
}
rgb estimate_direct_nomis(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                          thread_stats *ts) {
  return direct_rgb(c, it, b, fr, wo, smp, ts, 0);
}

rgb emitted_along(const render_ctx *c, const ray *r, const hit *h, int found, const isect *it) {
  const scene *s = c->s;
  if (!found) {
    if (c->ls.env_index < 0) return c3(0, 0, 0);
    return light_env_radiance(s, &s->lights[c->ls.env_index], r->d);
  }
  int32_t lid = s->tri_light[h->tri];
  if (lid < 0) return c3(0, 0, 0);
  return light_area_radiance(s, &s->lights[lid], it->ng, v3_neg(r->d), it->u, it->v);
}

int recursive_vertex(const render_ctx *c, const ray *r, sampler *smp, thread_stats *ts, int depth, int max_depth, int count_emission,
                     rgb *L, isect *it, bsdf *b, frame *fr, vec3 *wo) {
  hit h;
  int found = ctx_intersect(c, r, &h, ts);
  if (found) isect_from_hit(c->s, r, &h, it);
  *L = count_emission ? emitted_along(c, r, &h, found, it) : c3(0, 0, 0);
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
  return power_heuristic(st->prev_pdf, ctx_light_pmf(c, (uint32_t)lid, st->prev_p) * light_pdf_area(s, &s->lights[lid], st->prev_p, it->p, it->ng));
}

int path_trace_vertex(const render_ctx *c, const ray *r, const path_state *st, thread_stats *ts, isect *it, rgb *Le, float *w) {
  const scene *s = c->s;
  hit h;
  *Le = c3(0, 0, 0);
  *w = 1;
  if (!ctx_intersect(c, r, &h, ts)) {
    if (c->ls.env_index >= 0) {
      *Le = light_env_radiance(s, &s->lights[c->ls.env_index], r->d);
      *w = path_emission_weight(c, st, 1, r->d, -1, NULL);
    }
    return 0;
  }
  isect_from_hit(s, r, &h, it);
  int32_t lid = s->tri_light[h.tri];
  if (lid >= 0) {
    *Le = light_area_radiance(s, &s->lights[lid], it->ng, v3_neg(r->d), it->u, it->v);
    if (!c3_black(*Le)) *w = path_emission_weight(c, st, 0, r->d, lid, it);
  }
  return 1;
}

int sample_bsdf_world(const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp, thread_stats *ts, bsdf_sample *bs, vec3 *wi) {
  float ul = sampler_1d(smp), u1, u2;
  sampler_2d(smp, &u1, &u2);
  vec3 wo_l = frame_to_local(fr, wo);
  ts->surface_samples++;
  if (!bsdf_sample_dir(b, wo_l, ul, u1, u2, bs)) {
    if (bs->nonfinite) ts->lost[VALO_LOSS_BSDF_NONFINITE]++;
    return 0;
  }
  *wi = v3_norm(frame_to_world(fr, bs->wi));
  /* The sampled direction must agree with the geometric normal about reflection vs
   * transmission, or shading normals would leak light. */
  int refl_l = (bs->wi.z > 0) == (wo_l.z > 0), refl_g = (v3_dot(*wi, it->ng) > 0) == (v3_dot(wo, it->ng) > 0);
  if (refl_l != refl_g) { ts->lost[VALO_LOSS_SHADING_NORMAL]++; return 0; }
  return 1;
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

int delta_chain_vertex(const render_ctx *c, const ray *r, rgb beta, int depth, int max_depth, thread_stats *ts, rgb *L, isect *it, bsdf *b,
                       frame *fr, vec3 *wo) {
  rgb Le;
  float w;
  path_state st0 = path_state_start(r->o); /* emission along a delta chain counts fully */
  int surface = path_trace_vertex(c, r, &st0, ts, it, &Le, &w);
  *L = c3_add(*L, c3_mul(beta, Le));
  if (!surface || depth >= max_depth) return 0;
  *wo = v3_neg(r->d);
  *b = bsdf_at(c->s, it);
  *fr = shading_frame(it, b, *wo);
  return 1;
}

int delta_chain_continue(const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp, thread_stats *ts, rgb *beta, ray *r) {
  path_state st = path_state_start(r->o);
  rgb wgt;
  if (!path_continue(it, b, fr, wo, smp, ts, &st, &wgt, r) || !st.specular) return 0;
  *beta = c3_mul(*beta, wgt);
  return !c3_black(*beta) && c3_finite(*beta);
}

rgb li_shade_through_delta(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, surface_shade_fn shade) {
  rgb L = c3(0, 0, 0), beta = c3(1, 1, 1);
  int max_depth = c->max_depth >= 0 ? c->max_depth : 32;
  for (int depth = 0;; depth++) {
    isect it;
    bsdf b;
    frame fr;
    vec3 wo;
    if (!delta_chain_vertex(c, &r, beta, depth, max_depth, ts, &L, &it, &b, &fr, &wo)) break;
    if (bsdf_has_smooth(&b)) L = c3_add(L, c3_mul(beta, shade(c, &it, &b, &fr, wo, depth, smp, ts)));
    /* delta lobes carry the camera path on; a non-delta sample ends it */
    sampler_set_dim(smp, sdim_bounce(depth, SDIM_LOBE));
    if (!delta_chain_continue(&it, &b, &fr, wo, smp, ts, &beta, &r)) break;
  }
  return L;
}

float path_roulette(const path_state *st, float max_beta, int depth, sampler *smp) {
  float rr = max_beta * st->eta_acc;
  if (depth < 2 || rr >= 1) return 1;
  float q = fmaxf(0.0f, 1 - rr);
  if (sampler_1d(smp) < q) return 0;
  return 1 / (1 - q);
}

frame shading_frame(isect *it, const bsdf *b, vec3 wo) {
  vec3 ns = it->ns;
  if (!bsdf_transmits(b)) {
    if (v3_dot(it->ng, wo) < 0) it->ng = v3_neg(it->ng);
    if (v3_dot(ns, wo) < 0) ns = v3_neg(ns);
  }
  return frame_from_n(ns);
}

int ao_sample(const render_ctx *c, const isect *it, vec3 n, float dist, sampler *smp, thread_stats *ts, vec3 *dir) {
  float u1, u2;
  sampler_2d(smp, &u1, &u2);
  frame f = frame_from_n(n);
  vec3 d = frame_to_world(&f, sample_cosine_hemisphere(u1, u2));
  /* a direction under the geometric surface is blocked by it */
  if (v3_dot(d, it->ng) * v3_dot(n, it->ng) <= 0) return 0;
  ray r = spawn_ray(it, d);
  r.tmax = dist;
  ts->rays++;
  if (accel_occluded(c->acc, &r)) return 0;
  *dir = d;
  return 1;
}

float ao_ray_length(const scene *s, double d) { return d > 0 ? (float)d : 0.1f * s->radius; }

