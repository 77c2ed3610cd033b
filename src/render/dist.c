/* dist.c — see dist.h. The protocol, one MPI tag, every message a byte buffer that
 * starts with int32 words:
 *   worker -> 0: HELLO {threads}; RESULT {first tile, tiles} + the tiles' pixel states;
 *                ERROR {status} + message; STATS (after STOP) {rank_stats, thread_stats}
 *   0 -> worker: WORK {frame, prep, s0, s1, has_target, first tile, tiles} + per pixel
 *                [target] + state; STOP
 * A pixel's state is its count, its three sums and, when the film has them, its four sums
 * of squares and its AOV sums: everything a sample adds to. A worker's HELLO and each
 * of its results are answered with its next batch while the pass has tiles; at the next
 * pass rank 0 supplies it again, at the end it sends STOP. On rank 0 one thread talks to the other ranks while
 * its render threads take tiles from the same counter; only that thread calls MPI during
 * a pass (MPI_THREAD_SERIALIZED). Waiting is by MPI_Iprobe and sleeps that grow to 0.2 ms,
 * so an idle rank leaves its cores to the rank beside it. */
#include "render/dist.h"
#include "render/tiles.h"
#include "core/error.h"

#ifdef VALO_HAVE_MPI
#include "core/clock.h"
#include "core/threadpool.h"
#include <mpi.h>
#include <pthread.h>
#include <stdio.h>
#include <sys/resource.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { TAG = 7, MSG_HELLO = 1, MSG_RESULT, MSG_ERROR, MSG_STATS, MSG_WORK, MSG_STOP };
/* Batches a worker holds at once. One: rank 0 sends work only to a worker that waits in
 * MPI_Iprobe, and a worker sends its result only while rank 0's talking thread polls, so
 * no blocking send can wait on a rank that is itself blocked sending (with two, a large
 * batch to a rendering worker and its large result would each wait for the other). */
enum { IN_FLIGHT = 1 };
static int g_rank, g_size = 1, g_inited;

int dist_built(void) { return 1; }
int dist_rank(void) { return g_rank; }
int dist_size(void) { return g_size; }

int dist_init(int *argc, char ***argv) {
  const char *vars[] = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", NULL};
  int launched = 0;
  for (int i = 0; vars[i]; i++) launched |= getenv(vars[i]) != NULL;
  if (!launched || g_inited) return g_size;
  int prov = 0;
  if (MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &prov) != MPI_SUCCESS) return 1;
  g_inited = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  if (prov < MPI_THREAD_SERIALIZED && g_size > 1) {
    log_warning("this MPI library cannot be called from a second thread: rendering on rank 0 only");
    g_size = 1;
  }
  return g_size;
}

void dist_finalize(void) {
  if (g_inited) MPI_Finalize();
  g_inited = 0;
}

static uint64_t peak_memory(void) {
  struct rusage ru;
  return getrusage(RUSAGE_SELF, &ru) ? 0 : (uint64_t)ru.ru_maxrss * 1024u;
}

/* Sleeps while waiting for a message: 10 us first, twice as long each time up to cap_ns
 * (100 us on rank 0, which answers; 200 us on the others)
 * (a rank that waits long costs its cores almost nothing; a busy one answers at once). */
static void nap(int *idle, long cap_ns) {
  long ns = 10000L << (*idle < 7 ? *idle : 7);
  struct timespec d = {0, ns < cap_ns ? ns : cap_ns};
  nanosleep(&d, NULL);
  (*idle)++;
}

int dist_agree(int rc, valo_error *err) {
  if (g_size <= 1) return rc;
  int mine = rc ? g_rank : g_size, first = g_size;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == g_size) return 0;
  struct { int rc; char host[64]; char msg[sizeof err->message]; } m;
  memset(&m, 0, sizeof m);
  if (first == g_rank) {
    m.rc = rc;
    int len = 0;
    MPI_Get_processor_name(m.host, &len);
    snprintf(m.msg, sizeof m.msg, "%s", err->message);
  }
  MPI_Bcast(&m, (int)sizeof m, MPI_BYTE, first, MPI_COMM_WORLD);
  if (first != g_rank) snprintf(err->message, sizeof err->message, "rank %d (%s): %s", first, m.host, m.msg);
  return m.rc;
}

