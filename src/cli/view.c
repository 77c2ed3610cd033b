/* view.c — owns `valo view`: a window (SDL2) showing a render as it refines, step by step
 * through valo_render_step, with the integrator, samples per pixel and samples per second
 * on screen. The mouse orbits (left drag), pans (right or middle drag, or shift + left)
 * and zooms (wheel); W A S D Q E move; every move restarts the film. Keys switch the
 * integrator, the layer (image, albedo, normal, depth, ao) and the exposure, and save the
 * image (EXR and PNG). Image-wide integrators (restir-di, restir-gi) run in real time:
 * each frame shown alone, with temporal reuse from the last, in the fast configuration
 * below. The image is shown through the real-time denoiser (valo_render_denoise_live:
 * SVGF) unless --no-denoise or the F key turns it off. --benchmark N renders N frames on
 * the still camera without waiting for input (SDL's dummy video driver when there is no
 * display) and prints "fps X" last.
 * Built only when SDL2 is found; uses only the public API. */
#include "cli/view.h"
#include "cli/args.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* restir's real-time configuration, chosen by measurement (bench_view on the walls room
 * at 320x240 on 2 threads, docs/performance.md): restir-di with temporal reuse only (spatial
 * rounds cost more than they gain once history builds up, and let a bright sample spread);
 * restir-gi with one round of 2 neighbours. The user's --param entries come after it and win. */
static const char realtime_params[] =
    "restir-di.candidates=4 restir-di.iterations=0 restir-di.unbiased=0 restir-di.reservoirs=1 "
    "restir-gi.candidates=4 restir-gi.iterations=1 restir-gi.spatial=2 restir-gi.direct_iterations=0 restir-gi.unbiased=0";

static void usage_view(FILE *f) {
  fprintf(f,
          "Usage: valo view SCENE [options]\n\n"
          "Opens a window showing SCENE as it renders, refining while the camera is still.\n"
          "restir-di and restir-gi run in real time: each frame shown alone, with temporal\n"
          "reuse from the last, in a fast configuration that --param overrides:\n"
          "  %s\n\n"
          "The image is shown through a real-time denoiser (spatiotemporal variance-guided\n"
          "filtering, guided by the first hits' albedo, normal and depth); F turns it off and on.\n\n"
          "  --benchmark N          render N frames on the still camera without waiting for input\n"
          "                         (no window when there is no display), print \"fps X\" last\n"
          "  --no-denoise           show the raw image (F turns the denoiser on)\n"
          "  -o FILE                --benchmark: write the last frame as shown (.exr, .pfm, .hdr, .png, .jpg);\n"
          "                         otherwise the save key writes FILE's name with -0001.exr and\n"
          "                         -0001.png, ...\n"
          "                         (default: view-0001.exr, ...)\n"
          "  any `valo render` option: --integrator, --res (default: the scene's, at most 640 wide),\n"
          "  --spp (where refining stops; default: never), --threads, --seed, --param, --exposure ...\n\n"
          "Mouse: left drag orbits, right or middle drag (or shift + left) pans, the wheel zooms.\n"
          "Keys:  W A S D move, Q E down and up; Tab / shift+Tab the next / previous integrator;\n"
          "       V the layer (image, albedo, normal, depth, ao); F the denoiser (on, off);\n"
          "       + and - the exposure by half a stop;\n"
          "       P saves the layer shown (EXR and PNG); C prints the camera as scene-file JSON;\n"
          "       R restarts; H hides the overlay; Esc quits.\n",
          realtime_params);
}

#ifndef VALO_HAVE_SDL2
int cmd_view(int argc, char **argv) {
  for (int i = 0; i < argc; i++)
    if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) { usage_view(stdout); return 0; }
  fprintf(stderr, "valo: error: this valo was built without SDL2, so it has no viewer (install libsdl2-dev and rebuild)\n");
  return 1;
}
#else
#include "cli/view_draw.h"
#include <SDL.h>
#include <pthread.h>
#include <time.h>

