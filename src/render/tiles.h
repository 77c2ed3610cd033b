/* tiles.h — owns the per-ray tile loop (pbrt's ImageTileIntegrator): TILE x TILE tiles,
 * each pixel's samples taken in sample order, each sample a camera ray through the lens
 * (set per frame here), the AOVs of its first hit, and the integrator's li() — or, for
 * integrators with li_n, up to session.batch samples at once, added to the film in the
 * same order; and the source of a pass's tiles: this process's thread pool
 * (tiles_local), or under MPI rank 0 handing them out to every rank (dist_master,
 * render/dist.h), which calls back into the loop here. The session holds one and the
 * loop never asks which. */
#ifndef VALO_TILES_H
#define VALO_TILES_H
#include "render/session.h"

/* A pass: samples [s0, s1) of every pixel, or (target not NULL) each pixel from its count
 * up to target[pix]; prep: the sample index whose prepare the pass needs (-1: none). */
typedef struct tile_pass { int s0, s1; const uint32_t *target; int prep; } tile_pass;
/* Renders a pass's tiles, each by tiles_render_tile. */
typedef struct tile_source {
  valo_status (*run)(session *ss, const tile_pass *p, thread_stats *ts, valo_error *err);
} tile_source;
extern const tile_source tiles_local; /* the thread pool claims the tiles */

/* The pinhole basis of frame f (the scene's camera animation in a sequence, else the
 * still camera) into ss->lens.view; -1 when up is parallel to the view direction. */
int tiles_set_view(session *ss, int f);
/* Takes samples [s0, s1) of every pixel (integrators with prepare: one sample index at a
 * time, each after its prepare). VALO_ERR_CANCELLED when the session was cancelled. */
valo_status tiles_render(session *ss, int s0, int s1, thread_stats *ts, valo_error *err);
/* Takes each pixel from its count up to target[pix] (adaptive sampling), tile by tile;
 * the caller checks for cancellation. Fails only when another rank failed (MPI). */
valo_status tiles_render_to(session *ss, const uint32_t *target, thread_stats *ts, valo_error *err);
/* The tiles of the film, and tile t's pixels [x0, x1) x [y0, y1). */
int64_t tiles_count(const session *ss);
void tiles_rect(const session *ss, int64_t tile, int *x0, int *y0, int *x1, int *y1);
/* Takes samples [s0, s1) of every pixel of tile t, or (target not NULL) each pixel from
 * its count up to target[pix]; returns the samples taken. */
uint64_t tiles_render_tile(session *ss, int64_t tile, int s0, int s1, const uint32_t *target, thread_stats *ts);
/* Takes samples [s0, s1) of pixel (x, y) in order. */
void tiles_sample_pixel(session *ss, int x, int y, int s0, int s1, thread_stats *ts);
#endif
