/* svgf.h — owns the real-time denoiser of `valo view`: spatiotemporal variance-guided
 * filtering (Schied et al. 2017). Each frame's radiance and first-hit albedo are
 * accumulated over time (the last frames' estimate, reprojected to this frame's pixels and
 * kept where depth, normal and albedo agree, weighted by its sample count up to
 * SVGF_HISTORY_CAP times this frame's, SVGF_MOVING_CAP after a move), the one divided by the other (radiance and albedo averaged alike,
 * so a pixel on an edge whose camera rays hit now one side, now the other, keeps its
 * energy); the per-pixel luminance variance of that estimate comes from the samples'
 * moments (or, with few samples, from a 5x5 neighbourhood's), and an edge-aware a-trous
 * wavelet (four 3x3 rounds, steps 1 to 8) guided by normal, depth and that variance
 * smooths it; then the albedo multiplies it back and the emission seen directly (kept
 * apart from the start, accumulated the same way, never filtered) is added. Every step reads its window and writes
 * its pixel: images are the same for any thread count. What it biases: light finer than
 * the filter's footprint where the features are flat (soft shadow edges, small caustics)
 * is blurred, radiance is averaged across a pixel's edges, and a reprojected history lags
 * lighting that changes (valo's scenes are static: the camera moves). */
#ifndef VALO_SVGF_H
#define VALO_SVGF_H

#define SVGF_HISTORY_CAP 32 /* the history counts for at most this many times the frame's samples */
#define SVGF_MOVING_CAP 4   /* and after the camera moved (its history was resampled) */

typedef struct svgf svgf;

/* One frame: the film's image and AOVs. */
typedef struct svgf_frame {
  int w, h;
  const float *color;   /* 3 per pixel: each pixel's mean radiance */
  const float *lum2;    /* 1 per pixel: the mean of the samples' squared luminance (NULL: unknown) */
  float n;              /* samples per pixel in color */
  const float *albedo;  /* 3 per pixel */
  const float *emission; /* 3 per pixel: the part of color the first hit emits (left
                           unfiltered, so lamps do not bleed into what they light), or NULL */
  const float *normal;  /* 3 per pixel, unit, facing the camera; zero where nothing was hit */
  const float *depth;   /* 1 per pixel: distance to the first hit, 0 where nothing was hit */
  int fresh;            /* 1: color shares no sample with the last frame's (a restart), so the
                           history is reprojected; 0: color goes on accumulating the same film */
  const float *prev_xy; /* fresh frames: 2 per pixel, where this pixel's point lay on the last
                           frame's film (pixels; centres at +0.5), NaN for nowhere; NULL: the
                           same pixel (a still camera) */
  const float *prev_d;  /* with prev_xy: that point's distance from the last frame's camera */
} svgf_frame;

/* A filter for w x h frames with no history; NULL when out of memory. */
svgf *svgf_create(int w, int h);
void svgf_destroy(svgf *s);
/* Forgets the history: the next frame is filtered alone. */
void svgf_reset(svgf *s);
/* Filters frame f (its size the filter's) into out (3 per pixel) and keeps its history.
 * Returns 0, or -1 when out of memory. */
int svgf_run(svgf *s, const svgf_frame *f, float *out, int threads);
/* The history's samples at pixel (x, y) after the last frame (tests, the bench's ghosting
 * figure). */
float svgf_history(const svgf *s, int x, int y);
#endif