static const char *const layer_names[VIEW_LAYER_COUNT] = {"", "albedo", "normal", "depth", "ao"};

/* The render thread's mailbox: a posted step's inputs, a finished one's results. */
typedef struct worker {
  pthread_mutex_t mu;
  pthread_cond_t cv;
  int posted, busy, done, quit;
  int set_cam, n, restart;   /* in */
  valo_camera cam;
  view_layer layer;
  int denoise;               /* the image through valo_render_denoise_live */
  valo_status st;            /* out: the first failure, and whether it was the camera's */
  int cam_refused;
  valo_error err;
  double dt;
  int spp_done;
  float *back;               /* the finished step's layer, width*height*3 */
} worker;

typedef struct viewer {
  valo_scene *sc;
  valo_options base;       /* the options every render is made with, but the integrator and aovs */
  valo_output_options oo;
  valo_render *r;
  const char *const *integ; /* valo_integrator_names() */
  int ninteg, cur;
  int image_wide;          /* the current integrator is restir-di or restir-gi: real time */
  valo_camera cam;
  int dirty;               /* the camera moved: the next step restarts */
  view_layer layer;
  int aovs;                /* the current render records AOVs (with ao) */
  int denoise;             /* the image is shown denoised (F) */
  int shown_denoised;      /* the image in px was */
  int w, h, scale, overlay, quit, redraw;
  int step_spp, spp_cap, spp_done;
  int step_n, step_restart, step_cam; /* the step posted last */
  view_layer shown_layer;    /* the layer in px */
  worker wk;
  float *px;                 /* the layer shown */
  unsigned char *rgb8;
  double sps, fps, msg_until;
  int frame;               /* frames (real time) or steps since the camera last moved */
  char msg[160];
  const char *save_stem;
  int saves;
  SDL_Window *win;
  SDL_Renderer *ren;
  SDL_Texture *tex;
} viewer;


static void say(viewer *v, const char *m) {
  snprintf(v->msg, sizeof v->msg, "%s", m);
  v->msg_until = cli_now() + 3;
  fprintf(stderr, "valo: %s\n", m);
}

static void wait_idle(viewer *v);
/* (Re)creates the render for integrator v->cur and layer v->layer, keeping the camera;
 * on failure the current render stays as it was. */
static int make_render(viewer *v) {
  wait_idle(v);
  valo_options o = v->base;
  snprintf(o.integrator, sizeof o.integrator, "%s", v->integ[v->cur]);
  int image_wide = !strncmp(o.integrator, "restir", 6);
  view_layer layer = image_wide ? VIEW_LAYER_IMAGE : v->layer;
  /* the denoiser reads albedo, normal and depth, and per-ray integrators' sample variance */
  o.aovs = layer != VIEW_LAYER_IMAGE ? 1 | VALO_AOVS_AO | VALO_AOVS_VARIANCE : v->denoise ? (image_wide ? 1 : 1 | VALO_AOVS_VARIANCE) : VALO_UNSET;
  valo_error err;
  valo_render *r = NULL;
  if (valo_render_create(v->sc, &o, &r, &err)) {
    char m[1200];
    snprintf(m, sizeof m, "%s: %s", v->integ[v->cur], err.message);
    say(v, m);
    return 1;
  }
  if (v->r) {
    if (valo_render_set_camera(r, &v->cam, &err)) { valo_render_destroy(r); say(v, err.message); return 1; }
    valo_render_destroy(v->r);
  } else {
    valo_render_camera(r, &v->cam);
  }
  v->r = r;
  v->image_wide = image_wide;
  v->layer = layer;
  v->aovs = o.aovs != VALO_UNSET;
  v->dirty = 1;
  return 0;
}

