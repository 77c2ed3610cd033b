/* svgf.c — see svgf.h. */
#include "image/svgf.h"
#include "core/threadpool.h"
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define ALBEDO_MIN 0.02f  /* below this (lamps, the sky) the radiance is filtered as it is */
#define ROUNDS 4          /* a-trous rounds: steps 1, 2, 4, 8 */
#define SIGMA_L 4.0f      /* luminance: in standard deviations of the pixel's estimate */
#define SIGMA_Z 2.0f      /* depth: in units of the pixel's depth gradient times the offset */
#define NORMAL_POW 7      /* normals: max(0, n_p . n_q)^(2^7) */
#define REPROJ_DEPTH 0.05f  /* a history pixel is the same surface within 5 % of depth */
#define REPROJ_NORMAL 0.9f  /* and a normal within about 25 degrees */
#define REPROJ_ALBEDO 0.3f  /* and, after a move, an albedo within 0.3 (summed over r, g, b) */
#define MOMENTS_MIN 4.0f    /* fewer samples: the variance from the 5x5 neighbourhood */

struct svgf {
  int w, h, have;
  /* history: the integrated radiance and albedo, luminance moments (2), samples, normal, depth */
  float *hcol, *halb, *hemi, *hmom, *hlen, *hnrm, *hdep;
  /* the prior: the history reprojected at the last fresh frame */
  float *pcol, *palb, *pemi, *pmom, *plen;
  /* this frame: the albedo divided out, its radiance (finite), its moments, a-trous colour
   * and variance (ping-pong), depth gradient */
  float *alb, *rad, *cmom, *c[2], *v[2], *gz, *sd;
  float *kind;         /* 0 nothing hit, 1 a surface, 2 a lamp (no albedo): never mixed (floats for
                          the vectorised a-trous loop) */
};

float svgf_history(const svgf *s, int x, int y) { return s->have ? s->hlen[(size_t)y * s->w + x] : 0; }

/* e^-x for x in [0, 20], within 2e-4 relative (the weights need no more): 2^(-x log2 e)
 * split into an exponent and a fraction whose power a cubic gives. */
static inline float exp_neg(float x) {
  float t = -x * 1.44269504f;
  int e = (int)t;
  e -= (float)e > t ? 1 : 0; /* floor (t <= 0) */
  float fr = t - (float)e;
  float p = 1.0f + fr * (0.69583354f + fr * (0.22606716f + fr * 0.078024521f));
  int32_t bits = (e + 127) * (1 << 23); /* 2^e: e >= -29 for x <= 20 */
  float two_e;
  memcpy(&two_e, &bits, sizeof two_e);
  return p * two_e;
}