/* ---- pixel states ---- */
static size_t px_bytes(const film *f) { return 4 + 24 + (f->sq ? 32 : 0) + (f->aov ? AOV_FLOATS * 4 : 0); }
static size_t tile_pixels(const session *ss, int64_t t) {
  int x0, y0, x1, y1;
  tiles_rect(ss, t, &x0, &y0, &x1, &y1);
  return (size_t)(x1 - x0) * (size_t)(y1 - y0);
}
/* Copies the states of tiles [t0, t0+n) out of (to_film 0) or into (1) the film at p,
 * each pixel's target first when target is not NULL; returns the end of the bytes. */
static unsigned char *tile_states(session *ss, int64_t t0, int n, uint32_t *target, int to_film, unsigned char *p) {
  film *f = &ss->film;
#define MOVE(ptr, bytes) (to_film ? memcpy((ptr), p, (bytes)) : memcpy(p, (ptr), (bytes)), p += (bytes))
  for (int64_t t = t0; t < t0 + n; t++) {
    int x0, y0, x1, y1;
    tiles_rect(ss, t, &x0, &y0, &x1, &y1);
    for (int y = y0; y < y1; y++)
      for (int x = x0; x < x1; x++) {
        size_t pix = (size_t)y * (size_t)f->width + (size_t)x;
        if (target) MOVE(&target[pix], 4);
        MOVE(&f->count[pix], 4);
        MOVE(&f->sum[3 * pix], 24);
        if (f->sq) MOVE(&f->sq[4 * pix], 32);
        if (f->aov) MOVE(&f->aov[AOV_FLOATS * pix], AOV_FLOATS * 4);
      }
  }
#undef MOVE
  return p;
}

typedef struct buf { unsigned char *p; size_t cap; } buf;
static int buf_fit(buf *b, size_t n) {
  if (n <= b->cap) return 0;
  unsigned char *q = realloc(b->p, n);
  if (!q) return -1;
  b->p = q;
  b->cap = n;
  return 0;
}
/* Waits (politely) for the next message from src (MPI_ANY_SOURCE: anyone) and receives
 * it into b; its sender into *from. -1 when out of memory. */
