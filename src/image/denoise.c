/* denoise.c — see denoise.h. */
#include "image/denoise.h"
#include "core/threadpool.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define K_COLOR 0.45f     /* the colour term's bandwidth, in standard deviations */
#define EPS_COLOR 2.5e-5f  /* noise-free pixels merge only within about 0.5 % of each other */
#define SIGMA_ALBEDO 0.08f
#define SIGMA_NORMAL 0.25f /* on |n_p - n_q| */
#define SIGMA_DEPTH 0.03f  /* relative */
#define ALBEDO_MIN 0.02f   /* below this (lamps, the sky) the radiance is filtered as it is */

typedef struct dn_job {
  const denoise_in *in;
  const float *irr, *ivar, *alb;
  float *out;
} dn_job;

static void dn_row(void *user, int64_t yy, int thread) {
  (void)thread;
  const dn_job *j = user;
  const denoise_in *in = j->in;
  int w = in->w, h = in->h, y = (int)yy, R = DENOISE_RADIUS;
  for (int x = 0; x < w; x++) {
    size_t p = (size_t)y * w + x;
    double acc[3] = {0, 0, 0}, wsum = 0;
    for (int dy = -R; dy <= R; dy++) {
      int qy = y + dy;
      if (qy < 0 || qy >= h) continue;
      for (int dx = -R; dx <= R; dx++) {
        int qx = x + dx;
        if (qx < 0 || qx >= w) continue;
        size_t q = (size_t)qy * w + qx;
        /* features */
        float df = 0;
        if (in->albedo)
          for (int c = 0; c < 3; c++) { float d = (in->albedo[3 * p + c] - in->albedo[3 * q + c]) / SIGMA_ALBEDO; df += d * d; }
        if (in->normal)
          for (int c = 0; c < 3; c++) { float d = (in->normal[3 * p + c] - in->normal[3 * q + c]) / SIGMA_NORMAL; df += d * d; }
        if (in->depth) {
          float dp = in->depth[p], dq = in->depth[q];
          if ((dp > 0) != (dq > 0)) df += 1e3f; /* a hit beside a miss */
          else if (dp > 0) { float d = (dp - dq) / (SIGMA_DEPTH * dp); df += d * d; }
        }
        if (df > 30) continue;
        /* colour: the mean over a 3x3 patch of the variance-corrected squared difference */
        float dc = 0;
        int n = 0;
        for (int py = -1; py <= 1; py++) {
          int ay = y + py, by = qy + py;
          if (ay < 0 || ay >= h || by < 0 || by >= h) continue;
          for (int px = -1; px <= 1; px++) {
            int ax = x + px, bx = qx + px;
            if (ax < 0 || ax >= w || bx < 0 || bx >= w) continue;
            size_t a = (size_t)ay * w + ax, b = (size_t)by * w + bx;
            for (int c = 0; c < 3; c++) {
              float ia = j->irr[3 * a + c], ib = j->irr[3 * b + c], va = j->ivar[3 * a + c], vb = j->ivar[3 * b + c], d = ia - ib;
              dc += (d * d - (va + fminf(va, vb))) / (EPS_COLOR * (ia * ia + ib * ib) + 1e-10f + K_COLOR * K_COLOR * (va + vb));
            }
            n += 3;
          }
        }
        dc = n ? dc / (float)n : 0;
        float wt = expf(-(fmaxf(dc, 0) + 0.5f * df));
        for (int c = 0; c < 3; c++) acc[c] += wt * j->irr[3 * q + c];
        wsum += wt;
      }
    }
    for (int c = 0; c < 3; c++) j->out[3 * p + c] = (float)(wsum > 0 ? acc[c] / wsum : j->irr[3 * p + c]) * j->alb[3 * p + c];
  }
}

/* Without a variance buffer: each pixel's squared difference from its 3x3 neighbourhood's
 * mean, a rough (over-)estimate of its noise. */
static void estimate_var(const denoise_in *in, float *var) {
  int w = in->w, h = in->h;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      for (int c = 0; c < 3; c++) {
        double s = 0;
        int n = 0;
        for (int dy = -1; dy <= 1; dy++)
          for (int dx = -1; dx <= 1; dx++) {
            int ax = x + dx, ay = y + dy;
            if (ax < 0 || ax >= w || ay < 0 || ay >= h) continue;
            s += in->color[3 * ((size_t)ay * w + ax) + c];
            n++;
          }
        float d = in->color[3 * ((size_t)y * w + x) + c] - (float)(s / n);
        var[3 * ((size_t)y * w + x) + c] = d * d;
      }
}

int denoise_image(const denoise_in *in, float *out, int threads) {
  size_t np = (size_t)in->w * in->h;
  float *irr = malloc(np * 3 * sizeof(float)), *ivar = malloc(np * 3 * sizeof(float)), *alb = malloc(np * 3 * sizeof(float));
  float *own = in->var ? NULL : malloc(np * 3 * sizeof(float));
  if (!irr || !ivar || !alb || (!in->var && !own)) { free(irr); free(ivar); free(alb); free(own); return -1; }
  if (own) estimate_var(in, own);
  const float *var = in->var ? in->var : own;
  for (size_t i = 0; i < np * 3; i++) {
    float a = in->albedo ? in->albedo[i] : 1;
    alb[i] = a >= ALBEDO_MIN ? a : 1;
    float c = in->color[i];
    irr[i] = isfinite(c) ? c / alb[i] : 0;
    float v = isfinite(var[i]) && var[i] > 0 ? var[i] : 0;
    ivar[i] = v / (alb[i] * alb[i]);
  }
  dn_job j = {in, irr, ivar, alb, out};
  parallel_for(threads, in->h, dn_row, &j);
  free(irr); free(ivar); free(alb); free(own);
  return 0;
}