static void v3d_sub(const double *a, const double *b, double *o) { for (int k = 0; k < 3; k++) o[k] = a[k] - b[k]; }
static double v3d_dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void v3d_cross(const double *a, const double *b, double *o) {
  o[0] = a[1] * b[2] - a[2] * b[1];
  o[1] = a[2] * b[0] - a[0] * b[2];
  o[2] = a[0] * b[1] - a[1] * b[0];
}
static double v3d_norm(double *a) {
  double l = sqrt(v3d_dot(a, a));
  if (l > 0) for (int k = 0; k < 3; k++) a[k] /= l;
  return l;
}
/* Rotates a about the unit axis k by angle t (Rodrigues). */
static void v3d_rotate(double *a, const double *k, double t) {
  double c = cos(t), s = sin(t), kxa[3], d = v3d_dot(k, a);
  v3d_cross(k, a, kxa);
  for (int i = 0; i < 3; i++) a[i] = a[i] * c + kxa[i] * s + k[i] * d * (1 - c);
}

/* The camera's frame: unit forward, right and up, and the distance to the look-at point. */
static double cam_frame(const valo_camera *c, double *fwd, double *right, double *up) {
  v3d_sub(c->look_at, c->pos, fwd);
  double dist = v3d_norm(fwd);
  double wu[3] = {c->up[0], c->up[1], c->up[2]};
  v3d_cross(fwd, wu, right);
  v3d_norm(right);
  v3d_cross(right, fwd, up);
  return dist;
}

/* Orbits the camera about its look-at point: yaw about the up vector, pitch about the
 * right vector, stopping short of looking straight along up. */
static void cam_orbit(valo_camera *c, double yaw, double pitch) {
  double fwd[3], right[3], up[3], off[3], wu[3] = {c->up[0], c->up[1], c->up[2]};
  cam_frame(c, fwd, right, up);
  v3d_norm(wu);
  v3d_sub(c->pos, c->look_at, off);
  v3d_rotate(off, wu, yaw);
  v3d_rotate(right, wu, yaw);
  double keep[3] = {off[0], off[1], off[2]};
  v3d_rotate(off, right, pitch);
  double o[3] = {off[0], off[1], off[2]};
  v3d_norm(o);
  if (fabs(v3d_dot(o, wu)) > 0.995) memcpy(off, keep, sizeof off);
  for (int k = 0; k < 3; k++) c->pos[k] = c->look_at[k] + off[k];
}

/* Moves camera and look-at point together by a*right + b*up + f*forward, in units of the
 * distance between them. */
static void cam_move(valo_camera *c, double a, double b, double f) {
  double fwd[3], right[3], up[3];
  double dist = cam_frame(c, fwd, right, up);
  for (int k = 0; k < 3; k++) {
    double d = (a * right[k] + b * up[k] + f * fwd[k]) * dist;
    c->pos[k] += d;
    c->look_at[k] += d;
  }
}

/* Moves the camera toward its look-at point (factor < 1) or away; an orthographic
 * camera's view, which distance does not change, grows or shrinks by the same factor. */
static void cam_zoom(valo_camera *c, double factor) {
  double fwd[3], right[3], up[3];
  double dist = cam_frame(c, fwd, right, up) * factor;
  if (!(dist > 1e-6)) return;
  for (int k = 0; k < 3; k++) c->pos[k] = c->look_at[k] - fwd[k] * dist;
  if (c->ortho_height > 0 && c->ortho_height * factor > 1e-6) c->ortho_height *= factor;
}

static void print_camera(const valo_camera *c) {
  char size[64];
  if (c->spherical) snprintf(size, sizeof size, "\"type\": \"spherical\"");
  else if (c->ortho_height > 0) snprintf(size, sizeof size, "\"type\": \"orthographic\", \"height\": %.6g", c->ortho_height);
  else snprintf(size, sizeof size, "\"fov\": %.6g", c->fov_deg);
  printf("\"camera\": {\"position\": [%.6g, %.6g, %.6g], \"look_at\": [%.6g, %.6g, %.6g], \"up\": [%.6g, %.6g, %.6g], %s}\n",
         c->pos[0], c->pos[1], c->pos[2], c->look_at[0], c->look_at[1], c->look_at[2], c->up[0], c->up[1], c->up[2], size);
  fflush(stdout);
}

