/* path_media.c — owns the path integrator's walk through participating media and null
 * surfaces (pbrt-v3's VolPathIntegrator, Mitsuba 3's volpath), in RGB or on --spectral's
 * four wavelengths (the path's channels, material/medium.h: the walk is written once on
 * spec4 lanes, RGB in lanes 0-2): free-flight sampling with MIS over the channels
 * between surfaces; at a scattering point next-event estimation with the Henyey-Greenstein phase
 * function, MIS-weighted against phase sampling, and phase sampling to continue. Rays
 * pass null surfaces without a vertex (no depth, no MIS state), changing medium where a
 * shape bounds one; shadow rays do the same and carry the transmittance of every medium
 * they cross, so next-event estimation and MIS work as in path.c (the weights use the
 * directional pdfs: both strategies carry the same transmittance). */
#include "integrator/path_common.h"
#include "integrator/integrator.h"
#include "material/medium.h"
#include "core/sampling.h"

/* A ray crossing more null surfaces than this in one segment is taken to be stuck (an
 * offset that failed) and ends, as a blocked shadow ray. */
#define NULL_CROSSINGS_MAX 256

/* Transmittance along the segment r (to r.o + r.d, up to r.tmax) starting in medium
 * med: the product of each crossed medium's Beer-Lambert term, 0 when a surface that is
 * not null blocks it. far: the light lies at infinity (environment, directional), so a
 * medium the segment ends in goes on for ever. */
static spec4 segment_transmittance(const render_ctx *c, ray r, int32_t med, int far, uint64_t key, const wavelengths *wl,
                                   thread_stats *ts) {
  const scene *s = c->s;
  spec4 tr = chan_one(wl);
  vec3 target = v3_add(r.o, r.d);
  for (int k = 0; k < NULL_CROSSINGS_MAX; k++) {
    hit h;
    int found = ctx_intersect(c, &r, &h, ts);
    if (med >= 0) {
      float dl = v3_len(r.d);
      float len = found ? h.t * dl : far ? INFINITY : r.tmax * dl;
      mcoef mc = medium_coef(&s->media[med], wl);
      tr = spec_mul(tr, medium_transmittance(&s->media[med], &mc, r.o, v3_scale(r.d, 1 / dl), len, rng_mix64(key + (uint64_t)k)));
      if (spec_black(tr)) return tr;
    }
    if (!found) return tr;
    if (s->mats[s->tri_mat[h.tri]].type != MAT_NULL) return spec_const(0);
    isect it;
    isect_from_hit(s, &r, &h, &it);
    med = scene_medium_after(s, h.tri, it.ng, r.d, med);
    r.o = offset_origin_isect(&it, r.d);
    r.d = v3_sub(target, r.o);
    r.tmax = 1 - 1e-4f;
  }
  return spec_const(0);
}

/* Next-event estimation at a scattering point p of medium med (HG g) for viewer
 * direction wo, MIS-weighted (power heuristic) against phase sampling. */
static spec4 medium_direct(const render_ctx *c, vec3 p, vec3 wo, int32_t med, sampler *smp, uint64_t key, const wavelengths *wl,
                           thread_stats *ts) {
  float pmf;
  light_li ls;
  if (direct_light_sample(c, p, NULL, smp, ts, &pmf, &ls) == UINT32_MAX) return spec_const(0);
  float f = phase_hg(v3_dot(wo, ls.wi), c->s->media[med].g), light_pdf = pmf * ls.pdf;
  if (!(f > 0) || !(light_pdf > 0)) return spec_const(0);
  spec4 tr = segment_transmittance(c, segment_ray(p, p, ls.p_light, ls.n_light), med, isinf(ls.dist), key, wl, ts);
  if (spec_black(tr)) return spec_const(0);
  float w = ls.delta ? 1.0f : power_heuristic(light_pdf, f);
  return spec_scale(spec_mul(chan_from_rgb(ls.L, wl), tr), f * w / light_pdf);
}

/* The key of a tracking walk's random numbers: hashed from the camera sample's key
 * (distinct per pixel, sample index and seed) and the walk's number n (free flights
 * count up from 0, shadow rays down from ~0 by depth). */
static uint64_t walk_key(const sampler *smp, uint32_t n) { return rng_mix64(smp->key ^ (0x6d65646961ULL + (uint64_t)n * 0xd1b54a32d192ed03ULL)); }

static int finite4(spec4 v) {
  for (int k = 0; k < N_LAMBDA; k++)
    if (!isfinite(v.v[k])) return 0;
  return 1;
}