static int recv_msg(int src, buf *b, int *from) {
  MPI_Status st;
  for (int flag = 0, idle = 0; !flag;) {
    MPI_Iprobe(src, TAG, MPI_COMM_WORLD, &flag, &st);
    if (!flag) nap(&idle, 200000);
  }
  int n = 0;
  MPI_Get_count(&st, MPI_BYTE, &n);
  if (buf_fit(b, (size_t)n + 64)) return -1; /* headers are read whole, however short the message */
  MPI_Recv(b->p, n, MPI_BYTE, st.MPI_SOURCE, TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  *from = st.MPI_SOURCE;
  return 0;
}
static void send_words(int dst, const int32_t *w, int n) { MPI_Send(w, n * 4, MPI_BYTE, dst, TAG, MPI_COMM_WORLD); }

/* ---- rank 0 ---- */
typedef struct dist_state {
  unsigned char *heard; /* per rank: its HELLO came */
  int *held;            /* per rank: batches it holds (sent, result not back) */
  int *threads;         /* per rank, from its HELLO */
  rank_stats *rs;       /* per rank: its share so far (rank 0's tiles and samples) */
  buf in, out;
  valo_status err_status;
  char err_msg[sizeof ((valo_error *)0)->message];
} dist_state;

typedef struct pass_ctx {
  session *ss;
  dist_state *d;
  int s0, s1, prep;
  const uint32_t *target;
  int64_t ntiles;
  _Atomic int64_t next;    /* the next tile nobody has claimed */
  int outstanding;         /* batches out at other ranks (the talking thread's alone) */
  thread_stats *ts;
  _Atomic uint64_t local_tiles, local_samples;
} pass_ctx;

static int pass_over(pass_ctx *p) { return session_cancelled(p->ss) || p->d->err_status || atomic_load(&p->next) >= p->ntiles; }

/* Hands worker w its next batch: a share of what is left that keeps every rank busy to
 * the end (at most four tiles per thread of w); 0 when there is nothing to hand out. */
static int give(pass_ctx *p, int w) {
  dist_state *d = p->d;
  if (session_cancelled(p->ss) || d->err_status) return 0;
  int all = p->ss->opt.threads;
  for (int r = 1; r < dist_size(); r++) all += d->threads[r];
  int64_t left = p->ntiles - atomic_load(&p->next);
  int64_t want = left / (2 * (int64_t)all);
  if (want > 4 * (int64_t)d->threads[w]) want = 4 * (int64_t)d->threads[w];
  if (want < 1) want = 1;
  int64_t t0 = atomic_fetch_add(&p->next, want);
  if (t0 >= p->ntiles) return 0;
  int n = (int)(t0 + want <= p->ntiles ? want : p->ntiles - t0);
  size_t px = 0;
  for (int64_t t = t0; t < t0 + n; t++) px += tile_pixels(p->ss, t);
  size_t bytes = 32 + px * (px_bytes(&p->ss->film) + (p->target ? 4 : 0));
  if (buf_fit(&d->out, bytes)) {
    d->err_status = VALO_ERR_NOMEM;
    snprintf(d->err_msg, sizeof d->err_msg, "out of memory for a batch of %d tiles", n);
    return 0;
  }
  int32_t h[8] = {MSG_WORK, p->ss->view_frame, p->prep, p->s0, p->s1, p->target != NULL, (int32_t)t0, n};
  memcpy(d->out.p, h, sizeof h);
  unsigned char *end = tile_states(p->ss, t0, n, (uint32_t *)p->target, 0, d->out.p + sizeof h);
  MPI_Send(d->out.p, (int)(end - d->out.p), MPI_BYTE, w, TAG, MPI_COMM_WORLD);
  d->held[w]++;
  p->outstanding++;
  return 1;
}

/* Takes in one message from worker `from` (already in d->in). */
static void take_message(pass_ctx *p, int from) {
  dist_state *d = p->d;
  int32_t h[4];
  memcpy(h, d->in.p, sizeof h);
  if (h[0] == MSG_HELLO) {
    d->threads[from] = h[1] > 0 ? h[1] : 1;
    d->heard[from] = 1;
  } else if (h[0] == MSG_RESULT) {
    tile_states(p->ss, h[1], h[2], NULL, 1, d->in.p + sizeof h);
    p->outstanding--;
    d->held[from]--;
  } else if (h[0] == MSG_ERROR) {
    p->outstanding--;
    d->held[from]--;
    if (!d->err_status) {
      char host[64] = "";
      memcpy(host, d->in.p + sizeof h, sizeof host - 1);
      d->err_status = (valo_status)h[1];
      snprintf(d->err_msg, sizeof d->err_msg, "rank %d (%s): %s", from, host, (const char *)d->in.p + sizeof h + 64);
    }
  }
}

/* Tops worker w up to IN_FLIGHT batches while there is work. */
static void supply(pass_ctx *p, int w) {
  while (p->d->heard[w] && p->d->held[w] < IN_FLIGHT && give(p, w)) {}
}

static void *talk(void *arg) {
  pass_ctx *p = arg;
  dist_state *d = p->d;
  for (int w = 1; w < dist_size(); w++) supply(p, w);
  int idle = 0;
  while (p->outstanding > 0 || !pass_over(p)) {
    int flag = 0, from = 0;
    MPI_Status st;
    MPI_Iprobe(MPI_ANY_SOURCE, TAG, MPI_COMM_WORLD, &flag, &st);
    if (!flag) { nap(&idle, 100000); continue; }
    idle = 0;
    if (recv_msg(st.MPI_SOURCE, &d->in, &from)) {
      d->err_status = VALO_ERR_NOMEM;
      snprintf(d->err_msg, sizeof d->err_msg, "out of memory for a message from rank %d", st.MPI_SOURCE);
      break;
    }
    take_message(p, from);
    supply(p, from);
  }
  return NULL;
}

static void local_tiles(void *user, int64_t item, int thread) {
  (void)item;
  pass_ctx *p = user;
  for (;;) {
    if (session_cancelled(p->ss) || p->d->err_status) return;
    int64_t t = atomic_fetch_add(&p->next, 1);
    if (t >= p->ntiles) return;
    uint64_t n = tiles_render_tile(p->ss, t, p->s0, p->s1, p->target, &p->ts[thread]);
    atomic_fetch_add(&p->local_tiles, 1);
    atomic_fetch_add(&p->local_samples, n);
  }
}

static dist_state *dist_get(session *ss) {
  if (ss->dist) return ss->dist;
  dist_state *d = calloc(1, sizeof *d);
  if (!d) return NULL;
  d->heard = calloc((size_t)dist_size(), 1);
  d->held = calloc((size_t)dist_size(), sizeof *d->held);
  d->threads = calloc((size_t)dist_size(), sizeof *d->threads);
  d->rs = calloc((size_t)dist_size(), sizeof *d->rs);
  if (!d->heard || !d->held || !d->threads || !d->rs) {
    free(d->heard); free(d->held); free(d->threads); free(d->rs); free(d);
    return NULL;
  }
  ss->dist = d;
  return d;
}

static valo_status master_run(session *ss, const tile_pass *tp, thread_stats *ts, valo_error *err) {
  dist_state *d = dist_get(ss);
  if (!d) return err_set(err, VALO_ERR_NOMEM, "out of memory");
  pass_ctx p = {.ss = ss, .d = d, .s0 = tp->s0, .s1 = tp->s1, .prep = tp->prep, .target = tp->target, .ntiles = tiles_count(ss), .ts = ts};
  atomic_init(&p.next, 0);
  atomic_init(&p.local_tiles, 0);
  atomic_init(&p.local_samples, 0);
  pthread_t th;
  if (pthread_create(&th, NULL, talk, &p)) return err_set(err, VALO_ERR_NOMEM, "cannot start the thread that talks to the other ranks");
  parallel_for(ss->opt.threads, ss->opt.threads, local_tiles, &p);
  pthread_join(th, NULL);
  d->rs[0].tiles += atomic_load(&p.local_tiles);
  d->rs[0].samples += atomic_load(&p.local_samples);
  if (d->err_status) return err_set(err, d->err_status, "%s", d->err_msg);
  return VALO_OK;
}
const tile_source dist_master = {master_run};

void dist_finish(session *ss, thread_stats *sum) {
  dist_state *d = dist_get(ss);
  if (!d) return; /* cannot happen past the first pass; the workers then wait in vain */
  int n = dist_size(), from = 0;
  free(ss->ranks);
  ss->ranks = calloc((size_t)n, sizeof *ss->ranks);
  ss->nranks = ss->ranks ? n : 0;
  if (ss->ranks) {
    ss->ranks[0] = d->rs[0];
    ss->ranks[0].threads = ss->opt.threads;
    ss->ranks[0].rays = sum->rays;
    ss->ranks[0].busy_seconds = ss->render_seconds;
    ss->ranks[0].peak_memory = peak_memory();
    int len = 0;
    MPI_Get_processor_name(ss->ranks[0].host, &len);
  }
  for (int w = 1; w < n; w++) {
    while (!d->heard[w] || d->held[w] > 0) {
      if (recv_msg(w, &d->in, &from)) break;
      pass_ctx none = {.ss = ss, .d = d};
      take_message(&none, from);
    }
    const int32_t stop[2] = {MSG_STOP, 0};
    send_words(w, stop, 2);
    if (recv_msg(w, &d->in, &from)) continue;
    rank_stats rs;
    thread_stats t;
    memcpy(&rs, d->in.p + 8, sizeof rs);
    memcpy(&t, d->in.p + 8 + sizeof rs, sizeof t);
    thread_stats_add(sum, &t);
    if (ss->ranks) ss->ranks[w] = rs;
  }
  free(d->heard); free(d->held); free(d->threads); free(d->rs); free(d->in.p); free(d->out.p);
  free(d);
  ss->dist = NULL;
}

/* ---- the other ranks ---- */
typedef struct worker_job {
  session *ss;
  int s0, s1;
  const uint32_t *target;
  int64_t t0;
  thread_stats *ts;
  _Atomic uint64_t samples; /* taken in this batch */
} worker_job;
static void worker_tile(void *user, int64_t item, int thread) {
  worker_job *j = user;
  atomic_fetch_add(&j->samples, tiles_render_tile(j->ss, j->t0 + item, j->s0, j->s1, j->target, &j->ts[thread]));
}

valo_status dist_worker(session *ss, thread_stats *ts, valo_error *err) {
  size_t np = film_pixels(&ss->film);
  uint32_t *target = calloc(np, sizeof *target);
  buf in = {0}, out = {0};
  rank_stats me = {.threads = ss->opt.threads};
  int len = 0;
  MPI_Get_processor_name(me.host, &len);
  valo_status st = VALO_OK;
  int prepared = -1, from = 0;
  const int32_t hello[2] = {MSG_HELLO, ss->opt.threads};
  send_words(0, hello, 2);
  for (;;) {
    if (recv_msg(0, &in, &from)) { st = err_set(err, VALO_ERR_NOMEM, "out of memory"); break; }
    int32_t h[8];
    memcpy(h, in.p, sizeof h);
    if (h[0] == MSG_STOP) break;
    double t0 = now_seconds();
    valo_status wst = target ? VALO_OK : err_set(err, VALO_ERR_NOMEM, "out of memory for a %dx%d target", ss->opt.width, ss->opt.height);
    if (!wst && h[1] != ss->view_frame && tiles_set_view(ss, h[1]))
      wst = err_set(err, VALO_ERR_INVALID, "the camera at frame %d has its up vector along the view direction", h[1]);
    if (!wst && h[2] >= 0 && h[2] != prepared) {
      wst = ss->integ->prepare(ss->istate, &ss->ctx, h[2], err);
      if (!wst) prepared = h[2];
    }
    int n = h[7];
    size_t px = 0;
    for (int64_t t = h[6]; t < h[6] + n; t++) px += tile_pixels(ss, t);
    if (!wst && buf_fit(&out, 16 + px * px_bytes(&ss->film))) wst = err_set(err, VALO_ERR_NOMEM, "out of memory for a batch");
    if (wst) {
      unsigned char e[16 + 64 + sizeof err->message];
      memset(e, 0, sizeof e);
      const int32_t eh[4] = {MSG_ERROR, (int32_t)wst, 0, 0};
      memcpy(e, eh, sizeof eh);
      memcpy(e + 16, me.host, sizeof me.host);
      memcpy(e + 16 + 64, err->message, sizeof err->message);
      MPI_Send(e, (int)sizeof e, MPI_BYTE, 0, TAG, MPI_COMM_WORLD);
      continue;
    }
    tile_states(ss, h[6], n, h[5] ? target : NULL, 1, in.p + sizeof h);
    worker_job j = {ss, h[3], h[4], h[5] ? target : NULL, h[6], ts, 0};
    parallel_for(ss->opt.threads, n, worker_tile, &j);
    const int32_t rh[4] = {MSG_RESULT, h[6], n, 0};
    memcpy(out.p, rh, sizeof rh);
    unsigned char *end = tile_states(ss, h[6], n, NULL, 0, out.p + sizeof rh);
    me.tiles += (uint64_t)n;
    me.samples += atomic_load(&j.samples);
    me.busy_seconds += now_seconds() - t0;
    MPI_Send(out.p, (int)(end - out.p), MPI_BYTE, 0, TAG, MPI_COMM_WORLD);
  }
  thread_stats sum = ss->prep;
  for (int t = 0; t < ss->opt.threads; t++) thread_stats_add(&sum, &ts[t]);
  me.rays = sum.rays;
  me.peak_memory = peak_memory();
  unsigned char s[8 + sizeof me + sizeof sum];
  const int32_t sh[2] = {MSG_STATS, 0};
  memcpy(s, sh, 8);
  memcpy(s + 8, &me, sizeof me);
  memcpy(s + 8 + sizeof me, &sum, sizeof sum);
  MPI_Send(s, (int)sizeof s, MPI_BYTE, 0, TAG, MPI_COMM_WORLD);
  free(in.p);
  free(out.p);
  free(target);
  return st;
}

#else /* one process: valo built without MPI */
#include <stdlib.h>
int dist_built(void) { return 0; }
int dist_init(int *argc, char ***argv) {
  (void)argc; (void)argv;
  const char *n = getenv("OMPI_COMM_WORLD_SIZE");
  if (!n) n = getenv("PMI_SIZE");
  return n && atoi(n) > 1 ? atoi(n) : 1;
}
int dist_rank(void) { return 0; }
int dist_size(void) { return 1; }
void dist_finalize(void) {}
int dist_agree(int rc, valo_error *err) { (void)err; return rc; }
static valo_status master_run(session *ss, const tile_pass *tp, thread_stats *ts, valo_error *err) {
  (void)ss; (void)tp; (void)ts;
  return err_set(err, VALO_ERR_INVALID, "valo was built without MPI");
}
const tile_source dist_master = {master_run};
valo_status dist_worker(session *ss, thread_stats *ts, valo_error *err) {
  (void)ss; (void)ts;
  return err_set(err, VALO_ERR_INVALID, "valo was built without MPI");
}
void dist_finish(session *ss, thread_stats *sum) { (void)ss; (void)sum; }
#endif
