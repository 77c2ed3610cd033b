/* light_select.c — owns the choice of a light for a shading point (light.h): the power
 * alias table, the local selection of small scenes, the light grid, the units of emitting
 * spheres and their cones. */
#include "light/light.h"
#include "core/sampling.h"
#include <stdlib.h>
#include <string.h>

/* The light grid (light.h): per-light centre, radius and (one-sided area lights) plane,
 * then each cell's running sums. */
typedef struct grid_light { vec3 c; float r, w_far; vec3 n; float d; int local, one_sided; } grid_light;

static int grid_build(light_sampler *ls, const scene *s) {
  uint32_t n = ls->nu;
  uint64_t budget = LIGHT_GRID_CELLS;
  if (budget * n > (64u << 20)) budget = (64u << 20) / n; /* at most 256 MB of sums */
  if (budget < 8) return 0;
  vec3 ext = v3_sub(s->bounds.hi, s->bounds.lo);
  float emax = fmaxf(ext.x, fmaxf(ext.y, ext.z));
  if (!(emax > 0) || !isfinite(emax)) return 0;
  float e[3] = {fmaxf(ext.x, 1e-3f * emax), fmaxf(ext.y, 1e-3f * emax), fmaxf(ext.z, 1e-3f * emax)};
  float h = cbrtf(e[0] * e[1] * e[2] / (float)budget);
  uint64_t cells = 1;
  for (int a = 0; a < 3; a++) {
    int d = (int)ceilf(e[a] / h);
    ls->gdim[a] = d < 1 ? 1 : d > 64 ? 64 : d;
    cells *= (uint64_t)ls->gdim[a];
  }
  grid_light *gl = malloc(n * sizeof *gl);
  float *cdf = malloc(cells * n * sizeof *cdf);
  if (!gl || !cdf) { free(gl); free(cdf); return -1; }
  for (uint32_t i = 0; i < n; i++) {
    grid_light *g = &gl[i];
    memset(g, 0, sizeof *g);
    uint32_t li = ls->unit0 ? ls->unit0[i] : i;
    const light *l = &s->lights[li];
    if (ls->unit0 && ls->unit0[i + 1] - li > 1) { /* an emitting sphere */
      const sphere_shape *sp = &s->spheres[l->sphere - 1];
      g->c = sp->c;
      g->r = sp->r;
      g->w_far = ls->upower[i] / (4 * PI_F);
      g->local = 1;
      continue;
    }
    float pw = ls->power[li];
    switch (l->type) {
    case LIGHT_AREA: {
      vec3 a = l->v[0], b = l->v[1], c = l->v[2];
      g->c = l->centroid;
      g->r = sqrtf(fmaxf(v3_len2(v3_sub(a, g->c)), fmaxf(v3_len2(v3_sub(b, g->c)), v3_len2(v3_sub(c, g->c)))));
      g->w_far = pw / PI_F;
      g->local = 1;
      g->one_sided = !l->two_sided;
      g->n = l->ng;
      g->d = -v3_dot(g->n, a);
      break;
    }
    case LIGHT_POINT: case LIGHT_SPOT: g->c = l->p; g->w_far = pw / (4 * PI_F); g->local = 1; break;
    case LIGHT_DIRECTIONAL: case LIGHT_ENV: g->w_far = 0; break; /* their own share (light.h) */
    }
  }
  vec3 cell = v3(e[0] / ls->gdim[0], e[1] / ls->gdim[1], e[2] / ls->gdim[2]);
  vec3 half = v3_scale(cell, 0.5f);
  float rc = v3_len(half);
  for (int z = 0; z < ls->gdim[2]; z++)
    for (int y = 0; y < ls->gdim[1]; y++)
      for (int x = 0; x < ls->gdim[0]; x++) {
        size_t ci = ((size_t)z * ls->gdim[1] + y) * ls->gdim[0] + x;
        float *row = cdf + ci * n;
        vec3 cc = v3(s->bounds.lo.x + (x + 0.5f) * cell.x, s->bounds.lo.y + (y + 0.5f) * cell.y, s->bounds.lo.z + (z + 0.5f) * cell.z);
        double total = 0;
        for (uint32_t i = 0; i < n; i++) {
          const grid_light *g = &gl[i];
          float w = g->w_far;
          if (g->local) {
            /* one-sided and the whole cell behind (or level with) its plane: nothing */
            if (g->one_sided &&
                v3_dot(g->n, cc) + g->d + fabsf(g->n.x) * half.x + fabsf(g->n.y) * half.y + fabsf(g->n.z) * half.z <= 0)
              w = 0;
            else {
              float rr = rc + g->r;
              w /= fmaxf(v3_len2(v3_sub(g->c, cc)), rr * rr);
            }
          }
          total += (w > 0 && isfinite(w)) ? w : 0;
          row[i] = (float)total;
        }
        float inv = total > 0 ? (float)(1 / total) : 0;
        for (uint32_t i = 0; i < n; i++) row[i] *= inv;
        if (total > 0) row[n - 1] = 1;
      }
  free(gl);
  ls->grid_cdf = cdf;
  ls->glo = s->bounds.lo;
  ls->ginv = v3(1 / cell.x, 1 / cell.y, 1 / cell.z);
  return 0;
}

