/* splat.c — see splat.h. A hash grid answers the minimum-distance test; each triangle's
 * candidate points depend on geometry alone, so they are made in parallel over chunks of
 * triangles, then kept or skipped in triangle order by one thread. */
#include "scene/splat.h"
#include "core/threadpool.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- splatting with a hash grid for the minimum-distance test ---- */
/* Cells of side `cell`: a dense array over the scene's bounds when it has at most
 * DENSE_MAX cells (no hashing: the common case), else a hash table. */
#define DENSE_MAX (1 << 24)
typedef struct grid {
  uint64_t *key; int32_t *head;  /* hash mode, open addressing: cell key -> first point */
  int32_t *next;                 /* per point: next in its cell */
  uint32_t cap, used;
  float cell;
  int32_t *dense;                /* dense mode: nx*ny*nz heads, or NULL */
  int64_t x0, y0, z0, nx, ny, nz;
} grid;

static uint64_t cell_key(int64_t x, int64_t y, int64_t z) {
  return ((uint64_t)(x & 0x1fffff) << 42) | ((uint64_t)(y & 0x1fffff) << 21) | (uint64_t)(z & 0x1fffff);
}
static uint32_t slot_of(const grid *g, uint64_t k) {
  uint32_t h = (uint32_t)((k * 0x9e3779b97f4a7c15ULL) >> 32) & (g->cap - 1);
  while (g->head[h] >= 0 && g->key[h] != k) h = (h + 1) & (g->cap - 1);
  return h;
}
static int grid_grow(grid *g) {
  grid ng = *g;
  ng.cap = g->cap ? g->cap * 2 : 1024;
  ng.key = malloc(ng.cap * sizeof *ng.key);
  ng.head = malloc(ng.cap * sizeof *ng.head);
  if (!ng.key || !ng.head) { free(ng.key); free(ng.head); return -1; }
  for (uint32_t i = 0; i < ng.cap; i++) ng.head[i] = -1;
  for (uint32_t i = 0; i < g->cap; i++)
    if (g->head[i] >= 0) {
      uint32_t h = slot_of(&ng, g->key[i]);
      ng.key[h] = g->key[i];
      ng.head[h] = g->head[i];
    }
  free(g->key); free(g->head);
  g->key = ng.key; g->head = ng.head; g->cap = ng.cap;
  return 0;
}

typedef struct splat_ctx { splat_points *sp; grid g; uint32_t max_points; int oom; uint32_t group; uint32_t *pgroup; } splat_ctx;

/* The first point of cell (x, y, z), or -1. */
static int32_t cell_first(const grid *g, int64_t x, int64_t y, int64_t z) {
  if (g->dense) {
    x -= g->x0; y -= g->y0; z -= g->z0;
    if (x < 0 || y < 0 || z < 0 || x >= g->nx || y >= g->ny || z >= g->nz) return -1;
    return g->dense[(size_t)((z * g->ny + y) * g->nx + x)];
  }
  return g->head[slot_of(g, cell_key(x, y, z))];
}

static int cell_has_close(const splat_ctx *c, int64_t x, int64_t y, int64_t z, vec3 p, float d2) {
  const grid *g = &c->g;
  for (int32_t i = cell_first(g, x, y, z); i >= 0; i = g->next[i])
    if (v3_len2(v3_sub(c->sp->p[i], p)) < d2) return 1;
  return 0;
}

static int too_close(const splat_ctx *c, vec3 p, float dmin) {
  const grid *g = &c->g;
  int64_t r = (int64_t)ceilf(dmin / g->cell);
  int64_t cx = (int64_t)floorf(p.x / g->cell), cy = (int64_t)floorf(p.y / g->cell), cz = (int64_t)floorf(p.z / g->cell);
  float d2 = dmin * dmin;
  /* the point's own cell first: on finely tessellated meshes most candidates are
   * rejected there */
  if (cell_has_close(c, cx, cy, cz, p, d2)) return 1;
  for (int64_t x = cx - r; x <= cx + r; x++)
    for (int64_t y = cy - r; y <= cy + r; y++)
      for (int64_t z = cz - r; z <= cz + r; z++)
        if ((x != cx || y != cy || z != cz) && cell_has_close(c, x, y, z, p, d2)) return 1;
  return 0;
}

