/* checkpoint.c — see checkpoint.h. The file: the magic "VALOCKP1"; valo's version; the
 * scene's path and hash; the options text (one "name=value" line per option that changes
 * the image, the integrator's resolved parameters included); the film's size and arrays;
 * the pass state; the counters; then its own length and a checksum of all before them.
 * Numbers are written in this machine's byte order (a checkpoint moves between runs,
 * not machines). */
#include "render/checkpoint.h"
#include "core/atomicfile.h"
#include "core/error.h"
#include "core/memlimit.h"
#include "core/options.h"
#include "core/clock.h"
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define CKPT_MAGIC "VALOCKP1"
#define OPTS_CAP 65536 /* the options text, at most */

static uint64_t fnv(uint64_t h, const void *p, size_t n) {
  const unsigned char *b = p;
  for (size_t i = 0; i < n; i++) { h ^= b[i]; h *= 0x100000001b3ULL; }
  return h;
}
#define FNV0 0xcbf29ce484222325ULL

/* The scene's identity: geometry, material assignment and the materials' values. */
static uint64_t scene_hash(const scene *s) {
  uint64_t h = FNV0;
  h = fnv(h, &s->nverts, sizeof s->nverts);
  h = fnv(h, &s->ntris, sizeof s->ntris);
  h = fnv(h, s->pos, (size_t)s->nverts * sizeof *s->pos);
  h = fnv(h, s->idx, (size_t)s->ntris * 3 * sizeof *s->idx);
  if (s->tri_mat) h = fnv(h, s->tri_mat, (size_t)s->ntris * sizeof *s->tri_mat);
  for (uint32_t m = 0; m < s->nmats; m++) {
    const material *mt = &s->mats[m];
    float v[14] = {mt->kd.r, mt->kd.g, mt->kd.b, mt->ks.r, mt->ks.g, mt->ks.b, mt->emission.r, mt->emission.g, mt->emission.b,
                   mt->exponent, mt->ior, mt->roughness, mt->metallic, (float)mt->type};
    h = fnv(h, v, sizeof v);
    h = fnv(h, mt->name, strnlen(mt->name, sizeof mt->name));
    if (mt->vertex_colors) h = fnv(h, "vertex colours", 14);
  }
  if (s->col) h = fnv(h, s->col, (size_t)s->nverts * 3 * sizeof *s->col);
  h = fnv(h, &s->nlights, sizeof s->nlights);
  return h;
}

/* Every option that changes the image, one "name=value" line each, then the integrator's
 * resolved parameters. Left out: --threads (the image does not depend on it), --time
 * (a budget of each run), --frames (refused with checkpoints). */
static void options_text(const session *ss, char *out, size_t cap) {
  size_t n = 0;
  const valo_options *o = &ss->opt;
  for (const option_decl *d = option_table; d->info.flag || d->info.json; d++) {
    if (d->target != OPT_RENDER || d->offset == offsetof(valo_options, threads) || d->offset == offsetof(valo_options, time_budget) ||
        d->offset == offsetof(valo_options, frames) || d->type == OPT_PARAMS)
      continue;
    const char *f = (const char *)o + d->offset;
    char v[512];
    switch (d->type) {
    case OPT_INT: case OPT_CHOICE: case OPT_FLAG: snprintf(v, sizeof v, "%d", *(const int *)f); break;
    case OPT_INT64: snprintf(v, sizeof v, "%lld", (long long)*(const int64_t *)f); break;
    case OPT_REAL: snprintf(v, sizeof v, "%.17g", *(const double *)f); break;
    case OPT_FLOAT: snprintf(v, sizeof v, "%.9g", (double)*(const float *)f); break;
    case OPT_SIZE: snprintf(v, sizeof v, "%dx%d", ((const int *)f)[0], ((const int *)f)[1]); break;
    case OPT_RECT: snprintf(v, sizeof v, "%d,%d,%d,%d", ((const int *)f)[0], ((const int *)f)[1], ((const int *)f)[2], ((const int *)f)[3]); break;
    case OPT_NAME: case OPT_PARAMS: snprintf(v, sizeof v, "%.*s", (int)d->size, f); break;
    }
    int k = snprintf(out + n, cap - n, "%s %s\n", d->info.flag ? d->info.flag : d->info.json, v);
    n = k < 0 || n + (size_t)k >= cap ? cap - 1 : n + (size_t)k;
  }
  for (int i = 0; ss->integ->params && ss->integ->params[i].name; i++) {
    int k = snprintf(out + n, cap - n, "--param %s.%s=%.17g\n", ss->integ->name, ss->integ->params[i].name, ss->param[i]);
    n = k < 0 || n + (size_t)k >= cap ? cap - 1 : n + (size_t)k;
  }
}