/* The units of a sampler above the local count with spheres sampled by their cones. */
static int units_build(light_sampler *ls, const scene *s) {
  uint32_t n = ls->n, nu = n;
  for (uint32_t g = 0; g < s->nspheres; g++)
    if (s->spheres[g].l1 > s->spheres[g].l0) nu -= s->spheres[g].l1 - s->spheres[g].l0 - 1;
  if (nu == n) return 0;
  ls->unit0 = malloc((nu + 1) * sizeof *ls->unit0);
  ls->unit_of = malloc(n * sizeof *ls->unit_of);
  ls->upower = malloc(nu * sizeof *ls->upower);
  ls->power_cdf = malloc(n * sizeof *ls->power_cdf);
  if (!ls->unit0 || !ls->unit_of || !ls->upower || !ls->power_cdf) return -1;
  uint32_t u = 0;
  double acc = 0;
  for (uint32_t i = 0; i < n; u++) {
    const light *l = &s->lights[i];
    uint32_t end = i + 1;
    if (l->type == LIGHT_AREA && l->sphere) end = s->spheres[l->sphere - 1].l1; /* its sphere's lights, in order (scene_commit) */
    ls->unit0[u] = i;
    double sum = 0;
    for (; i < end; i++) {
      ls->unit_of[i] = u;
      sum += ls->power[i];
      ls->power_cdf[i] = acc += ls->power[i];
    }
    ls->upower[u] = (float)sum;
  }
  ls->unit0[nu] = n;
  ls->nu = nu;
  return 0;
}

static int is_infinite(const light *l) { return l->type == LIGHT_ENV || l->type == LIGHT_DIRECTIONAL; }

/* The infinite lights' share (light.h) and the table of the finite ones. */
static int infinite_build(light_sampler *ls, const scene *s) {
  uint32_t ninf = 0;
  for (uint32_t i = 0; i < ls->n; i++) ninf += is_infinite(&s->lights[i]) && ls->power[i] > 0;
  if (ninf == 0) return 0;
  ls->inf = malloc(ninf * sizeof *ls->inf);
  float *fw = malloc(ls->nu * sizeof *fw);
  if (!ls->inf || !fw) { free(fw); return -1; }
  for (uint32_t i = 0; i < ls->n; i++)
    if (is_infinite(&s->lights[i]) && ls->power[i] > 0) ls->inf[ls->ninf++] = i;
  for (uint32_t u = 0; u < ls->nu; u++) {
    uint32_t li = ls->unit0 ? ls->unit0[u] : u;
    fw[u] = is_infinite(&s->lights[li]) ? 0 : (ls->unit0 ? ls->upower[u] : ls->power[li]);
  }
  ls->has_finite = alias_build(&ls->ftable, fw, ls->nu) == 0;
  free(fw);
  ls->p_inf = ls->has_finite ? (float)ninf / (float)(ninf + 1) : 1.0f;
  return 0;
}

