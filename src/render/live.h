/* live.h — owns the viewer's denoised frames (valo_render_denoise_live): a real-time
 * filter's state (image/svgf.h) kept across the steps of one render, fed with the film's
 * image, luminance moments and AOVs, and the reprojection of its history from the camera
 * of the last call to this one (through the first hits' depth). */
#ifndef VALO_LIVE_H
#define VALO_LIVE_H
#include "render/session.h"

typedef struct live_state live_state;

/* One frame of the filter on the film as it stands into out (3 per pixel); *lp is
 * created on the first call. The film must hold AOVs. */
valo_status live_denoise(live_state **lp, const session *ss, float *out, valo_error *err);
/* Forgets the history (the next call filters its frame alone). */
void live_reset(live_state *l);
void live_free(live_state *l);
#endif