/* ---- writing ---- */
typedef struct wbuf { FILE *f; uint64_t h, len; int bad; } wbuf;
static void put(wbuf *w, const void *p, size_t n) {
  if (!n) return;
  if (fwrite(p, 1, n, w->f) != n) w->bad = 1;
  w->h = fnv(w->h, p, n);
  w->len += n;
}
static void put_u32(wbuf *w, uint32_t v) { put(w, &v, sizeof v); }
static void put_str(wbuf *w, const char *s) { uint32_t n = (uint32_t)strlen(s); put_u32(w, n); put(w, s, n); }

valo_status checkpoint_write(const session *ss, const thread_stats *ts, const char *path, valo_error *err) {
  char tmp[4200];
  if (atomic_temp_name(path, tmp, sizeof tmp)) return err_set(err, VALO_ERR_INVALID, "%s: name too long", path);
  char *opts = malloc(OPTS_CAP);
  if (!opts) return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", path);
  options_text(ss, opts, OPTS_CAP);
  FILE *f = fopen(tmp, "wb");
  if (!f) { free(opts); return err_set(err, VALO_ERR_IO, "%s: cannot write the checkpoint: %s", path, strerror(errno)); }
  wbuf w = {f, FNV0, 0, 0};
  const film *fm = &ss->film;
  size_t np = film_pixels(fm);
  put(&w, CKPT_MAGIC, 8);
  put_str(&w, VALO_VERSION_STRING);
  put_str(&w, ss->s->path);
  uint64_t sh = scene_hash(ss->s);
  put(&w, &sh, sizeof sh);
  put_str(&w, opts);
  free(opts);
  put_u32(&w, (uint32_t)fm->width);
  put_u32(&w, (uint32_t)fm->height);
  int32_t st[6] = {ss->spp_done, ss->ckpt_state.phase, ss->ckpt_state.stage, ss->ckpt_state.stages, ss->image_frames,
                   (fm->sq ? 1 : 0) | (fm->aov ? 2 : 0) | (fm->wsum ? 4 : 0)};
  put(&w, st, sizeof st);
  put(&w, &ss->ckpt_state.taken, sizeof(double));
  put(&w, fm->sum, np * 3 * sizeof *fm->sum);
  put(&w, fm->count, np * sizeof *fm->count);
  if (fm->sq) put(&w, fm->sq, np * 4 * sizeof *fm->sq);
  if (fm->aov) put(&w, fm->aov, np * AOV_FLOATS * sizeof *fm->aov);
  if (fm->wsum) put(&w, fm->wsum, np * sizeof *fm->wsum);
  if (ss->ckpt_state.phase == CKPT_ADAPT_ERROR) {
    put(&w, ss->ckpt_state.first, np * sizeof(uint32_t));
    put(&w, ss->ckpt_state.fin, np * sizeof(uint32_t));
  }
  thread_stats sum = ss->total;
  thread_stats_add(&sum, &ss->prep);
  for (int t = 0; t < ss->opt.threads; t++) thread_stats_add(&sum, &ts[t]);
  uint64_t c[2 + VALO_LOSS_COUNT] = {sum.rays, sum.surface_samples};
  memcpy(c + 2, sum.lost, sizeof sum.lost);
  put(&w, c, sizeof c);
  double secs = ss->render_seconds + ss->ckpt_run_seconds;
  put(&w, &secs, sizeof secs);
  uint64_t tail[2] = {w.len, w.h};
  if (fwrite(tail, 1, sizeof tail, f) != sizeof tail) w.bad = 1;
  if (fclose(f)) w.bad = 1;
  if (w.bad) {
    int e = errno;
    remove(tmp);
    return err_set(err, VALO_ERR_IO, "%s: cannot write the checkpoint: %s", path, strerror(e));
  }
  if (atomic_commit(tmp, path)) return err_set(err, VALO_ERR_IO, "%s: cannot write the checkpoint: %s", path, strerror(errno));
  return VALO_OK;
}

