/* aov.c — see aov.h. */
#include "integrator/direct.h"
#include "integrator/ao.h"
#include "render/aov.h"
#include <string.h>

const char *const aov_prefixes[AOV_KIND_COUNT] = {"albedo:", "normal:", "depth:", "ao:", "bent:", "spp:", "denoised:"};

int aov_kind_of(const char *output, size_t *plen) {
  for (int k = 0; k < AOV_KIND_COUNT; k++) {
    size_t n = strlen(aov_prefixes[k]);
    if (!strncmp(output, aov_prefixes[k], n)) {
      if (plen) *plen = n;
      return k;
    }
  }
  if (plen) *plen = 0;
  return -1;
}

void aov_record(const session *ss, ray ry, float *acc, sampler *smp, thread_stats *ts) {
  hit h;
  isect it;
  float before; /* the distance to the last null surface passed (they have no AOVs) */
  if (!ctx_intersect_solid(&ss->ctx, ry, &h, &it, &before, ts)) return;
  bsdf b = bsdf_at(ss->s, &it);
  material tm = *it.m;
  tm.kd = b.kd;
  tm.ks = b.ks;
  rgb a = material_albedo(&tm, v3_dot(it.ns, v3_neg(ry.d)));
  vec3 n = v3_faceforward(it.ns, v3_neg(ry.d));
  acc[AOV_ALBEDO] += a.r; acc[AOV_ALBEDO + 1] += a.g; acc[AOV_ALBEDO + 2] += a.b;
  acc[AOV_NORMAL] += n.x; acc[AOV_NORMAL + 1] += n.y; acc[AOV_NORMAL + 2] += n.z;
  acc[AOV_DEPTH] += before + h.t * v3_len(ry.d);
  if (!ss->ctx.hide_emitters) {
    rgb e = emitted_along(&ss->ctx, &ry, &h, 1, &it);
    acc[AOV_EMIT] += e.r; acc[AOV_EMIT + 1] += e.g; acc[AOV_EMIT + 2] += e.b;
  }
  if (!(ss->opt.aovs & VALO_AOVS_AO)) return;
  vec3 dir;
  sampler_set_dim(smp, SDIM_AOV);
  if (ao_sample(&ss->ctx, &it, n, ss->ao_dist, smp, ts, &dir)) {
    acc[AOV_AO] += 1;
    acc[AOV_BENT] += dir.x; acc[AOV_BENT + 1] += dir.y; acc[AOV_BENT + 2] += dir.z;
  }
}