int light_sampler_init(light_sampler *ls, const scene *s, light_select_mode mode, int sphere_cones) {
  memset(ls, 0, sizeof *ls);
  ls->env_index = -1;
  ls->sphere_cones = sphere_cones;
  if (s->nlights == 0) return 0;
  float *w = malloc(s->nlights * sizeof *w);
  if (!w) return -1;
  for (uint32_t i = 0; i < s->nlights; i++) {
    w[i] = light_power(s, &s->lights[i]);
    if (!(w[i] >= 0) || !isfinite(w[i])) w[i] = 0;
    if (s->lights[i].type == LIGHT_ENV) ls->env_index = (int)i;
  }
  ls->power = w;
  ls->n = ls->nu = s->nlights;
  ls->local = s->nlights <= LIGHT_LOCAL_MAX;
  if (!ls->local && sphere_cones && units_build(ls, s)) { light_sampler_free(ls); return -1; }
  int rc = alias_build(&ls->table, ls->unit0 ? ls->upower : w, ls->nu);
  if (rc) { /* all lights black: nothing to sample */
    light_sampler_free(ls);
    return 0;
  }
  if (infinite_build(ls, s)) { light_sampler_free(ls); return -1; }
  if (!ls->local && mode == LIGHT_SELECT_GRID && grid_build(ls, s)) { light_sampler_free(ls); return -1; }
  return 0;
}
void light_sampler_free(light_sampler *ls) {
  alias_free(&ls->table);
  if (ls->inf) alias_free(&ls->ftable);
  free(ls->inf);
  ls->inf = NULL;
  ls->ninf = 0;
  ls->p_inf = 0;
  ls->has_finite = 0;
  free(ls->power);
  free(ls->grid_cdf);
  free(ls->power_cdf);
  free(ls->unit0);
  free(ls->unit_of);
  free(ls->upower);
  ls->power_cdf = NULL;
  ls->power = NULL;
  ls->grid_cdf = NULL;
  ls->unit0 = ls->unit_of = NULL;
  ls->upower = NULL;
  ls->n = ls->nu = 0;
}

/* Can light l send anything to p? Only one-sided area lights can be turned away. */
static int light_faces(const light *l, vec3 p) {
  if (l->type != LIGHT_AREA || l->two_sided) return 1;
  return v3_dot(l->ng, v3_sub(p, l->v[0])) > 0;
}

/* The local selection weights at p (power, 0 for lights facing away) and their sum, in
 * one order, so light_select and light_select_pmf agree to the bit. (The local selection
 * has no units: it is used only up to LIGHT_LOCAL_MAX lights.) */
static float facing_weights(const light_sampler *ls, const scene *s, vec3 p, float w[LIGHT_LOCAL_MAX]) {
  float total = 0;
  for (uint32_t i = 0; i < ls->n; i++) {
    const light *l = &s->lights[i];
    w[i] = light_faces(l, p) && !(ls->ninf && is_infinite(l)) ? ls->power[i] : 0;
    total += w[i];
  }
  return total;
}

/* The table next-event estimation picks finite lights from (by power). */
static inline const alias_table *nee_table(const light_sampler *ls) { return ls->ninf ? &ls->ftable : &ls->table; }