/* ---- reading ---- */
typedef struct rbuf { const unsigned char *p; size_t n, at; int bad; } rbuf;
static void get(rbuf *r, void *out, size_t n) {
  if (r->bad || n > r->n - r->at) { r->bad = 1; memset(out, 0, n); return; }
  memcpy(out, r->p + r->at, n);
  r->at += n;
}
static uint32_t get_u32(rbuf *r) { uint32_t v; get(r, &v, sizeof v); return v; }
/* A string (at most cap - 1 bytes) into out. */
static void get_str(rbuf *r, char *out, size_t cap) {
  uint32_t n = get_u32(r);
  if (r->bad || n >= cap || n > r->n - r->at) { r->bad = 1; out[0] = 0; return; }
  memcpy(out, r->p + r->at, n);
  out[n] = 0;
  r->at += n;
}

/* The first line where a and b differ, as "name: A here, B there". */
static void first_difference(const char *a, const char *b, char *out, size_t cap) {
  while (*a || *b) {
    size_t la = strcspn(a, "\n"), lb = strcspn(b, "\n");
    if (la != lb || memcmp(a, b, la)) {
      snprintf(out, cap, "it was made with %.*s; this render has %.*s", (int)la, a, (int)lb, b);
      return;
    }
    a += la + (a[la] ? 1 : 0);
    b += lb + (b[lb] ? 1 : 0);
  }
  snprintf(out, cap, "its options differ");
}