static float lum3(const float *c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

svgf *svgf_create(int w, int h) {
  svgf *s = calloc(1, sizeof *s);
  if (!s) return NULL;
  s->w = w;
  s->h = h;
  size_t np = (size_t)w * h;
  /* one block: 3+3+3+2+1+3+1 history, 3+3+3+2+1 prior, 3+3+2+3+3+1+1+1+1 frame */
  float *b = calloc(np * 46, sizeof(float));
  s->kind = calloc(np, sizeof(float));
  if (!b || !s->kind) { free(b); free(s->kind); free(s); return NULL; }
  float **slot[] = {&s->hcol, &s->halb, &s->hemi, &s->hmom, &s->hlen, &s->hnrm, &s->hdep, &s->pcol, &s->palb, &s->pemi, &s->pmom, &s->plen,
                    &s->alb, &s->rad, &s->cmom, &s->c[0], &s->c[1], &s->v[0], &s->v[1], &s->gz, &s->sd};
  const int size[] = {3, 3, 3, 2, 1, 3, 1, 3, 3, 3, 2, 1, 3, 3, 2, 3, 3, 1, 1, 1, 1};
  for (size_t k = 0; k < sizeof size / sizeof *size; k++) {
    *slot[k] = b;
    b += np * size[k];
  }
  return s;
}

void svgf_destroy(svgf *s) {
  if (!s) return;
  free(s->hcol); /* the block */
  free(s->kind);
  free(s);
}

void svgf_reset(svgf *s) { s->have = 0; }

typedef struct job {
  svgf *s;
  const svgf_frame *f;
  float *out;
  int round, known;
  volatile int failed; /* a row's scratch could not be allocated */
} job;

/* The frame's radiance less its emission (non-finite and negative values as 0) and
 * per-sample luminance moments. */
static void st_moments(void *user, int64_t y, int thread) {
  (void)thread;
  job *j = user;
  svgf *s = j->s;
  const svgf_frame *f = j->f;
  for (int x = 0; x < s->w; x++) {
    size_t p = (size_t)y * s->w + x;
    for (int c = 0; c < 3; c++) {
      float col = f->color[3 * p + c] - (f->emission ? f->emission[3 * p + c] : 0);
      s->rad[3 * p + c] = isfinite(col) && col > 0 ? col : 0;
    }
    float l = lum3(&s->rad[3 * p]);
    s->cmom[2 * p] = l;
    s->cmom[2 * p + 1] = f->lum2 && isfinite(f->lum2[p]) ? fmaxf(f->lum2[p], l * l) : l * l;
  }
}

/* The prior of a fresh frame: the history at this pixel's point on the last frame's film,
 * bilinear over the four pixels around it that saw the same surface. */
static void st_reproject(void *user, int64_t y, int thread) {
  (void)thread;
  job *j = user;
  svgf *s = j->s;
  const svgf_frame *f = j->f;
  int w = s->w, h = s->h;
  for (int x = 0; x < w; x++) {
    size_t p = (size_t)y * w + x;
    float d = f->depth[p], acc[12] = {0}, wsum = 0;
    const float *n = &f->normal[3 * p];
    int taps = 0;
    int qx[4], qy[4];
    float qw[4];
    if (!f->prev_xy) {
      qx[0] = x; qy[0] = (int)y; qw[0] = 1; taps = 1;
    } else if (d > 0 && isfinite(f->prev_xy[2 * p])) {
      float fx = f->prev_xy[2 * p] - 0.5f, fy = f->prev_xy[2 * p + 1] - 0.5f;
      int x0 = (int)floorf(fx), y0 = (int)floorf(fy);
      float ax = fx - (float)x0, ay = fy - (float)y0;
      for (int k = 0; k < 4; k++) {
        qx[k] = x0 + (k & 1);
        qy[k] = y0 + (k >> 1);
        qw[k] = (k & 1 ? ax : 1 - ax) * (k >> 1 ? ay : 1 - ay);
      }
      taps = 4;
    }
    float dexp = f->prev_xy ? f->prev_d[p] : d;
    for (int k = 0; k < taps; k++) {
      if (qx[k] < 0 || qy[k] < 0 || qx[k] >= w || qy[k] >= h || !(qw[k] > 0)) continue;
      size_t q = (size_t)qy[k] * w + qx[k];
      if (!(s->hlen[q] > 0)) continue;
      float hd = s->hdep[q];
      if ((hd > 0) != (d > 0)) continue;
      if (d > 0) {
        if (fabsf(hd - dexp) > REPROJ_DEPTH * dexp) continue;
        const float *hn = &s->hnrm[3 * q];
        if (hn[0] * n[0] + hn[1] * n[1] + hn[2] * n[2] < REPROJ_NORMAL) continue;
        /* after a move, nor a lamp's history for a wall beside it, nor the other way (on a
         * still camera a pixel's rays hit either side of an edge, and radiance and albedo
         * are averaged alike: that history is right) */
        const float *ha = &s->halb[3 * q], *a = &f->albedo[3 * p];
        if (f->prev_xy && fabsf(ha[0] - a[0]) + fabsf(ha[1] - a[1]) + fabsf(ha[2] - a[2]) > REPROJ_ALBEDO) continue;
      }
      float wt = qw[k];
      for (int c = 0; c < 3; c++) acc[c] += wt * s->hcol[3 * q + c];
      for (int c = 0; c < 3; c++) acc[6 + c] += wt * s->halb[3 * q + c];
      for (int c = 0; c < 3; c++) acc[9 + c] += wt * s->hemi[3 * q + c];
      acc[3] += wt * s->hmom[2 * q];
      acc[4] += wt * s->hmom[2 * q + 1];
      acc[5] += wt * s->hlen[q];
      wsum += wt;
    }
    if (wsum < 0.01f) {
      s->plen[p] = 0;
      continue;
    }
    for (int c = 0; c < 3; c++) s->pcol[3 * p + c] = acc[c] / wsum;
    for (int c = 0; c < 3; c++) s->palb[3 * p + c] = acc[6 + c] / wsum;
    for (int c = 0; c < 3; c++) s->pemi[3 * p + c] = acc[9 + c] / wsum;
    s->pmom[2 * p] = acc[3] / wsum;
    s->pmom[2 * p + 1] = acc[4] / wsum;
    /* a moving camera's history is resampled every frame (a blur): it counts for less */
    float len = acc[5] / wsum, cap = (f->prev_xy ? SVGF_MOVING_CAP : SVGF_HISTORY_CAP) * f->n;
    s->plen[p] = len < cap ? len : cap;
  }
}

/* The frame and its prior together, by sample count; the new history; the variance of the
 * estimate from its moments (-1: to be taken from the neighbourhood); the depth gradient. */
static void st_integrate(void *user, int64_t y, int thread) {
  (void)thread;
  job *j = user;
  svgf *s = j->s;
  const svgf_frame *f = j->f;
  int w = s->w, h = s->h;
  for (int x = 0; x < w; x++) {
    size_t p = (size_t)y * w + x;
    float n = f->n, pl = s->have ? s->plen[p] : 0, N = n + pl;
    /* radiance and albedo accumulate alike (each frame's camera rays hit where they hit:
     * at an edge the albedo averages as the radiance does), then the one divides the other */
    for (int c = 0; c < 3; c++) {
      float col = (n * s->rad[3 * p + c] + pl * s->pcol[3 * p + c]) / N, a = (n * f->albedo[3 * p + c] + pl * s->palb[3 * p + c]) / N;
      s->hcol[3 * p + c] = col;
      s->halb[3 * p + c] = a;
      float e = f->emission && isfinite(f->emission[3 * p + c]) ? f->emission[3 * p + c] : 0;
      s->hemi[3 * p + c] = (n * e + pl * s->pemi[3 * p + c]) / N;
      s->alb[3 * p + c] = a >= ALBEDO_MIN ? a : 1;
      s->c[0][3 * p + c] = col / s->alb[3 * p + c];
    }
    float m1 = (n * s->cmom[2 * p] + pl * s->pmom[2 * p]) / N, m2 = (n * s->cmom[2 * p + 1] + pl * s->pmom[2 * p + 1]) / N;
    s->hmom[2 * p] = m1;
    s->hmom[2 * p + 1] = m2;
    s->hlen[p] = N;
    for (int c = 0; c < 3; c++) s->hnrm[3 * p + c] = f->normal[3 * p + c];
    float d = f->depth[p], asum = s->halb[3 * p] + s->halb[3 * p + 1] + s->halb[3 * p + 2], la = lum3(&s->alb[3 * p]);
    s->hdep[p] = d;
    s->kind[p] = !(d > 0) ? 0.0f : asum < ALBEDO_MIN ? 2.0f : 1.0f;
    /* the variance of the estimate, divided by the albedo as the colour is */
    s->v[0][p] = j->known && N >= MOMENTS_MIN ? fmaxf(0, m2 - m1 * m1) / N / (la * la) : -1;
    /* depth gradient: the smaller one-sided difference on each axis (edges do not count) */
    float g[2] = {0, 0};
    for (int a = 0; a < 2; a++) {
      float best = INFINITY;
      for (int sgn = -1; sgn <= 1; sgn += 2) {
        int qx = x + (a ? 0 : sgn), qy = (int)y + (a ? sgn : 0);
        if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
        float dq = f->depth[(size_t)qy * w + qx];
        if (dq > 0) best = fminf(best, fabsf(dq - d));
      }
      g[a] = isfinite(best) ? best : 0;
    }
    s->gz[p] = sqrtf(g[0] * g[0] + g[1] * g[1]);
  }
}

/* Edge-stopping between p and q apart from luminance: 0 for another kind (hit, miss,
 * lamp), else the normals' weight, with the depth's exponent added to *ez; inv_z is one
 * over the depth difference's scale at this offset. */
static inline float feature_weight(const svgf *s, const svgf_frame *f, size_t p, size_t q, float inv_z, float *ez) {
  if (s->kind[p] != s->kind[q]) return 0;
  if (s->kind[p] != 1) return 1;
  const float *np = &f->normal[3 * p], *nq = &f->normal[3 * q];
  float wn = fmaxf(0, np[0] * nq[0] + np[1] * nq[1] + np[2] * nq[2]);
  for (int k = 0; k < NORMAL_POW; k++) wn *= wn;
  *ez += fabsf(f->depth[p] - f->depth[q]) * inv_z;
  return wn;
}

/* One over the depth difference's scale at p for an offset of dist pixels. */
static inline float depth_scale(const svgf *s, const svgf_frame *f, size_t p, float dist) {
  return 1.0f / (SIGMA_Z * s->gz[p] * dist + 1e-3f * f->depth[p] + 1e-20f);
}

/* Where the moments are too few: the variance from the 5x5 neighbourhood's moments (or,
 * without moments, from its means), weighted by the features. */
static void st_variance(void *user, int64_t y, int thread) {
  (void)thread;
  job *j = user;
  svgf *s = j->s;
  const svgf_frame *f = j->f;
  int w = s->w, h = s->h;
  for (int x = 0; x < w; x++) {
    size_t p = (size_t)y * w + x;
    float v = s->v[0][p];
    if (v >= 0) { s->v[1][p] = v; continue; }
    double a1 = 0, a2 = 0, ws = 0;
    for (int dy = -2; dy <= 2; dy++)
      for (int dx = -2; dx <= 2; dx++) {
        int qx = x + dx, qy = (int)y + dy;
        if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
        size_t q = (size_t)qy * w + qx;
        float ez = 0, wt = q == p ? 1 : feature_weight(s, f, p, q, depth_scale(s, f, p, sqrtf((float)(dx * dx + dy * dy))), &ez);
        if (!(wt > 0)) continue;
        wt *= exp_neg(ez > 20 ? 20 : ez);
        float m1 = s->hmom[2 * q], m2 = j->known ? s->hmom[2 * q + 1] : m1 * m1;
        a1 += wt * m1;
        a2 += wt * m2;
        ws += wt;
      }
    a1 /= ws;
    a2 /= ws;
    float la = lum3(&s->alb[3 * p]), var = (float)fmax(0, a2 - a1 * a1) / (la * la);
    s->v[1][p] = j->known ? var / s->hlen[p] : var;
  }
}

/* The luminance scale of each pixel for a round: SIGMA_L standard deviations, from the
 * variance's 3x3 Gaussian blur (separable; the edge pixel stands in for the one outside).
 * A pair of pixels is compared on the larger of their two scales, so weights are
 * symmetric: a bright pixel among dim ones spreads as much as it gathers, rather than
 * only darkening. */
static void st_scale(void *user, int64_t yy, int thread) {
  (void)thread;
  job *j = user;
  svgf *s = j->s;
  int w = s->w, h = s->h, y = (int)yy;
  const float *vi = s->v[(j->round + 1) & 1];
  static const float k3[3] = {0.25f, 0.5f, 0.25f};
  float *sd = s->sd + (size_t)y * w;
  for (int x = 0; x < w; x++) sd[x] = 0;
  float gy = 0;
  for (int dy = -1; dy <= 1; dy++) {
    int qy = y + dy;
    if (qy < 0 || qy >= h) continue;
    float ky = k3[dy + 1];
    const float *vr = vi + (size_t)qy * w;
    gy += ky;
    for (int x = 0; x < w; x++) {
      float l = x > 0 ? vr[x - 1] : vr[x], r = x + 1 < w ? vr[x + 1] : vr[x];
      sd[x] += ky * (0.25f * l + 0.5f * vr[x] + 0.25f * r);
    }
  }
  for (int x = 0; x < w; x++) sd[x] = SIGMA_L * sqrtf(sd[x] / gy);
}

/* Four pixels at a time (GCC/clang vector extensions: SSE2 on x86-64, NEON on arm64). */
typedef float v4f __attribute__((vector_size(16)));
typedef int32_t v4i __attribute__((vector_size(16)));
static inline v4f ld4(const float *p) { v4f v; memcpy(&v, p, sizeof v); return v; }
static inline void st4(float *p, v4f v) { memcpy(p, &v, sizeof v); }
/* channel c of four consecutive pixels of a 3-per-pixel array */
static inline v4f ld4c(const float *p, int c) { return (v4f){p[c], p[3 + c], p[6 + c], p[9 + c]}; }
static inline v4f sel4(v4i m, v4f a, v4f b) { return (v4f)(((v4i)a & m) | ((v4i)b & ~m)); }
static inline v4f abs4(v4f a) { return (v4f)((v4i)a & 0x7fffffff); }
/* exp_neg on four values (the same steps) */
static inline v4f exp_neg4(v4f x) {
  v4f t = x * -1.44269504f;
  v4i e = __builtin_convertvector(t, v4i);
  e += (v4i)(__builtin_convertvector(e, v4f) > t); /* true is -1: floor */
  v4f fr = t - __builtin_convertvector(e, v4f);
  v4f p = 1.0f + fr * (0.69583354f + fr * (0.22606716f + fr * 0.078024521f));
  return p * (v4f)((e + 127) * (1 << 23));
}

/* One tap (offset dx, dy) along n pixels of a row: every array from the first of them (q's
 * at the tap). */
typedef struct tap_row {
  const float *np, *nq, *dp, *dq, *cq, *vq, *kp, *kq; /* normals, depths, colours, variances, kinds */
  const float *lp, *sdp, *sdq, *iz, *sf;              /* p's luminance, both luminance scales, p's depth scale, surface flag */
  float kw;
  float *ar, *ag, *ab, *ws, *vs;                      /* the sums */
} tap_row;

static void tap_scalar(const tap_row *t, int x) {
  float dot = t->np[3 * x] * t->nq[3 * x] + t->np[3 * x + 1] * t->nq[3 * x + 1] + t->np[3 * x + 2] * t->nq[3 * x + 2];
  float wn = dot > 0 ? dot : 0;
  for (int k = 0; k < NORMAL_POW; k++) wn *= wn;
  float lq = 0.2126f * t->cq[3 * x] + 0.7152f * t->cq[3 * x + 1] + 0.0722f * t->cq[3 * x + 2];
  float sf = t->sf[x], sl = t->sdp[x] > t->sdq[x] ? t->sdp[x] : t->sdq[x];
  float e = fabsf(t->lp[x] - lq) / (sl + 1e-6f) + sf * fabsf(t->dp[x] - t->dq[x]) * t->iz[x];
  float wt = t->kw * (t->kp[x] == t->kq[x] ? 1.0f : 0.0f) * (sf * wn + (1 - sf)) * exp_neg(e < 20 ? e : 20);
  t->ar[x] += wt * t->cq[3 * x];
  t->ag[x] += wt * t->cq[3 * x + 1];
  t->ab[x] += wt * t->cq[3 * x + 2];
  t->ws[x] += wt;
  t->vs[x] += wt * wt * t->vq[x];
}

static void tap_run(const tap_row *t, int n) {
  int x = 0;
  for (; x + 4 <= n; x += 4) {
    const float *np = t->np + 3 * x, *nq = t->nq + 3 * x, *cq = t->cq + 3 * x;
    v4f dot = ld4c(np, 0) * ld4c(nq, 0) + ld4c(np, 1) * ld4c(nq, 1) + ld4c(np, 2) * ld4c(nq, 2);
    v4f wn = (v4f)((v4i)dot & (dot > 0));
    for (int k = 0; k < NORMAL_POW; k++) wn *= wn;
    v4f cr = ld4c(cq, 0), cg = ld4c(cq, 1), cb = ld4c(cq, 2);
    v4f lq = 0.2126f * cr + 0.7152f * cg + 0.0722f * cb, sf = ld4(t->sf + x);
    v4f sp = ld4(t->sdp + x), sq = ld4(t->sdq + x), sl = sel4(sp > sq, sp, sq);
    v4f e = abs4(ld4(t->lp + x) - lq) / (sl + 1e-6f) + sf * abs4(ld4(t->dp + x) - ld4(t->dq + x)) * ld4(t->iz + x);
    e = sel4(e < 20.0f, e, (v4f){20, 20, 20, 20});
    v4f same = (v4f)((v4i)(v4f){1, 1, 1, 1} & (ld4(t->kp + x) == ld4(t->kq + x)));
    v4f wt = t->kw * same * (sf * wn + (1.0f - sf)) * exp_neg4(e);
    st4(t->ar + x, ld4(t->ar + x) + wt * cr);
    st4(t->ag + x, ld4(t->ag + x) + wt * cg);
    st4(t->ab + x, ld4(t->ab + x) + wt * cb);
    st4(t->ws + x, ld4(t->ws + x) + wt);
    st4(t->vs + x, ld4(t->vs + x) + wt * wt * ld4(t->vq + x));
  }
  for (; x < n; x++) tap_scalar(t, x);
}

/* One a-trous round at step 2^round, from buffer round%2 to the other (the colour), and the
 * variance filtered with the squared weights; the last round multiplies the albedo back.
 * A row at a time, one tap at a time along the row. */
static void st_atrous(void *user, int64_t yy, int thread) {
  (void)thread;
  job *j = user;
  svgf *s = j->s;
  const svgf_frame *f = j->f;
  int w = s->w, h = s->h, y = (int)yy, step = 1 << j->round;
  /* the variance is in v[1] after st_variance; colour in c[0]: round r reads c[r%2], v[(r+1)%2] */
  const float *ci = s->c[j->round & 1], *vi = s->v[(j->round + 1) & 1];
  float *co = s->c[(j->round + 1) & 1], *vo = s->v[j->round & 1];
  static const float k3[3] = {0.25f, 0.5f, 0.25f};
  float *row = malloc((size_t)w * 10 * sizeof *row);
  if (!row) { j->failed = 1; return; }
  float *lp = row, *iz0 = lp + w, *iz1 = iz0 + w, *ar = iz1 + w, *ag = ar + w, *ab = ag + w, *ws = ab + w, *vs = ws + w, *surf = vs + w;
  const float *kf = s->kind;
  size_t p0 = (size_t)y * w;
  for (int x = 0; x < w; x++) {
    size_t p = p0 + x;
    lp[x] = lum3(&ci[3 * p]);
    iz0[x] = depth_scale(s, f, p, (float)step);
    iz1[x] = depth_scale(s, f, p, (float)step * 1.41421356f);
    surf[x] = kf[p] == 1;
    /* the centre tap */
    ar[x] = 0.25f * ci[3 * p];
    ag[x] = 0.25f * ci[3 * p + 1];
    ab[x] = 0.25f * ci[3 * p + 2];
    ws[x] = 0.25f;
    vs[x] = 0.0625f * vi[p];
  }
  for (int dy = -1; dy <= 1; dy++) {
    int qy = y + dy * step;
    if (qy < 0 || qy >= h) continue;
    for (int dx = -1; dx <= 1; dx++) {
      if (!dx && !dy) continue;
      int off = dx * step, x0 = off < 0 ? -off : 0, x1 = off > 0 ? w - off : w;
      /* every pointer at the first pixel the tap reaches */
      size_t a0 = p0 + x0, b0 = (size_t)qy * w + (size_t)(x0 + off);
      tap_row t = {f->normal + 3 * a0, f->normal + 3 * b0, f->depth + a0, f->depth + b0, ci + 3 * b0, vi + b0, kf + a0, kf + b0,
                   lp + x0, s->sd + a0, s->sd + b0, (dx && dy ? iz1 : iz0) + x0, surf + x0, k3[dx + 1] * k3[dy + 1], ar + x0, ag + x0, ab + x0, ws + x0, vs + x0};
      tap_run(&t, x1 - x0);
    }
  }
  for (int x = 0; x < w; x++) {
    size_t p = p0 + x;
    co[3 * p] = ar[x] / ws[x];
    co[3 * p + 1] = ag[x] / ws[x];
    co[3 * p + 2] = ab[x] / ws[x];
    vo[p] = vs[x] / (ws[x] * ws[x]);
    if (j->round == ROUNDS - 1)
      for (int c = 0; c < 3; c++) j->out[3 * p + c] = co[3 * p + c] * s->alb[3 * p + c] + s->hemi[3 * p + c];
  }
  free(row);
}

int svgf_run(svgf *s, const svgf_frame *f, float *out, int threads) {
  if (f->w != s->w || f->h != s->h) return -1;
  job j = {s, f, out, 0, f->lum2 != NULL || f->n <= 1, 0};
  parallel_for(threads, s->h, st_moments, &j);
  if (!s->have) memset(s->plen, 0, (size_t)s->w * s->h * sizeof *s->plen);
  else if (f->fresh) parallel_for(threads, s->h, st_reproject, &j);
  parallel_for(threads, s->h, st_integrate, &j);
  s->have = 1;
  parallel_for(threads, s->h, st_variance, &j);
  for (j.round = 0; j.round < ROUNDS; j.round++) {
    parallel_for(threads, s->h, st_scale, &j);
    parallel_for(threads, s->h, st_atrous, &j);
  }
  return j.failed ? -1 : 0;
}