/* The save key: the layer shown (the denoised image as shown) as STEM-NNNN.exr and .png
 * (the PNG through the exposure). */
static void save(viewer *v) {
  wait_idle(v);
  char stem[1024], names[2][1100];
  snprintf(stem, sizeof stem, "%s", v->save_stem);
  char *dot = strrchr(stem, '.'), *slash = strrchr(stem, '/');
  if (dot && (!slash || dot > slash)) *dot = 0;
  v->saves++;
  valo_error err;
  for (int k = 0; k < 2; k++) {
    snprintf(names[k], sizeof names[k], "%s%s%s-%04d.%s", layer_names[v->layer], *layer_names[v->layer] ? ":" : "", stem, v->saves, k ? "png" : "exr");
    valo_status st = v->shown_denoised ? valo_image_write(names[k], v->w, v->h, v->px, &v->oo, &err) : valo_render_write(v->r, names[k], &v->oo, &err);
    if (st) { say(v, err.message); return; }
  }
  char m[160];
  snprintf(m, sizeof m, "saved %s-%04d.exr and .png", stem, v->saves);
  say(v, m);
  print_camera(&v->cam);
}

static void handle_key(viewer *v, const SDL_KeyboardEvent *k) {
  int shift = (k->keysym.mod & KMOD_SHIFT) != 0;
  const double step = 0.05;
  switch (k->keysym.sym) {
    case SDLK_ESCAPE: v->quit = 1; break;
    case SDLK_w: cam_move(&v->cam, 0, 0, step); v->dirty = 1; break;
    case SDLK_s: cam_move(&v->cam, 0, 0, -step); v->dirty = 1; break;
    case SDLK_a: cam_move(&v->cam, -step, 0, 0); v->dirty = 1; break;
    case SDLK_d: cam_move(&v->cam, step, 0, 0); v->dirty = 1; break;
    case SDLK_q: cam_move(&v->cam, 0, -step, 0); v->dirty = 1; break;
    case SDLK_e: cam_move(&v->cam, 0, step, 0); v->dirty = 1; break;
    case SDLK_r: v->dirty = 1; break;
    case SDLK_h: v->overlay = !v->overlay; break;
    case SDLK_c: print_camera(&v->cam); break;
    case SDLK_p: save(v); break;
    case SDLK_PLUS: case SDLK_EQUALS: case SDLK_KP_PLUS: v->oo.exposure += 0.5f; break;
    case SDLK_MINUS: case SDLK_KP_MINUS: v->oo.exposure -= 0.5f; break;
    case SDLK_TAB: {
      int was = v->cur;
      v->cur = (v->cur + (shift ? v->ninteg - 1 : 1)) % v->ninteg;
      if (make_render(v)) v->cur = was;
      break;
    }
    case SDLK_v: {
      if (v->image_wide) { say(v, "restir-di and restir-gi: the viewer shows their image only"); break; }
      view_layer was = v->layer;
      v->layer = (view_layer)((v->layer + 1) % VIEW_LAYER_COUNT);
      if (v->layer != VIEW_LAYER_IMAGE && was == VIEW_LAYER_IMAGE && make_render(v)) v->layer = was; /* the ao AOV too */
      break;
    }
    case SDLK_f:
      v->denoise = !v->denoise;
      if (v->denoise && !v->aovs && make_render(v)) v->denoise = 0;
      v->dirty = 1;
      say(v, v->denoise ? "denoiser on" : "denoiser off: the raw image");
      break;
    default: break;
  }
}