valo_status checkpoint_read(session *ss, const char *path, valo_error *err) {
  FILE *f = fopen(path, "rb");
  if (!f) return err_set(err, VALO_ERR_IO, "%s: cannot open the checkpoint: %s", path, strerror(errno));
  struct stat sb;
  if (fstat(fileno(f), &sb) || sb.st_size < 0) { fclose(f); return err_set(err, VALO_ERR_IO, "%s: cannot read the checkpoint", path); }
  size_t n = (size_t)sb.st_size;
  valo_status mst = mem_check(n, path, "a checkpoint", err);
  if (mst) { fclose(f); return mst; }
  unsigned char *data = malloc(n ? n : 1);
  if (!data) { fclose(f); return err_set(err, VALO_ERR_NOMEM, "%s: out of memory", path); }
  size_t got = fread(data, 1, n, f);
  fclose(f);
  valo_status st = VALO_OK;
  char *opts = NULL, *mine = NULL; /* the options texts, stored and this render's */
  if (got != n) { st = err_set(err, VALO_ERR_IO, "%s: cannot read the checkpoint", path); goto done; }
  if (n < 8 + 16 || memcmp(data, CKPT_MAGIC, 8)) {
    st = err_set(err, VALO_ERR_PARSE, "%s: not a valo checkpoint%s", path, n >= 8 && !memcmp(data, "VALOCKP", 7) ? " of this format" : "");
    goto done;
  }
  uint64_t tail[2];
  memcpy(tail, data + n - 16, 16);
  if (tail[0] != n - 16) {
    st = err_set(err, VALO_ERR_PARSE, "%s: the checkpoint is truncated or damaged (its %zu bytes do not end with their own length): refused",
                 path, n);
    goto done;
  }
  if (fnv(FNV0, data, n - 16) != tail[1]) {
    st = err_set(err, VALO_ERR_PARSE, "%s: the checkpoint is corrupted (its checksum does not match its contents): refused", path);
    goto done;
  }
  rbuf r = {data, n - 16, 8, 0};
  char ver[64], spath[1100];
  opts = malloc(OPTS_CAP);
  mine = malloc(OPTS_CAP);
  if (!opts || !mine) { st = err_set(err, VALO_ERR_NOMEM, "%s: out of memory", path); goto done; }
  get_str(&r, ver, sizeof ver);
  if (!r.bad && strcmp(ver, VALO_VERSION_STRING)) {
    st = err_set(err, VALO_ERR_INVALID, "%s: the checkpoint was made by valo %s; this is valo %s: refused", path, ver, VALO_VERSION_STRING);
    goto done;
  }
  get_str(&r, spath, sizeof spath);
  uint64_t sh = 0;
  get(&r, &sh, sizeof sh);
  if (!r.bad && sh != scene_hash(ss->s)) {
    st = err_set(err, VALO_ERR_INVALID, "%s: the checkpoint is of another scene (%s%s): refused", path, spath,
                 strcmp(spath, ss->s->path) ? "" : ", which has changed since");
    goto done;
  }
  get_str(&r, opts, OPTS_CAP);
  options_text(ss, mine, OPTS_CAP);
  if (!r.bad && strcmp(opts, mine)) {
    char why[600];
    first_difference(opts, mine, why, sizeof why);
    st = err_set(err, VALO_ERR_INVALID, "%s: the checkpoint was made with other options (%s): refused", path, why);
    goto done;
  }
  film *fm = &ss->film;
  size_t np = film_pixels(fm);
  uint32_t w = get_u32(&r), h = get_u32(&r);
  int32_t s6[6];
  get(&r, s6, sizeof s6);
  double taken = 0;
  get(&r, &taken, sizeof taken);
  if (!r.bad && (w != (uint32_t)fm->width || h != (uint32_t)fm->height || s6[5] != ((fm->sq ? 1 : 0) | (fm->aov ? 2 : 0) | (fm->wsum ? 4 : 0)) ||
                 s6[0] < 0 || s6[1] < 0 || s6[1] > CKPT_ADAPT_DIGEST)) {
    st = err_set(err, VALO_ERR_PARSE, "%s: the checkpoint's film does not match this render: refused", path);
    goto done;
  }
  get(&r, fm->sum, np * 3 * sizeof *fm->sum);
  get(&r, fm->count, np * sizeof *fm->count);
  if (fm->sq) get(&r, fm->sq, np * 4 * sizeof *fm->sq);
  if (fm->aov) get(&r, fm->aov, np * AOV_FLOATS * sizeof *fm->aov);
  if (fm->wsum) get(&r, fm->wsum, np * sizeof *fm->wsum);
  ckpt_state cs = {s6[1], s6[2], s6[3], taken, NULL, NULL};
  if (cs.phase == CKPT_ADAPT_ERROR) {
    cs.first = malloc(np * sizeof(uint32_t));
    cs.fin = malloc(np * sizeof(uint32_t));
    if (!cs.first || !cs.fin) { free(cs.first); free(cs.fin); st = err_set(err, VALO_ERR_NOMEM, "%s: out of memory", path); goto done; }
    get(&r, cs.first, np * sizeof(uint32_t));
    get(&r, cs.fin, np * sizeof(uint32_t));
  }
  uint64_t c[2 + VALO_LOSS_COUNT];
  get(&r, c, sizeof c);
  double secs = 0;
  get(&r, &secs, sizeof secs);
  if (r.bad || r.at != r.n) {
    free(cs.first); free(cs.fin);
    film_clear(fm);
    st = err_set(err, VALO_ERR_PARSE, "%s: the checkpoint's contents do not match its header: refused", path);
    goto done;
  }
  ss->spp_done = s6[0];
  ss->image_frames = s6[4];
  ss->resume = cs;
  ss->resumed = 1;
  memset(&ss->total, 0, sizeof ss->total);
  ss->total.rays = c[0];
  ss->total.surface_samples = c[1];
  memcpy(ss->total.lost, c + 2, sizeof ss->total.lost);
  ss->render_seconds = secs;
done:
  free(opts);
  free(mine);
  free(data);
  return st;
}

void checkpoint_tick(session *ss, const thread_stats *ts, double run_t0) {
  if (!ss->ckpt_path[0]) return;
  double now = now_seconds();
  if (ss->ckpt_every > 0 && now - ss->ckpt_last < ss->ckpt_every) return;
  ss->ckpt_run_seconds = now - run_t0;
  valo_error e;
  if (checkpoint_write(ss, ts, ss->ckpt_path, &e)) log_warning("%s (the render goes on)", e.message);
  ss->ckpt_last = now_seconds();
}