static void place(splat_ctx *c, vec3 p, vec3 n, float d) {
  if (c->oom || !v3_finite(p) || too_close(c, p, 0.5f * d)) return;
  splat_points *sp = c->sp;
  if (sp->n_pts >= c->max_points) { c->oom = 1; return; }
  if (sp->n_pts == sp->cap) {
    uint32_t cap = sp->cap ? sp->cap * 2 : 4096;
    vec3 *np = realloc(sp->p, cap * sizeof *np);
    if (np) sp->p = np;
    vec3 *nn = realloc(sp->n, cap * sizeof *nn);
    if (nn) sp->n = nn;
    float *na = realloc(sp->area, cap * sizeof *na);
    if (na) sp->area = na;
    float *ns = realloc(sp->spacing, cap * sizeof *ns);
    if (ns) sp->spacing = ns;
    uint32_t *pg = realloc(c->pgroup, cap * sizeof *pg);
    if (pg) c->pgroup = pg;
    int32_t *nx = realloc(c->g.next, cap * sizeof *nx);
    if (nx) c->g.next = nx;
    if (!np || !nn || !na || !nx || !ns || !pg) { c->oom = 1; return; }
    sp->cap = cap;
  }
  grid *g = &c->g;
  int64_t x = (int64_t)floorf(p.x / g->cell), y = (int64_t)floorf(p.y / g->cell), z = (int64_t)floorf(p.z / g->cell);
  int32_t *head;
  if (g->dense) {
    x -= g->x0; y -= g->y0; z -= g->z0;
    if (x < 0 || y < 0 || z < 0 || x >= g->nx || y >= g->ny || z >= g->nz) { c->oom = 1; return; } /* cannot happen: bounds */
    head = &g->dense[(size_t)((z * g->ny + y) * g->nx + x)];
  } else {
    if (2 * (g->used + 1) > g->cap && grid_grow(g)) { c->oom = 1; return; }
    uint64_t k = cell_key(x, y, z);
    uint32_t h = slot_of(g, k);
    if (g->head[h] < 0) { g->key[h] = k; g->used++; }
    head = &g->head[h];
  }
  uint32_t i = sp->n_pts++;
  sp->p[i] = p; sp->n[i] = n; sp->spacing[i] = d; sp->area[i] = 0;
  c->pgroup[i] = c->group;
  g->next[i] = *head;
  *head = (int32_t)i;
}

/* Splatting runs in two phases so that it can use every thread and still place the
 * very points of the sequential algorithm: (A) in parallel over chunks of triangles,
 * each triangle's candidate points in the order the algorithm visits them — the
 * vertices it is the first (non-degenerate) triangle to use, then the midpoints of the
 * recursive split and the centroids that pass the corner rule, all decided by geometry
 * alone; (B) one thread takes the candidates in triangle order and keeps those no
 * closer than d/2 to a point already kept. */
typedef struct cand { vec3 p, n; float d; uint32_t group; } cand;
typedef struct cand_buf { cand *c; uint32_t n, cap; int oom; float max_ratio; } cand_buf;

static void emit(cand_buf *cb, vec3 p, vec3 n, float d, uint32_t group) {
  if (cb->oom) return;
  if (cb->n == cb->cap) {
    uint32_t cap = cb->cap ? 2 * cb->cap : 1024;
    cand *nc = realloc(cb->c, cap * sizeof *nc);
    if (!nc) { cb->oom = 1; return; }
    cb->c = nc;
    cb->cap = cap;
  }
  cand k = {p, n, d, group};
  cb->c[cb->n++] = k;
}

