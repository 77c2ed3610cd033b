/* lightpath.c — owns light-path shooting (lightpath.h): emission, adjoint BSDF sampling,
 * Russian roulette, and the deterministic chunked rounds. */
#include "integrator/path_common.h"
#include "integrator/lightpath.h"
#include "core/threadpool.h"
#include "core/error.h"
#include <stdlib.h>
#include <string.h>

#define CHUNK 1024
#define MAX_BOUNCES 64
#define MAX_EMIT_FACTOR 64

typedef struct chunk_buf { unsigned char *rec; uint32_t n, cap; int oom; } chunk_buf;
typedef struct shoot_job {
  const render_ctx *c;
  uint64_t first, end, key;
  size_t rec_size;
  int only_specular;
  const lp_aim *aim;
  lp_visit_fn visit;
  void *user;
  chunk_buf *bufs;
  thread_stats *ts;
} shoot_job;

static void *slot(chunk_buf *b, size_t rec_size) {
  if (b->oom) return NULL;
  if (b->n == b->cap) {
    uint32_t cap = b->cap ? 2 * b->cap : 64;
    unsigned char *np = realloc(b->rec, (size_t)cap * rec_size);
    if (!np) { b->oom = 1; return NULL; }
    b->rec = np;
    b->cap = cap;
  }
  return b->rec + (size_t)b->n * rec_size;
}

static void shoot_path(const shoot_job *j, uint64_t index, chunk_buf *out, thread_stats *ts) {
  const render_ctx *c = j->c;
  const scene *s = c->s;
  sampler smp = sampler_make_kind(j->key, 0, index, SAMPLER_SOBOL);
  float ul = sampler_1d(&smp), u[4];
  sampler_2d(&smp, &u[0], &u[1]);
  sampler_2d(&smp, &u[2], &u[3]);
  float pmf;
  uint32_t li = light_select_power(&c->ls, ul, &pmf);
  light_emit e;
  if (!(pmf > 0)) return;
  if (!(j->aim && light_sample_emit_toward(s, &s->lights[li], u, j->aim->c, j->aim->r, &e)) && !light_sample_emit(s, &s->lights[li], u, &e)) return;
  if (c3_black(e.beta)) return;
  rgb beta = c3_scale(e.beta, 1 / pmf);
  ray r = {e.o, e.d, INFINITY};
  if (s->lights[li].type == LIGHT_AREA) r.o = offset_origin(e.o, v3(0, 0, 0), e.n, e.d);
  int specular_path = 1;
  for (int depth = 0; depth < MAX_BOUNCES; depth++) {
    hit h;
    if (!ctx_intersect(c, &r, &h, ts)) return;
    isect it;
    isect_from_hit(s, &r, &h, &it);
    bsdf b = bsdf_at(s, &it);
    vec3 wo = v3_neg(r.d);
    frame fr = shading_frame(&it, &b, wo);
    /* a blend's photons are stored whichever material it picked: the camera's pick applies
     * the BSDF, so the flux stored must not carry this one's */
    if (bsdf_has_smooth(&b) || (s->mats[s->tri_mat[h.tri]].type == MAT_BLEND && surface_has_smooth(s, h.tri))) {
      lp_vertex v = {&it, &b, &fr, r.d, beta, depth, specular_path};
      void *rec = slot(out, j->rec_size);
      if (rec && j->visit(j->user, &v, rec)) out->n++;
    }
    path_state st = path_state_start(r.o);
    rgb w;
    ray next;
    float eta_before = st.eta_acc;
    if (!path_continue(&it, &b, &fr, wo, &smp, ts, &st, &w, &next)) return;
    if (j->only_specular && !st.specular) return;
    specular_path = specular_path && st.specular;
    /* adjoint transport: undo the radiance scale across refraction, and correct for
     * shading normals (Veach 1997, 5.3.2) */
    w = c3_scale(w, st.eta_acc / eta_before);
    vec3 wi = next.d;
    float den = fabsf(v3_dot(wo, it.ng)) * fabsf(v3_dot(wi, fr.n));
    float corr = den > 0 ? fabsf(v3_dot(wo, fr.n)) * fabsf(v3_dot(wi, it.ng)) / den : 0;
    if (!st.specular || bsdf_transmits(&b)) w = c3_scale(w, fminf(corr, 10.0f));
    rgb nb = c3_mul(beta, w);
    float q = fminf(1.0f, c3_max(nb) / fmaxf(c3_max(beta), 1e-30f));
    if (!(q > 0) || sampler_1d(&smp) >= q) return;
    beta = c3_scale(nb, 1 / q);
    if (!c3_finite(beta)) return;
    r = next;
  }
}