spec4 path_media_walk(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, int count_first_emission, wavelengths *wl) {
  const scene *s = c->s;
  spec4 L = spec_const(0), beta = chan_one(wl);
  path_state st = path_state_start(r.o);
  int max_depth = c->max_depth >= 0 ? c->max_depth : PATH_HARD_CAP;
  int32_t med = s->cam_medium;
  uint32_t flight = 0; /* free-flight samples drawn so far (their dimensions), and the
                          key of each tracking walk's own random numbers (grid media) */
  for (int depth = 0;; depth++) {
    /* To the next vertex: a scattering point, a surface that is not null, or away. */
    isect it;
    hit h;
    int found = 0, scattered = 0, crossings = 0;
    vec3 mp = r.o;
    for (;;) {
      found = ctx_intersect(c, &r, &h, ts);
      if (med >= 0) {
        const medium *m = &s->media[med];
        mcoef mc = medium_coef(m, wl);
        float dlen = v3_len(r.d), t;
        spec4 w, emit;
        sampler_set_dim(smp, SDIM_MEDIUM + 2 * (flight++ % SDIM_MEDIUM_MAX));
        float uc = sampler_1d(smp), ud = sampler_1d(smp);
        vec3 dir = v3_scale(r.d, 1 / dlen);
        scattered = medium_sample(m, &mc, &beta, r.o, dir, found ? h.t * dlen : INFINITY, uc, ud, walk_key(smp, flight), &t, &w, &emit);
        if (medium_glows(m) && (depth > 0 || count_first_emission)) {
          spec4 le = {{mc.le[0], mc.le[1], mc.le[2], mc.le[3]}};
          L = spec_add(L, spec_mul(spec_mul(beta, emit), le));
        }
        beta = spec_mul(beta, w);
        if (spec_black(beta)) return L;
        if (scattered) { mp = v3_add(r.o, v3_scale(dir, t)); break; }
      }
      if (!found) break;
      isect_from_hit(s, &r, &h, &it);
      if (it.m->type != MAT_NULL) break;
      med = scene_medium_after(s, h.tri, it.ng, r.d, med);
      r.o = offset_origin_isect(&it, r.d);
      r.tmax = INFINITY;
      if (++crossings > NULL_CROSSINGS_MAX) return L;
    }
    if (scattered) {
      if (depth >= max_depth) break;
      vec3 wo = v3_neg(v3_norm(r.d)), wi;
      float g = s->media[med].g, u1, u2;
      sampler_set_dim(smp, sdim_bounce(depth, SDIM_LIGHT_PICK));
      L = spec_add(L, spec_mul(beta, medium_direct(c, mp, wo, med, smp, walk_key(smp, ~(uint32_t)depth), wl, ts)));
      sampler_set_dim(smp, sdim_bounce(depth, SDIM_BSDF_DIR));
      sampler_2d(smp, &u1, &u2);
      float pdf = phase_hg_sample(wo, g, u1, u2, &wi); /* weight phase / pdf = 1 */
      st.specular = 0;
      st.prev_pdf = pdf;
      st.prev_p = mp;
      r.o = mp;
      r.d = wi;
      r.tmax = INFINITY;
    } else {
      rgb Le;
      float w;
      path_vertex_emission(c, &r, &st, found ? &h : NULL, found ? &it : NULL, &Le, &w);
      if (!c3_black(Le) && (depth > 0 || count_first_emission)) L = spec_add(L, spec_scale(spec_mul(beta, chan_from_rgb(Le, wl)), w));
      if (!found || depth >= max_depth) break;
      vec3 wo = v3_neg(r.d), ng = it.ng; /* the winding normal: shading_frame may turn it->ng */
      bsdf b = bsdf_at(s, &it);
      const nk_curve *nk = wl ? spectral_bsdf(s, &it, &b, wl) : NULL;
      frame fr = shading_frame(&it, &b, wo);
      sampler_set_dim(smp, sdim_bounce(depth, SDIM_LIGHT_PICK));
      direct_sample d;
      if (bsdf_has_smooth(&b) && sample_direct_unshadowed(c, &it, &b, &fr, wo, smp, ts, 1, &d)) {
        ray sr = segment_ray(offset_origin_isect(&it, v3_sub(d.p_light, it.p)), it.p, d.p_light, d.n_light);
        spec4 tr = segment_transmittance(c, sr, scene_medium_after(s, it.tri, ng, d.wi, med), d.far, walk_key(smp, ~(uint32_t)depth), wl, ts);
        /* f and Li upsampled apart and multiplied per wavelength (in RGB per channel) */
        spec4 f = chan_from_rgb(d.f_cos, wl);
        if (nk) f = spec_mul(f, nk_fresnel(nk, wo, d.wi, wl));
        L = spec_add(L, spec_mul(beta, spec_scale(spec_mul(spec_mul(f, chan_from_rgb(d.Li, wl)), tr), d.scale)));
      }
      rgb weight;
      sampler_set_dim(smp, sdim_bounce(depth, SDIM_LOBE));
      if (!path_continue(&it, &b, &fr, wo, smp, ts, &st, &weight, &r)) break;
      med = scene_medium_after(s, it.tri, ng, r.d, med);
      beta = spec_mul(beta, chan_from_rgb(weight, wl));
      if (nk) beta = spec_mul(beta, nk_fresnel(nk, wo, r.d, wl));
    }
    if (spec_black(beta) || !finite4(beta)) break;
    sampler_set_dim(smp, sdim_bounce(depth, SDIM_ROULETTE));
    float survive = path_roulette(&st, spec_max(beta), depth, c->rr_depth, smp);
    if (survive == 0) break;
    beta = spec_scale(beta, survive);
  }
  return L;
}

rgb path_radiance_media(const render_ctx *c, ray r, sampler *smp, thread_stats *ts, int count_first_emission) {
  spec4 L = path_media_walk(c, r, smp, ts, count_first_emission, NULL);
  return c3(L.v[0], L.v[1], L.v[2]);
}