/* Splits at the midpoint of the longest edge while it is longer than 2d; the centroid of
 * each final triangle, unless it is too close to a corner (the seed's rule; it settles
 * every triangle finer than the spacing without a grid lookup). */
static void split(cand_buf *cb, vec3 a, vec3 b, vec3 t, vec3 n, float d, uint32_t group, int depth) {
  float lab = v3_len2(v3_sub(b, a)), lbt = v3_len2(v3_sub(t, b)), lta = v3_len2(v3_sub(a, t));
  /* rotate so that (a, b) is the longest edge */
  if (lbt >= lab && lbt >= lta) { vec3 x = a; a = b; b = t; t = x; lab = lbt; }
  else if (lta >= lab && lta >= lbt) { vec3 x = t; t = b; b = a; a = x; lab = lta; }
  if (lab > 4 * d * d && depth < 60 && !cb->oom) {
    vec3 m = v3_scale(v3_add(a, b), 0.5f);
    emit(cb, m, n, d, group);
    split(cb, a, m, t, n, d, group, depth + 1);
    split(cb, m, b, t, n, d, group, depth + 1);
    return;
  }
  float ratio = sqrtf(lab) / (2 * d);
  if (ratio > cb->max_ratio) cb->max_ratio = ratio;
  vec3 g = v3_scale(v3_add(v3_add(a, b), t), 1.0f / 3.0f);
  float q = 0.25f * d * d;
  if (v3_len2(v3_sub(g, a)) < q || v3_len2(v3_sub(g, b)) < q || v3_len2(v3_sub(g, t)) < q) return;
  emit(cb, g, n, d, group);
}

#define SPLAT_CHUNK 4096
typedef struct splat_job {
  const scene *s;
  float default_spacing;
  const uint32_t *owner;   /* per vertex: the first non-degenerate triangle using it */
  const uint8_t *degenerate;
  cand_buf *bufs;
} splat_job;

static void splat_chunk(void *user, int64_t item, int thread) {
  (void)thread;
  splat_job *j = user;
  const scene *s = j->s;
  cand_buf *cb = &j->bufs[item];
  uint32_t t0 = (uint32_t)item * SPLAT_CHUNK, t1 = t0 + SPLAT_CHUNK < s->ntris ? t0 + SPLAT_CHUNK : s->ntris;
  for (uint32_t t = t0; t < t1; t++) {
    if (j->degenerate[t]) continue;
    const shape_ao *sa = scene_shape_ao(s, t);
    uint32_t group = sa ? (uint32_t)(sa - s->shape_ao) : s->nshape_ao;
    float d = sa && sa->spacing > 0 ? sa->spacing : j->default_spacing;
    const uint32_t *ix = &s->idx[3 * t];
    vec3 n = v3_norm(scene_tri_ng(s, t));
    for (int k = 0; k < 3; k++)
      if (j->owner[ix[k]] == t) emit(cb, s->pos[ix[k]], n, d, group);
    split(cb, s->pos[ix[0]], s->pos[ix[1]], s->pos[ix[2]], n, d, group, 0);
  }
}