static void shoot_chunk(void *user, int64_t item, int thread) {
  shoot_job *j = user;
  chunk_buf *b = &j->bufs[item];
  uint64_t lo = j->first + (uint64_t)item * CHUNK, hi = lo + CHUNK < j->end ? lo + CHUNK : j->end;
  for (uint64_t i = lo; i < hi; i++) shoot_path(j, i, b, &j->ts[thread]);
}

/* Shoots paths [first, first + npaths) and appends their records to *all (n of cap). */
static valo_status shoot_round(const render_ctx *c, uint64_t key, uint64_t first, uint64_t npaths, size_t rec_size, int only_specular,
                               const lp_aim *aim, lp_visit_fn visit, void *user, thread_stats *ts, unsigned char **all, uint64_t *n, uint64_t *mcap,
                               valo_error *err) {
  int64_t chunks = (int64_t)((npaths + CHUNK - 1) / CHUNK);
  chunk_buf *bufs = calloc((size_t)(chunks ? chunks : 1), sizeof *bufs);
  if (!bufs) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  shoot_job j = {c, first, first + npaths, key, rec_size, only_specular, aim, visit, user, bufs, ts};
  parallel_for(c->threads, chunks, shoot_chunk, &j);
  valo_status st = VALO_OK;
  for (int64_t k = 0; k < chunks && st == VALO_OK; k++) {
    if (bufs[k].oom) { st = err_set(err, VALO_ERR_NOMEM, "out of memory for light paths"); break; }
    if (*n + bufs[k].n > *mcap) {
      uint64_t nc = *mcap ? 2 * *mcap : 4096;
      while (nc < *n + bufs[k].n) nc *= 2;
      if (nc > UINT32_MAX / 2) { st = err_set(err, VALO_ERR_NOMEM, "too many light-path records"); break; }
      unsigned char *np = realloc(*all, nc * rec_size);
      if (!np) { st = err_set(err, VALO_ERR_NOMEM, "out of memory for light paths"); break; }
      *all = np;
      *mcap = nc;
    }
    if (bufs[k].n) memcpy(*all + *n * rec_size, bufs[k].rec, (size_t)bufs[k].n * rec_size);
    *n += bufs[k].n;
  }
  for (int64_t k = 0; k < chunks; k++) free(bufs[k].rec);
  free(bufs);
  return st;
}

/* Either rounds until `target` records (npaths == 0), or exactly npaths paths. */
static valo_status shoot(const render_ctx *c, uint64_t key, uint64_t target, uint64_t npaths, size_t rec_size, int only_specular,
                         const lp_aim *aim, lp_visit_fn visit, void *user, lp_set *out, valo_error *err) {
  memset(out, 0, sizeof *out);
  if ((target == 0 && npaths == 0) || c->ls.table.n == 0) return VALO_OK;
  thread_stats *ts = calloc((size_t)c->threads, sizeof *ts);
  if (!ts) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  uint64_t emitted = 0, n = 0, mcap = 0;
  unsigned char *all = NULL;
  valo_status st = VALO_OK;
  if (npaths) {
    st = shoot_round(c, key, 0, npaths, rec_size, only_specular, aim, visit, user, ts, &all, &n, &mcap, err);
    emitted = npaths;
  } else {
    uint64_t cap = target * MAX_EMIT_FACTOR, round = 4 * CHUNK;
    if (cap < 65536) cap = 65536;
    while (n < target && emitted < cap) {
      round = (round + CHUNK - 1) / CHUNK * CHUNK;
      st = shoot_round(c, key, emitted, round, rec_size, only_specular, aim, visit, user, ts, &all, &n, &mcap, err);
      emitted += round;
      if (st) break;
      /* next round: what the rate so far says reaches the target */
      double rate = (double)n / (double)emitted;
      double need = rate > 0 ? (double)(target - (n < target ? n : target)) / rate : (double)emitted * 4;
      round = (uint64_t)need + CHUNK;
      if (round > cap - (emitted < cap ? emitted : cap)) round = cap > emitted ? cap - emitted : CHUNK;
    }
  }
  for (int t = 0; t < c->threads && c->prep; t++) thread_stats_add(c->prep, &ts[t]);
  free(ts);
  if (st) { free(all); return st; }
  out->rec = all;
  out->n = (uint32_t)n;
  out->emitted = emitted;
  return VALO_OK;
}

valo_status lightpath_shoot(const render_ctx *c, uint64_t key, uint64_t target, size_t rec_size, int only_specular, const lp_aim *aim,
                            lp_visit_fn visit, void *user, lp_set *out, valo_error *err) {
  return shoot(c, key, target, 0, rec_size, only_specular, only_specular ? aim : NULL, visit, user, out, err);
}

valo_status lightpath_shoot_paths(const render_ctx *c, uint64_t key, uint64_t npaths, size_t rec_size, lp_visit_fn visit, void *user,
                                  lp_set *out, valo_error *err) {
  return shoot(c, key, 0, npaths, rec_size, 0, NULL, visit, user, out, err);
}
