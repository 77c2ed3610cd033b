/* adaptive.h — owns adaptive sampling after the uniform first pass: the "error" rule
 * (unbiased: each pixel's count from its neighbours' relative variance, water-filled) and
 * the "digest" rule (rounds for the pixels with the highest priority on their own
 * samples; biased). docs/integrators.md describes both; docs/performance.md has the
 * measurements that chose the first pass's share and the neighbourhood. */
#ifndef VALO_ADAPTIVE_H
#define VALO_ADAPTIVE_H
#include "render/session.h"

/* The uniform first pass's share of the budget (of the samples, or of the time). */
#define ADAPT_UNIFORM 0.5

/* After the first pass: samples up to `total` over the image (or until the time budget
 * `budget` > 0, counted from t0), reporting progress. */
valo_status adapt_error(session *ss, double total, double budget, double t0, valo_progress_fn progress, void *user, thread_stats *ts,
                        valo_error *err);
valo_status adapt_digest(session *ss, int uniform_spp, double total, double budget, double t0, valo_progress_fn progress, void *user,
                         thread_stats *ts, valo_error *err);
/* The rules' per-pixel statistics: the relative variance of one sample (error) and the
 * priority on the pixel's own luminance samples (digest). */
double adapt_pixel_relvar(const session *ss, size_t i);
double adapt_pixel_digest(const session *ss, size_t i);
#endif