static void handle_events(viewer *v) {
  SDL_Event e;
  while (SDL_PollEvent(&e)) {
    v->redraw = 1;
    if (e.type == SDL_QUIT) v->quit = 1;
    else if (e.type == SDL_KEYDOWN) handle_key(v, &e.key);
    else if (e.type == SDL_MOUSEWHEEL && e.wheel.y) { cam_zoom(&v->cam, pow(0.9, e.wheel.y)); v->dirty = 1; }
    else if (e.type == SDL_MOUSEMOTION && e.motion.state) {
      int pan = (e.motion.state & (SDL_BUTTON_RMASK | SDL_BUTTON_MMASK)) || (SDL_GetModState() & KMOD_SHIFT);
      double wh = (double)v->h * v->scale;
      if (pan) {
        double fwd[3], right[3], up[3], dist = cam_frame(&v->cam, fwd, right, up);
        /* a pixel's width at the look-at point, in units of its distance (cam_move's) */
        double k = (v->cam.ortho_height > 0 ? v->cam.ortho_height / dist : 2 * tan(v->cam.fov_deg * M_PI / 360)) / wh;
        cam_move(&v->cam, -e.motion.xrel * k, e.motion.yrel * k, 0);
      } else {
        cam_orbit(&v->cam, -e.motion.xrel * 0.006, -e.motion.yrel * 0.006);
      }
      v->dirty = 1;
    }
  }
}

/* The render thread: runs each posted step (camera, step, the layer's pixels into
 * back) while the main thread shows the last one and reads input. */
static void *render_thread(void *arg) {
  viewer *v = arg;
  worker *w = &v->wk;
  pthread_mutex_lock(&w->mu);
  for (;;) {
    while (!w->posted && !w->quit) pthread_cond_wait(&w->cv, &w->mu);
    if (w->quit) break;
    w->posted = 0;
    pthread_mutex_unlock(&w->mu);
    valo_error err;
    valo_status st = VALO_OK;
    double t0 = cli_now();
    int refused = w->set_cam && valo_render_set_camera(v->r, &w->cam, &err);
    if (refused) st = err.status;
    /* with the denoiser, a restarted film takes new sample indices (independent noise for its history) */
    if (!st) st = valo_render_step(v->r, w->n, w->restart && w->denoise ? VALO_STEP_FRESH : w->restart, &err);
    double dt = cli_now() - t0;
    if (!st) st = w->layer == VIEW_LAYER_IMAGE && w->denoise ? valo_render_denoise_live(v->r, w->back, &err)
                                                             : valo_render_layer(v->r, layer_names[w->layer], w->back, &err);
    valo_stats vs;
    valo_render_stats(v->r, &vs);
    pthread_mutex_lock(&w->mu);
    w->st = st;
    w->cam_refused = refused;
    if (st) w->err = err;
    w->dt = dt;
    w->spp_done = vs.spp_done;
    w->busy = 0;
    w->done = 1;
    pthread_cond_broadcast(&w->cv);
  }
  pthread_mutex_unlock(&w->mu);
  return NULL;
}

/* Waits until no step runs (the render may then be changed, written or destroyed). */
static void wait_idle(viewer *v) {
  pthread_mutex_lock(&v->wk.mu);
  while (v->wk.busy) pthread_cond_wait(&v->wk.cv, &v->wk.mu);
  pthread_mutex_unlock(&v->wk.mu);
}

/* Posts the next step, if there is one: a new frame (real time, a moved camera, the
 * benchmark) or more samples on the film (until --spp). 0 when there was nothing to do. */
static int post_step(viewer *v, int benchmark) {
  worker *w = &v->wk;
  int restart = v->dirty || v->image_wide || benchmark;
  if (!restart && v->spp_done >= v->spp_cap) return 0;
  if (restart) v->step_spp = 1;
  int n = v->step_spp;
  if (!restart && v->spp_done + n > v->spp_cap) n = v->spp_cap - v->spp_done;
  pthread_mutex_lock(&w->mu);
  w->set_cam = v->dirty;
  w->cam = v->cam;
  w->n = n;
  w->restart = restart;
  w->layer = v->layer;
  w->denoise = v->denoise;
  w->posted = w->busy = 1;
  pthread_cond_broadcast(&w->cv);
  pthread_mutex_unlock(&w->mu);
  v->dirty = 0;
  v->step_n = n;
  v->step_restart = restart;
  v->step_cam = w->set_cam;
  return 1;
}

