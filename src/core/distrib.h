/* distrib.h — owns piecewise-constant distributions (pbrt-v3 §13.6.7): 1D (a CDF over n
 * bins, sampled continuously with its pdf) and 2D (a marginal over rows and one
 * conditional per row), used to importance-sample environment maps. */
#ifndef VALO_DISTRIB_H
#define VALO_DISTRIB_H
#include <stdint.h>

typedef struct distrib1d { float *func, *cdf; uint32_t n; float integral; } distrib1d;
typedef struct distrib2d { distrib1d *rows; distrib1d marginal; uint32_t nu, nv; } distrib2d;

/* f: n non-negative values (copied). Returns 0, or -1 on OOM/bad input. */
int distrib1d_init(distrib1d *d, const float *f, uint32_t n);
void distrib1d_free(distrib1d *d);
/* Returns x in [0,1) and its density; *bin receives the bin. */
float distrib1d_sample(const distrib1d *d, float u, float *pdf, uint32_t *bin);

/* f: nu*nv values, row-major (v rows of nu). */
int distrib2d_init(distrib2d *d, const float *f, uint32_t nu, uint32_t nv);
void distrib2d_free(distrib2d *d);
/* Samples (u, v) in [0,1)^2 with density *pdf (w.r.t. du dv). */
void distrib2d_sample(const distrib2d *d, float u1, float u2, float *u, float *v, float *pdf);
float distrib2d_pdf(const distrib2d *d, float u, float v);
#endif
