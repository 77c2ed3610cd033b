/* path.c — owns the `path` integrator: unidirectional path tracing with next-event
 * estimation and multiple importance sampling (power heuristic, Veach 1997) between light
 * and BSDF sampling, delta lights and specular lobes handled without MIS, and unbiased
 * Russian roulette (digest 000: divide by the continuation probability). Emission found
 * by BSDF-sampled rays is MIS-weighted against the NEE that could have found it, so
 * nothing is counted twice. Scenes with participating media or null surfaces take the
 * walk of path_media.c. One path at a time (path_radiance) and a batch stage by stage
 * (path_radiance_n) share the vertex (path_vertex). */
#include "integrator/path_common.h"
#include "integrator/integrator.h"
#include "core/sampling.h"

/* One vertex of an RGB path at the surface it (reached along *r), depth below the
 * maximum: the light sample, added to *L when nothing can block it and otherwise left in
 * *se with its shadow ray in *sray (*has_shadow 1) for the caller to test; then the BSDF
 * sample and Russian roulette, which update *r, *st and *beta. Returns 1 when the path
 * goes on. */
static int path_vertex(const render_ctx *c, int depth, isect *it, ray *r, path_state *st, rgb *beta, sampler *smp, thread_stats *ts, rgb *L,
                       ray *sray, rgb *se, int *has_shadow) {
  vec3 wo = v3_neg(r->d);
  bsdf b2, b = bsdf_at_blend(c->s, it, &b2); /* a blend: both its BSDFs */
  frame fr = shading_frame(it, &b, wo);      /* opaque surfaces are two-sided */
  sampler_set_dim(smp, sdim_bounce(depth, SDIM_LIGHT_PICK));
  direct_sample d;
  *has_shadow = 0;
  if (bsdf_has_smooth(&b) && sample_direct_unshadowed(c, it, &b, &fr, wo, smp, ts, 1, &d)) {
    rgb e = c3_mul(*beta, c3_scale(c3_mul(d.f_cos, d.Li), d.scale));
    if (d.visible) *L = c3_add(*L, e);
    else {
      *sray = segment_ray_from(it, d.p_light, d.n_light);
      *se = e;
      *has_shadow = 1;
    }
  }
  rgb weight;
  sampler_set_dim(smp, sdim_bounce(depth, SDIM_LOBE));
  if (!path_continue(it, &b, &fr, wo, smp, ts, st, &weight, r)) return 0;
  *beta = c3_mul(*beta, weight);
  return path_survive(st, beta, depth, c->rr_depth, smp);
}

rgb path_radiance(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, int count_first_emission) {
  rgb L = c3(0, 0, 0), beta = c3(1, 1, 1);
  path_state st = path_state_start(r.o); /* camera rays count emission fully */
  int max_depth = c->max_depth >= 0 ? c->max_depth : PATH_HARD_CAP;
  for (int depth = 0;; depth++) {
    isect it;
    rgb Le;
    float w;
    int surface = path_trace_vertex(c, &r, &st, ts, &it, &Le, &w);
    if (!c3_black(Le) && (depth > 0 || count_first_emission)) L = c3_add(L, c3_scale(c3_mul(beta, Le), w));
    if (!surface || depth >= max_depth) break;
    ray sray = r;
    rgb se = c3(0, 0, 0);
    int pending, go = path_vertex(c, depth, &it, &r, &st, &beta, smp, ts, &L, &sray, &se, &pending);
    if (pending && !ctx_occluded(c, &sray, ts)) L = c3_add(L, se);
    if (!go) break;
  }
  return L;
}

/* Starts loading what isect_from_hit reads of triangle t (its indices, material and flags,
 * then its vertices' positions, normals and UVs), so that the loads run while another
 * path is shaded. always_inline: GCC drops calls to a function of prefetches alone. */
static inline __attribute__((always_inline)) void prefetch_tri(const scene *s, uint32_t t) {
  const uint32_t *ix = &s->idx[3 * t];
  __builtin_prefetch(&s->tri_mat[t]);
  __builtin_prefetch(&s->tri_flags[t]);
  uint32_t a = ix[0], b = ix[1], d = ix[2];
  __builtin_prefetch(&s->pos[a]); __builtin_prefetch(&s->pos[b]); __builtin_prefetch(&s->pos[d]);
  __builtin_prefetch(&s->nrm[a]); __builtin_prefetch(&s->nrm[b]); __builtin_prefetch(&s->nrm[d]);
  __builtin_prefetch(&s->uv[2 * a]); __builtin_prefetch(&s->uv[2 * b]); __builtin_prefetch(&s->uv[2 * d]);
}