/* The grid cell's running sums for point p (NULL when the cell has no light). */
static const float *grid_row(const light_sampler *ls, vec3 p) {
  vec3 q = v3_sub(p, ls->glo);
  int c[3];
  const float f[3] = {q.x * ls->ginv.x, q.y * ls->ginv.y, q.z * ls->ginv.z};
  for (int a = 0; a < 3; a++) {
    int i = isfinite(f[a]) ? (int)floorf(fminf(fmaxf(f[a], 0), 1e6f)) : 0;
    c[a] = i >= ls->gdim[a] ? ls->gdim[a] - 1 : i;
  }
  const float *row = ls->grid_cdf + (((size_t)c[2] * ls->gdim[1] + c[1]) * ls->gdim[0] + c[0]) * ls->nu;
  return row[ls->nu - 1] > 0 ? row : NULL;
}
/* The mixture's probability of unit i at a point whose cell has running sums row: one
 * expression for light_select and light_select_pmf, so they agree to the bit. */
static inline float grid_mix_pmf(const light_sampler *ls, const float *row, uint32_t i) {
  return LIGHT_GRID_POWER * alias_pmf(nee_table(ls), i) + (1 - LIGHT_GRID_POWER) * (i ? row[i] - row[i - 1] : row[0]);
}

light_site light_locate(const light_sampler *ls, vec3 p) {
  light_site at = {p, ls->table.n && ls->grid_cdf ? grid_row(ls, p) : NULL};
  return at;
}
uint32_t light_select(const light_sampler *ls, const scene *s, vec3 p, float u, float *pmf) {
  light_site at = light_locate(ls, p);
  return light_select_at(ls, s, &at, u, pmf);
}

/* The probability of light li of unit un, the unit picked with probability pu: one
 * expression for light_select and light_select_pmf, so they agree to the bit. */
static inline float unit_share(const light_sampler *ls, uint32_t un, uint32_t li, float pu) {
  if (ls->unit0[un + 1] - ls->unit0[un] == 1) return pu;
  return ls->upower[un] > 0 ? pu * (ls->power[li] / ls->upower[un]) : 0;
}

/* The light of unit un picked with probability pu, rest the number left of the unit's
 * choice: the unit's only light, or one of its lights by power. */
static uint32_t unit_light(const light_sampler *ls, uint32_t un, float pu, float rest, float *pmf) {
  uint32_t l0 = ls->unit0[un], l1 = ls->unit0[un + 1];
  *pmf = pu;
  if (l1 - l0 == 1) return l0;
  double base = l0 ? ls->power_cdf[l0 - 1] : 0, target = base + (double)rest * (ls->power_cdf[l1 - 1] - base);
  uint32_t lo = l0, hi = l1 - 1; /* the first light whose running sum passes the target */
  while (lo < hi) {
    uint32_t mid = (lo + hi) / 2;
    if (ls->power_cdf[mid] > target) hi = mid; else lo = mid + 1;
  }
  *pmf = unit_share(ls, un, lo, pu);
  return lo;
}

/* A light by power from table t (over the units). */
static uint32_t power_pick(const light_sampler *ls, const alias_table *t, float u, float *pmf) {
  if (!ls->unit0) return alias_sample(t, u, pmf);
  float pu, rest;
  uint32_t un = alias_sample_rest(t, u, &pu, &rest);
  return unit_light(ls, un, pu, rest, pmf);
}
uint32_t light_select_power(const light_sampler *ls, float u, float *pmf) {
  if (ls->table.n == 0) return UINT32_MAX;
  return power_pick(ls, &ls->table, u, pmf);
}

/* The grid's choice at `at` (row not NULL): the unit, its mixture pmf *pu and, with
 * units, the number left of the choice *rest. */
static uint32_t grid_select(const light_sampler *ls, const float *row, float u, float *pu, float *rest) {
  uint32_t i;
  *rest = 0;
  const float a = LIGHT_GRID_POWER;
  if (u < a) {
    float power_pmf; /* not the answer: the mixture's pmf is */
    float v = fminf(u / a, 0x1.fffffep-1f);
    i = ls->unit0 ? alias_sample_rest(nee_table(ls), v, &power_pmf, rest) : alias_sample(nee_table(ls), v, &power_pmf);
  } else {
    float v = fminf((u - a) / (1 - a), 0x1.fffffep-1f);
    uint32_t lo = 0, hi = ls->nu - 1; /* the first i with row[i] > v */
    while (lo < hi) {
      uint32_t mid = (lo + hi) / 2;
      if (row[mid] > v) hi = mid; else lo = mid + 1;
    }
    i = lo;
    if (ls->unit0) {
      float below = i ? row[i - 1] : 0;
      *rest = fminf(fmaxf((v - below) / (row[i] - below), 0), 0x1.fffffep-1f);
    }
  }
  *pu = grid_mix_pmf(ls, row, i);
  return i;
}