/* Takes a finished step's image and figures, if one finished: 1, else 0 (-1 on error). */
static int collect(viewer *v, int benchmark) {
  worker *w = &v->wk;
  pthread_mutex_lock(&w->mu);
  int done = w->done;
  w->done = 0;
  valo_status st = w->st;
  int cam_refused = w->cam_refused;
  valo_error err = w->err;
  double dt = w->dt;
  v->spp_done = w->spp_done;
  float *t = w->back;
  if (done && !st) { w->back = v->px; v->px = t; }
  pthread_mutex_unlock(&w->mu);
  if (!done) return 0;
  if (st) {
    say(v, err.message);
    if (cam_refused) { valo_render_camera(v->r, &v->cam); return 1; } /* back to the last good camera */
    return -1;
  }
  v->shown_layer = w->layer;
  v->shown_denoised = w->layer == VIEW_LAYER_IMAGE && w->denoise;
  /* frames (real time) or steps since the camera last moved */
  v->frame = (v->image_wide ? v->step_cam : v->step_restart) ? 1 : v->frame + 1;
  double sdt = dt > 1e-9 ? dt : 1e-9, sps = (double)v->w * v->h * v->step_n / sdt;
  v->sps = v->sps > 0 && !v->step_restart ? 0.7 * v->sps + 0.3 * sps : sps;
  v->fps = v->fps > 0 ? 0.8 * v->fps + 0.2 / sdt : 1 / sdt;
  /* per-ray integrators refine in steps of about 1/15 s, so input stays lively */
  if (!v->image_wide && !benchmark) {
    if (dt < 1.0 / 30 && v->step_spp < 64) v->step_spp *= 2;
    else if (dt > 1.0 / 8 && v->step_spp > 1) v->step_spp /= 2;
  }
  return 1;
}

static void show(viewer *v) {
  size_t np = (size_t)v->w * v->h;
  view_to_srgb8(v->px, np, v->shown_layer, v->shown_layer == VIEW_LAYER_IMAGE ? v->oo.exposure : 0, v->rgb8);
  SDL_UpdateTexture(v->tex, NULL, v->rgb8, v->w * 3);
  SDL_RenderClear(v->ren);
  SDL_RenderCopy(v->ren, v->tex, NULL, NULL);
  char l1[160], l2[160];
  if (v->image_wide)
    snprintf(l1, sizeof l1, "%s  frame %d  %.1f fps  %.2f msamples/s", v->integ[v->cur], v->frame, v->fps, v->sps * 1e-6);
  else
    snprintf(l1, sizeof l1, "%s  %d spp  %.2f msamples/s", v->integ[v->cur], v->spp_done, v->sps * 1e-6);
  snprintf(l2, sizeof l2, "%s%s  exposure %+.1f", v->shown_layer ? layer_names[v->shown_layer] : "image",
           v->shown_layer ? "" : v->shown_denoised ? " (denoised)" : " (raw)", (double)v->oo.exposure);
  const char *lines[3] = {l1, l2, v->msg};
  int fs = v->w * v->scale >= 480 ? 2 : 1;
  if (v->overlay) view_draw_panel(v->ren, 4, 4, fs, lines, cli_now() < v->msg_until ? 3 : 2);
  SDL_RenderPresent(v->ren);
  char title[200];
  snprintf(title, sizeof title, "valo view: %s", l1);
  SDL_SetWindowTitle(v->win, title);
}