/* path_radiance for n camera rays at once, stage by stage (a wavefront): the live paths'
 * rays are traced one after another, each hit shaded as it is found (its emission, its
 * light sample and the next ray), and the shadow rays of the whole stage then go to the
 * accelerator together (accel_occluded_n: Embree's streams). Every path draws the same
 * numbers and adds the same terms in the same order as path_radiance, so out[i] is its
 * result bit for bit. Each path's closest hit is found one path ahead, its triangle's data
 * prefetched while the path before it is shaded (0.95x the time on Sponza). (Tracing the
 * whole stage before shading it, with the hits' vertex data prefetched, measured 1.08x
 * slower on Veach's MIS file.) */
static void path_radiance_n(const render_ctx *c, const ray *r0, sampler *smp, thread_stats *ts, int count_first_emission, rgb *out,
                            int n) {
  int max_depth = c->max_depth >= 0 ? c->max_depth : PATH_HARD_CAP;
  ray r[LI_BATCH_MAX], shadow[LI_BATCH_MAX];
  path_state st[LI_BATCH_MAX];
  rgb beta[LI_BATCH_MAX], pend[LI_BATCH_MAX];
  int live[LI_BATCH_MAX], owner[LI_BATCH_MAX];
  uint8_t blocked[LI_BATCH_MAX];
  for (int i = 0; i < n; i++) {
    r[i] = r0[i];
    st[i] = path_state_start(r0[i].o);
    beta[i] = c3(1, 1, 1);
    out[i] = c3(0, 0, 0);
    live[i] = i;
  }
  int nlive = n;
  for (int depth = 0; nlive > 0; depth++) {
    int next = 0, nshadow = 0;
    /* one path ahead: path k + 1's ray is traced, and its triangle's data prefetched, before
     * path k is shaded (the ray does not depend on path k: the same image) */
    hit hq[2];
    int fq[2];
    fq[0] = ctx_intersect(c, &r[live[0]], &hq[0], ts);
    if (fq[0]) prefetch_tri(c->s, hq[0].tri);
    for (int k = 0; k < nlive; k++) {
      int i = live[k];
      if (k + 1 < nlive) {
        int q = (k + 1) & 1;
        fq[q] = ctx_intersect(c, &r[live[k + 1]], &hq[q], ts);
        if (fq[q]) prefetch_tri(c->s, hq[q].tri);
      }
      isect it;
      rgb Le;
      float w;
      int surface = path_hit_vertex(c, &r[i], &st[i], fq[k & 1] ? &hq[k & 1] : NULL, &it, &Le, &w);
      if (!c3_black(Le) && (depth > 0 || count_first_emission)) out[i] = c3_add(out[i], c3_scale(c3_mul(beta[i], Le), w));
      if (!surface || depth >= max_depth) continue;
      int pending, go = path_vertex(c, depth, &it, &r[i], &st[i], &beta[i], &smp[i], ts, &out[i], &shadow[nshadow], &pend[nshadow],
                                   &pending);
      if (pending) owner[nshadow++] = i; /* added after the stage's shadow rays, before anything else reaches out[i] */
      if (go) live[next++] = i;
    }
    ts->rays += (uint64_t)nshadow;
    accel_occluded_n(c->acc, shadow, blocked, nshadow);
    for (int k = 0; k < nshadow; k++)
      if (!blocked[k]) out[owner[k]] = c3_add(out[owner[k]], pend[k]);
    nlive = next;
  }
}

static void path_li_n(const render_ctx *c, const ray *r, sampler *smp, thread_stats *ts, rgb *out, int n) {
  int first = !c->hide_emitters;
  if (!c->s->has_media) { path_radiance_n(c, r, smp, ts, first, out, n); return; }
  for (int i = 0; i < n; i++) out[i] = path_radiance_media(c, r[i], &smp[i], ts, first);
}

static rgb path_li(const render_ctx *c, ray r, sampler *smp, thread_stats *ts) {
  int first = !c->hide_emitters;
  return c->s->has_media ? path_radiance_media(c, r, smp, ts, first) : path_radiance(c, r, smp, ts, first);
}

const integrator_ops integrator_path = {
    .name = "path",
    .description = "unidirectional path tracing with next-event estimation, MIS and Russian roulette",
    .kind = INTEGRATOR_RAY,
    .li = path_li,
    .li_n = path_li_n,
};