int splat_scene(const scene *s, float default_spacing, uint32_t max_points, int threads, splat_points *out) {
  memset(out, 0, sizeof *out);
  splat_ctx c;
  memset(&c, 0, sizeof c);
  c.sp = out;
  c.max_points = max_points;
  float dmin = default_spacing;
  for (uint32_t i = 0; i < s->nshape_ao; i++)
    if (s->shape_ao[i].spacing > 0 && s->shape_ao[i].spacing < dmin) dmin = s->shape_ao[i].spacing;
  c.g.cell = 0.5f * dmin;
  int64_t nchunks = ((int64_t)s->ntris + SPLAT_CHUNK - 1) / SPLAT_CHUNK;
  uint32_t *owner = malloc((s->nverts ? s->nverts : 1) * sizeof *owner);
  uint8_t *degenerate = malloc(s->ntris ? s->ntris : 1);
  /* group g < nshape_ao: that shape; nshape_ao: every triangle without settings */
  double *garea = calloc(s->nshape_ao + 1, sizeof *garea);
  uint32_t *gcount = calloc(s->nshape_ao + 1, sizeof *gcount);
  cand_buf *bufs = calloc((size_t)(nchunks ? nchunks : 1), sizeof *bufs);
  /* dense cells over the bounds (one cell of margin), when few enough */
  if (c.g.cell > 0 && s->ntris) {
    grid *g = &c.g;
    g->x0 = (int64_t)floorf(s->bounds.lo.x / g->cell) - 1; g->nx = (int64_t)floorf(s->bounds.hi.x / g->cell) + 2 - g->x0;
    g->y0 = (int64_t)floorf(s->bounds.lo.y / g->cell) - 1; g->ny = (int64_t)floorf(s->bounds.hi.y / g->cell) + 2 - g->y0;
    g->z0 = (int64_t)floorf(s->bounds.lo.z / g->cell) - 1; g->nz = (int64_t)floorf(s->bounds.hi.z / g->cell) + 2 - g->z0;
    double cells = (double)g->nx * (double)g->ny * (double)g->nz;
    if (cells > 0 && cells <= DENSE_MAX) {
      g->dense = malloc((size_t)cells * sizeof *g->dense);
      if (g->dense) memset(g->dense, 0xff, (size_t)cells * sizeof *g->dense); /* all -1 */
    }
  }
  int fail = !owner || !degenerate || !garea || !gcount || !bufs || !(c.g.cell > 0) || (!c.g.dense && grid_grow(&c.g));
  if (!fail) {
    for (uint32_t v = 0; v < s->nverts; v++) owner[v] = UINT32_MAX;
    for (uint32_t t = 0; t < s->ntris; t++) {
      const shape_ao *sa = scene_shape_ao(s, t);
      float l = v3_len(scene_tri_ng(s, t));
      garea[sa ? (uint32_t)(sa - s->shape_ao) : s->nshape_ao] += 0.5 * (double)l;
      degenerate[t] = !(l > 0) || !isfinite(l);
      if (degenerate[t]) continue;
      for (int k = 0; k < 3; k++)
        if (owner[s->idx[3 * t + k]] == UINT32_MAX) owner[s->idx[3 * t + k]] = t;
    }
    splat_job j = {s, default_spacing, owner, degenerate, bufs};
    parallel_for(threads > 0 ? threads : 1, nchunks, splat_chunk, &j);
    for (int64_t k = 0; k < nchunks && !c.oom; k++) {
      if (bufs[k].oom) { c.oom = 1; break; }
      if (bufs[k].max_ratio > out->max_edge_ratio) out->max_edge_ratio = bufs[k].max_ratio;
      for (uint32_t i = 0; i < bufs[k].n && !c.oom; i++) {
        c.group = bufs[k].c[i].group;
        place(&c, bufs[k].c[i].p, bufs[k].c[i].n, bufs[k].c[i].d);
      }
    }
    if (!c.oom) {
      /* each point's share of its group's surface */
      for (uint32_t i = 0; i < out->n_pts; i++) gcount[c.pgroup[i]]++;
      for (uint32_t i = 0; i < out->n_pts; i++) out->area[i] = (float)(garea[c.pgroup[i]] / gcount[c.pgroup[i]]);
    }
  }
  for (int64_t k = 0; bufs && k < nchunks; k++) free(bufs[k].c);
  free(bufs); free(owner); free(degenerate);
  free(c.g.key); free(c.g.head); free(c.g.next); free(c.g.dense); free(garea); free(gcount); free(c.pgroup);
  if (fail || c.oom) { splat_free(out); return -1; }
  return 0;
}

void splat_free(splat_points *sp) {
  free(sp->p); free(sp->n); free(sp->area); free(sp->spacing);
  memset(sp, 0, sizeof *sp);
}