static int open_window(viewer *v, int benchmark) {
  if (benchmark && !getenv("DISPLAY") && !getenv("WAYLAND_DISPLAY") && !getenv("SDL_VIDEODRIVER")) SDL_setenv("SDL_VIDEODRIVER", "dummy", 1);
  if (SDL_Init(SDL_INIT_VIDEO)) {
    fprintf(stderr, "valo: error: cannot open a window: %s (no display? --benchmark runs without one)\n", SDL_GetError());
    return 1;
  }
  const char *drv = SDL_GetCurrentVideoDriver();
  if (!benchmark && drv && (!strcmp(drv, "dummy") || !strcmp(drv, "offscreen") || !strcmp(drv, "evdev"))) {
    fprintf(stderr, "valo: error: cannot open a window: no display (SDL chose its \"%s\" driver; set DISPLAY, or use --benchmark)\n", drv);
    return 1;
  }
  v->scale = 640 / v->w; /* small films shown at least 640 wide, up to 4x */
  v->scale = v->scale < 1 ? 1 : v->scale > 4 ? 4 : v->scale;
  v->win = SDL_CreateWindow("valo view", SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, v->w * v->scale, v->h * v->scale, 0);
  if (v->win) v->ren = SDL_CreateRenderer(v->win, -1, SDL_RENDERER_SOFTWARE);
  if (v->ren) v->tex = SDL_CreateTexture(v->ren, SDL_PIXELFORMAT_RGB24, SDL_TEXTUREACCESS_STREAMING, v->w, v->h);
  if (!v->tex) { fprintf(stderr, "valo: error: cannot open a window: %s\n", SDL_GetError()); return 1; }
  return 0;
}

