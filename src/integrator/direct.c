/* direct.c — see direct.h. */
#include "integrator/direct.h"
#include "core/sampling.h"
#include <math.h>

ray segment_ray(vec3 o, vec3 from, vec3 p_to, vec3 n_to) {
  vec3 target = p_to;
  if (v3_len2(n_to) > 0) {
    vec3 err = v3_scale(v3_abs(p_to), fp_gamma(7));
    target = offset_origin(p_to, err, n_to, v3_sub(from, p_to));
  }
  ray r;
  r.o = o;
  r.d = v3_sub(target, o);
  r.tmax = 1 - 1e-4f;
  return r;
}

int ctx_intersect_solid(const render_ctx *c, ray r, hit *h, isect *it, float *before, thread_stats *ts) {
  *before = 0;
  for (int crossed = 0; crossed < 256; crossed++) { /* more: an offset that failed */
    if (!ctx_intersect(c, &r, h, ts)) return 0;
    isect_from_hit(c->s, &r, h, it);
    if (it->m->type != MAT_NULL) return 1;
    *before += h->t * v3_len(r.d);
    r.o = offset_origin_isect(it, r.d);
    r.tmax -= h->t;
  }
  return 0;
}

ray segment_ray_from(const isect *it, vec3 p_to, vec3 n_to) { return segment_ray(offset_origin_isect(it, v3_sub(p_to, it->p)), it->p, p_to, n_to); }

int ctx_segment_blocked(const render_ctx *c, const isect *it, vec3 p_to, vec3 n_to, thread_stats *ts) {
  ray r = segment_ray_from(it, p_to, n_to);
  return ctx_occluded(c, &r, ts);
}

/* An emitting sphere's sample: a direction in its cone k, and the first solid surface
 * along it, which must be one of the sphere's triangles; *pmf is the sphere's. */
static uint32_t sphere_sample(const render_ctx *c, const light_cone *k, vec3 p, const isect *it, float u1, float u2, thread_stats *ts,
                              float *pmf, light_li *ls) {
  const scene *s = c->s;
  vec3 wi = light_cone_sample(k, u1, u2);
  ray r = {it ? offset_origin_isect(it, wi) : p, wi, INFINITY};
  hit h;
  const light *l0 = &s->lights[k->sp->l0];
  if (!s->has_media && l0->tex_ke < 0) {
    /* Nothing to pass through, and one radiance over the sphere: no per-triangle data is
     * read (a random triangle's would be two cache misses). The sphere's triangles are the
     * range [first, end); its mesh is convex and p outside it, so the triangle met first
     * faces p and emits the sphere's radiance towards it. */
    if (!ctx_intersect(c, &r, &h, ts) || h.tri < k->sp->first || h.tri >= k->sp->end) return UINT32_MAX;
    memset(ls, 0, sizeof *ls);
    ls->wi = wi;
    ls->dist = h.t;
    ls->p_light = v3_add(r.o, v3_scale(wi, h.t));
    ls->n_light = v3_norm(v3_sub(ls->p_light, k->sp->c));
    ls->L = l0->L;
    ls->pdf = k->pdf;
    ls->visible = 1;
    return c3_black(ls->L) || !(*pmf > 0) ? UINT32_MAX : k->sp->l0 + (h.tri - k->sp->first);
  }
  isect hi;
  float before;
  if (!ctx_intersect_solid(c, r, &h, &hi, &before, ts)) return UINT32_MAX;
  int32_t lid = s->tri_light[h.tri];
  if (lid < (int32_t)k->sp->l0 || lid >= (int32_t)k->sp->l1) return UINT32_MAX; /* blocked, or past the faces' edge */
  memset(ls, 0, sizeof *ls);
  ls->wi = wi;
  ls->dist = before + h.t;
  ls->p_light = hi.p;
  ls->n_light = hi.ng;
  ls->L = light_tri_radiance(s, h.tri, hi.ng, v3_neg(wi), hi.u, hi.v);
  ls->pdf = k->pdf;
  ls->visible = 1;
  return c3_black(ls->L) || !(*pmf > 0) ? UINT32_MAX : (uint32_t)lid;
}

uint32_t direct_light_sample(const render_ctx *c, vec3 p, const isect *it, sampler *smp, thread_stats *ts, float *pmf, light_li *ls) {
  float ul = sampler_1d(smp), u1, u2;
  sampler_2d(smp, &u1, &u2);
  light_cone k;
  uint32_t li = light_select_cone(&c->ls, c->s, p, ul, pmf, &k);
  if (li == UINT32_MAX) return UINT32_MAX;
  if (k.sp) return sphere_sample(c, &k, p, it, u1, u2, ts, pmf, ls);
  if (!light_sample(c->s, &c->s->lights[li], p, u1, u2, ls)) return UINT32_MAX;
  ls->visible = 0;
  return li;
}

float ctx_light_pdf_area(const render_ctx *c, uint32_t li, vec3 p, vec3 p_light, vec3 n_light) {
  light_cone k;
  if (light_sphere_at(&c->ls, c->s, li, p, &k)) return light_range_pmf(&c->ls, k.sp->l0, k.sp->l1, p) * k.pdf;
  return ctx_light_pmf(c, li, p) * light_pdf_area(&c->s->lights[li], p, p_light, n_light);
}

int sample_direct_unshadowed(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                             thread_stats *ts, int mis, direct_sample *out) {
  float pmf;
  light_li ls;
  if (direct_light_sample(c, it->p, it, smp, ts, &pmf, &ls) == UINT32_MAX) return 0;
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
  float light_pdf = pmf * ls.pdf;
  float w = (ls.delta || !mis) ? 1.0f : power_heuristic(light_pdf, bpdf);
  out->f_cos = c3_scale(f, fabsf(wi_l.z));
  out->Li = ls.L;
  out->scale = w / light_pdf;
  out->light_pdf = light_pdf; /* pick x sample density (per steradian, or the delta light's weight) */
  out->delta = ls.delta;
  out->wi = ls.wi;
  out->p_light = ls.p_light;
  out->n_light = ls.n_light;
  out->far = isinf(ls.dist);
  out->visible = ls.visible;
  return 1;
}

int sample_direct(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                  thread_stats *ts, int mis, direct_sample *out) {
  return sample_direct_unshadowed(c, it, b, fr, wo, smp, ts, mis, out) &&
         (out->visible || !ctx_segment_blocked(c, it, out->p_light, out->n_light, ts));
}

rgb estimate_direct_nomis(const render_ctx *c, const isect *it, const bsdf *b, const frame *fr, vec3 wo, sampler *smp,
                          thread_stats *ts) {
  direct_sample d;
  if (!sample_direct(c, it, b, fr, wo, smp, ts, 0, &d)) return c3(0, 0, 0);
  return c3_scale(c3_mul(d.f_cos, d.Li), d.scale);
}

rgb emitted_along(const render_ctx *c, const ray *r, const hit *h, int found, const isect *it) {
  const scene *s = c->s;
  if (!found) {
    if (c->ls.env_index < 0) return c3(0, 0, 0);
    return light_env_radiance(s, &s->lights[c->ls.env_index], r->d);
  }
  int32_t lid;
  return light_hit(s, h->tri, it->p, it->ng, v3_neg(r->d), it->u, it->v, &lid);
}