/* The unit picked at `at` (a sampler with units): *pu and *rest as grid_select. */
static uint32_t unit_select(const light_sampler *ls, const light_site *at, float u, float *pu, float *rest) {
  if (ls->grid_cdf && at->row) return grid_select(ls, at->row, u, pu, rest);
  return alias_sample_rest(nee_table(ls), u, pu, rest);
}

/* The infinite lights' share of u (light.h): an infinite light when u falls in it (its pmf
 * in *pmf), else UINT32_MAX with u rescaled to the finite lights' share, *keep. */
static uint32_t infinite_pick(const light_sampler *ls, float *u, float *pmf, float *keep) {
  *keep = 1;
  if (!ls->ninf) return UINT32_MAX;
  if (*u < ls->p_inf) {
    uint32_t k = (uint32_t)(*u / ls->p_inf * (float)ls->ninf);
    *pmf = ls->p_inf / (float)ls->ninf;
    return ls->inf[k < ls->ninf ? k : ls->ninf - 1];
  }
  *keep = 1 - ls->p_inf;
  *u = fminf((*u - ls->p_inf) / *keep, 0x1.fffffep-1f);
  return UINT32_MAX;
}

static uint32_t finite_select_at(const light_sampler *ls, const scene *s, const light_site *at, float u, float *pmf) {
  if (ls->unit0) {
    float pu, rest;
    uint32_t un = unit_select(ls, at, u, &pu, &rest);
    return unit_light(ls, un, pu, rest, pmf);
  }
  if (ls->grid_cdf) {
    if (!at->row) return power_pick(ls, nee_table(ls), u, pmf);
    float rest;
    return grid_select(ls, at->row, u, pmf, &rest);
  }
  if (!ls->local) return power_pick(ls, nee_table(ls), u, pmf);
  float w[LIGHT_LOCAL_MAX], total = facing_weights(ls, s, at->p, w);
  if (!(total > 0)) return UINT32_MAX;
  float target = u * total, acc = 0;
  uint32_t last = UINT32_MAX;
  for (uint32_t i = 0; i < ls->n; i++) {
    if (w[i] <= 0) continue;
    last = i;
    acc += w[i];
    if (target < acc) break;
  }
  *pmf = w[last] / total;
  return last;
}

uint32_t light_select_at(const light_sampler *ls, const scene *s, const light_site *at, float u, float *pmf) {
  if (ls->table.n == 0) return UINT32_MAX;
  float keep;
  uint32_t li = infinite_pick(ls, &u, pmf, &keep);
  if (li != UINT32_MAX || !(keep > 0)) return li;
  li = finite_select_at(ls, s, at, u, pmf);
  if (li != UINT32_MAX) *pmf *= keep;
  return li;
}

/* The probability of unit un at p. */
static float unit_pmf(const light_sampler *ls, uint32_t un, vec3 p) {
  const float *row = ls->grid_cdf ? grid_row(ls, p) : NULL;
  return row ? grid_mix_pmf(ls, row, un) : alias_pmf(nee_table(ls), un);
}

/* The share of the finite lights in the choice (light.h). */
static inline float finite_share(const light_sampler *ls) { return ls->ninf ? 1 - ls->p_inf : 1; }