int cmd_view(int argc, char **argv) {
  static const char *const own[] = {"-o", "--output", "--benchmark", NULL};
  const char *val[3] = {NULL, NULL, NULL};
  int no_denoise = 0;
  for (int i = 0; i < argc; i++) /* view's own flag, taken out before the render options */
    if (!strcmp(argv[i], "--no-denoise")) {
      no_denoise = 1;
      memmove(&argv[i], &argv[i + 1], (size_t)(argc - i - 1) * sizeof *argv);
      argc--;
      i--;
    }
  cli_args ca;
  int prc = cli_parse_with_own(argc, argv, own, val, &ca, stderr);
  if (prc == CLI_HELP) { usage_view(stdout); return 0; }
  if (prc >= 0) return prc;
  const char *out = val[0] ? val[0] : val[1];
  long bench = 0;
  if (val[2]) {
    char *end;
    bench = strtol(val[2], &end, 10);
    if (end == val[2] || *end || bench < 1 || bench > 1000000) {
      fprintf(stderr, "valo: --benchmark: \"%s\" is not a number of frames from 1 to 1000000\n", val[2]);
      return EXIT_USAGE;
    }
  }
  int rc = 0;
  if (ca.opt.frames != VALO_UNSET || ca.opt.adaptive > 0 || ca.ckpt || ca.resume || ca.stats_json) {
    fprintf(stderr, "valo: view renders a still camera that moves: --frames, --adaptive, --noise-threshold, --checkpoint, --resume and --stats-json are for valo render\n");
    return EXIT_USAGE;
  }
  viewer v;
  memset(&v, 0, sizeof v);
  pthread_mutex_init(&v.wk.mu, NULL);
  pthread_cond_init(&v.wk.cv, NULL);
  v.oo = ca.oo;
  v.overlay = 1;
  v.denoise = !no_denoise;
  v.save_stem = out ? out : "view";
  valo_error err;
  if (valo_scene_load_with(ca.scene_path, &ca.lo, &v.sc, &err)) { fprintf(stderr, "valo: error: %s\n", err.message); return 1; }
  valo_options fo;
  valo_scene_file_options(v.sc, &fo);
  v.base = ca.opt;
  if (v.base.width == VALO_UNSET) {
    /* the scene's size (256x256 by default), at most 640 wide */
    int w = fo.width != VALO_UNSET ? fo.width : 256, h = fo.height != VALO_UNSET ? fo.height : 256;
    if (w > 640) { h = (int)((double)h * 640 / w + 0.5); w = 640; }
    v.base.width = w;
    v.base.height = h > 0 ? h : 1;
  }
  v.spp_cap = ca.opt.spp != VALO_UNSET ? ca.opt.spp : 1048576;
  v.base.spp = v.spp_cap;
  v.base.time_budget = VALO_UNSET;
  char params[sizeof v.base.params];
  snprintf(params, sizeof params, "%s %s", realtime_params, ca.opt.params);
  snprintf(v.base.params, sizeof v.base.params, "%s", params);
  v.integ = valo_integrator_names();
  const char *want = ca.opt.integrator[0] ? ca.opt.integrator : fo.integrator[0] ? fo.integrator : "path";
  for (v.ninteg = 0; v.integ[v.ninteg]; v.ninteg++)
    if (!strcmp(v.integ[v.ninteg], want)) v.cur = v.ninteg;
  v.w = v.base.width;
  v.h = v.base.height;
  v.px = malloc((size_t)v.w * v.h * 3 * sizeof *v.px);
  v.rgb8 = malloc((size_t)v.w * v.h * 3);
  if (!v.px || !v.rgb8) { fprintf(stderr, "valo: error: out of memory\n"); rc = 1; }
  if (!rc && make_render(&v)) rc = 1;
  if (!rc && open_window(&v, bench > 0)) rc = 1;
  if (!rc && !bench) fprintf(stderr, "valo: view: %s, %dx%d, %d triangles (keys: valo view --help)\n", ca.scene_path, v.w, v.h, (int)valo_scene_triangle_count(v.sc));
  pthread_t th;
  int started = 0;
  if (!rc) {
    started = !(v.wk.back = malloc((size_t)v.w * v.h * 3 * sizeof *v.px)) ? 0 : !pthread_create(&th, NULL, render_thread, &v);
    if (!started) { fprintf(stderr, "valo: error: cannot start the render thread\n"); rc = 1; }
  }
  double t0 = cli_now();
  long frames = 0;
  int running = !rc && post_step(&v, bench > 0);
  while (!rc && !v.quit) {
    handle_events(&v);
    if (v.quit) break;
    int c = collect(&v, bench > 0);
    if (c < 0) { rc = 1; break; }
    if (c > 0) {
      frames++;
      if (bench && frames >= bench) { running = 0; show(&v); break; }
      running = post_step(&v, bench > 0); /* the next step renders while this one is shown */
      show(&v);
      v.redraw = 0;
    } else if (!running) {
      /* refined to --spp: wait for input */
      if (v.dirty) running = post_step(&v, 0);
      else { show(&v); SDL_WaitEventTimeout(NULL, 50); }
    } else {
      if (v.redraw) { show(&v); v.redraw = 0; }
      struct timespec until;
      clock_gettime(CLOCK_REALTIME, &until);
      until.tv_nsec += 4000000;
      if (until.tv_nsec >= 1000000000) { until.tv_sec++; until.tv_nsec -= 1000000000; }
      pthread_mutex_lock(&v.wk.mu);
      if (!v.wk.done) pthread_cond_timedwait(&v.wk.cv, &v.wk.mu, &until);
      pthread_mutex_unlock(&v.wk.mu);
    }
  }
  if (started) {
    wait_idle(&v);
    pthread_mutex_lock(&v.wk.mu);
    v.wk.quit = 1;
    pthread_cond_broadcast(&v.wk.cv);
    pthread_mutex_unlock(&v.wk.mu);
    pthread_join(th, NULL);
  }
  if (!rc && bench) {
    double el = cli_now() - t0;
    /* the frame as shown: the denoised image, or the render's own */
    valo_status wst = !out ? VALO_OK : v.shown_denoised ? valo_image_write(out, v.w, v.h, v.px, &v.oo, &err) : valo_render_write(v.r, out, &v.oo, &err);
    if (wst) { fprintf(stderr, "valo: error: %s\n", err.message); rc = 1; }
    if (!rc) printf("fps %.2f\n", (double)bench / el);
  }
  free(v.wk.back);
  valo_render_destroy(v.r);
  valo_scene_destroy(v.sc);
  free(v.px);
  free(v.rgb8);
  if (v.tex) SDL_DestroyTexture(v.tex);
  if (v.ren) SDL_DestroyRenderer(v.ren);
  if (v.win) SDL_DestroyWindow(v.win);
  SDL_Quit();
  return rc;
}
#endif
