/* path.c — owns the `path` integrator: unidirectional path tracing with next-event
 * estimation and multiple importance sampling (power heuristic, Veach 1997) between light
 * and BSDF sampling, delta lights and specular lobes handled without MIS, and unbiased
 * Russian roulette (digest 000: divide by the continuation probability). Emission found
 * by BSDF-sampled rays is MIS-weighted against the NEE that could have found it, so
 * nothing is counted twice. Scenes with participating media or null surfaces take the
 * walk of path_media.c. */
#include "integrator/path_common.h"
#include "integrator/integrator.h"
#include "core/sampling.h"

rgb path_radiance(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, int count_first_emission) {
  const scene *s = c->s;
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
    vec3 wo = v3_neg(r.d);

    bsdf b2, b = bsdf_at_blend(s, &it, &b2); /* a blend: both its BSDFs */
    frame fr = shading_frame(&it, &b, wo); /* opaque surfaces are two-sided */
    sampler_set_dim(smp, sdim_bounce(depth, SDIM_LIGHT_PICK));
    if (bsdf_has_smooth(&b)) L = c3_add(L, c3_mul(beta, estimate_direct(c, &it, &b, &fr, wo, smp, ts)));

    rgb weight;
    sampler_set_dim(smp, sdim_bounce(depth, SDIM_LOBE));
    if (!path_continue(&it, &b, &fr, wo, smp, ts, &st, &weight, &r)) break;
    beta = c3_mul(beta, weight);
    if (!path_survive(&st, &beta, depth, c->rr_depth, smp)) break;
  }
  return L;
}

/* path_radiance for n camera rays at once, stage by stage (a wavefront): the live paths'
 * rays are traced one after another, each hit is shaded (its emission, its light sample
 * and the next ray), and the shadow rays of the whole stage then go to the accelerator
 * together (accel_occluded_n: Embree's streams). Every path draws the same numbers and
 * adds the same terms in the same order as path_radiance, so out[i] is its result bit
 * for bit. */
static void path_radiance_n(const render_ctx *c, const ray *r0, sampler *smp, thread_stats *ts, int count_first_emission, rgb *out,
                            int n) {
  const scene *s = c->s;
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
    for (int k = 0; k < nlive; k++) {
      int i = live[k];
      rgb *L = &out[i];
      isect it;
      rgb Le;
      float w;
      int surface = path_trace_vertex(c, &r[i], &st[i], ts, &it, &Le, &w);
      if (!c3_black(Le) && (depth > 0 || count_first_emission)) *L = c3_add(*L, c3_scale(c3_mul(beta[i], Le), w));
      if (!surface || depth >= max_depth) continue;
      vec3 wo = v3_neg(r[i].d);
      bsdf b2, b = bsdf_at_blend(s, &it, &b2);
      frame fr = shading_frame(&it, &b, wo);
      sampler_set_dim(&smp[i], sdim_bounce(depth, SDIM_LIGHT_PICK));
      direct_sample d;
      if (bsdf_has_smooth(&b) && sample_direct_unshadowed(c, &it, &b, &fr, wo, &smp[i], ts, 1, &d)) {
        rgb e = c3_mul(beta[i], c3_scale(c3_mul(d.f_cos, d.Li), d.scale));
        if (d.visible) *L = c3_add(*L, e);
        else { /* added after the stage's shadow rays, before anything else reaches L */
          shadow[nshadow] = segment_ray_from(&it, d.p_light, d.n_light);
          pend[nshadow] = e;
          owner[nshadow++] = i;
        }
      }
      rgb weight;
      sampler_set_dim(&smp[i], sdim_bounce(depth, SDIM_LOBE));
      if (!path_continue(&it, &b, &fr, wo, &smp[i], ts, &st[i], &weight, &r[i])) continue;
      beta[i] = c3_mul(beta[i], weight);
      if (!path_survive(&st[i], &beta[i], depth, c->rr_depth, &smp[i])) continue;
      live[next++] = i;
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