static float finite_pmf(const light_sampler *ls, const scene *s, uint32_t li, vec3 p) {
  if (ls->unit0) {
    uint32_t un = ls->unit_of[li];
    return unit_share(ls, un, li, unit_pmf(ls, un, p));
  }
  if (!ls->local) return unit_pmf(ls, li, p); /* each light its own unit */
  float w[LIGHT_LOCAL_MAX], total = facing_weights(ls, s, p, w);
  return total > 0 ? w[li] / total : 0;
}

float light_select_pmf(const light_sampler *ls, const scene *s, uint32_t li, vec3 p) {
  if (ls->table.n == 0 || li >= ls->n) return 0;
  if (ls->ninf && is_infinite(&s->lights[li])) return ls->power[li] > 0 ? ls->p_inf / (float)ls->ninf : 0;
  float keep = finite_share(ls);
  return keep > 0 ? keep * finite_pmf(ls, s, li, p) : 0;
}

float light_range_pmf(const light_sampler *ls, uint32_t l0, uint32_t l1, vec3 p) {
  if (ls->table.n == 0 || !ls->unit0 || l1 <= l0 || l1 > ls->n) return 0;
  uint32_t un = ls->unit_of[l0];
  if (ls->unit0[un] != l0 || ls->unit0[un + 1] != l1) return 0;
  float keep = finite_share(ls);
  return keep > 0 ? keep * unit_pmf(ls, un, p) : 0;
}

/* The cone of emitting sphere sp from p, when p lies outside it by the margin. */
static int sphere_cone(const sphere_shape *sp, vec3 p, light_cone *k) {
  vec3 d = v3_sub(sp->c, p);
  float d2 = v3_len2(d), rr = sp->r * (1 + LIGHT_SPHERE_MARGIN);
  if (!(d2 > rr * rr) || !isfinite(d2)) return 0;
  float sin2 = sp->r * sp->r / d2, cos_max = sqrtf(fmaxf(0.0f, 1 - sin2));
  k->sp = sp;
  k->axis = v3_scale(d, 1 / sqrtf(d2));
  k->one_minus_cos = sin2 / (1 + cos_max); /* without cancellation for a small, far sphere */
  k->pdf = 1 / (2 * PI_F * k->one_minus_cos);
  return isfinite(k->pdf) && k->pdf > 0;
}

int light_sphere_at(const light_sampler *ls, const scene *s, uint32_t li, vec3 p, light_cone *k) {
  if (!ls->sphere_cones || !ls->unit0 || li >= s->nlights) return 0;
  const light *l = &s->lights[ls->unit0[ls->unit_of[li]]]; /* its unit's first: a sphere's lights share type and sphere */
  if (l->type != LIGHT_AREA || !l->sphere) return 0;
  return sphere_cone(&s->spheres[l->sphere - 1], p, k);
}

uint32_t light_select_cone(const light_sampler *ls, const scene *s, vec3 p, float u, float *pmf, light_cone *k) {
  k->sp = NULL;
  if (!ls->unit0 || !ls->sphere_cones) return light_select(ls, s, p, u, pmf);
  if (ls->table.n == 0) return UINT32_MAX;
  float keep;
  uint32_t li = infinite_pick(ls, &u, pmf, &keep);
  if (li != UINT32_MAX || !(keep > 0)) return li;
  light_site at = light_locate(ls, p);
  float pu, rest;
  uint32_t un = unit_select(ls, &at, u, &pu, &rest), l0 = ls->unit0[un];
  pu *= keep;
  if (light_sphere_at(ls, s, l0, p, k)) { *pmf = pu; return l0; }
  k->sp = NULL;
  return unit_light(ls, un, pu, rest, pmf);
}

vec3 light_cone_sample(const light_cone *k, float u1, float u2) {
  float omc = u1 * k->one_minus_cos, c = 1 - omc, sn = sqrtf(fmaxf(0.0f, omc * (2 - omc))), phi = 2 * PI_F * u2;
  frame f = frame_from_n(k->axis);
  return v3_norm(frame_to_world(&f, v3(sn * cosf(phi), sn * sinf(phi), c)));
}
