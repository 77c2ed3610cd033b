/* view_draw.h — what `valo view` draws besides SDL itself (view_draw.c). Built only with
 * SDL2. */
#ifndef VALO_CLI_VIEW_DRAW_H
#define VALO_CLI_VIEW_DRAW_H
#include <SDL.h>
#include <stddef.h>

/* The layers the viewer shows, in the order its V key steps through them; the names are
 * valo_render_layer's. */
typedef enum view_layer { VIEW_LAYER_IMAGE, VIEW_LAYER_ALBEDO, VIEW_LAYER_NORMAL, VIEW_LAYER_DEPTH, VIEW_LAYER_AO, VIEW_LAYER_COUNT } view_layer;

/* np linear RGB pixels of a layer into 8-bit RGB for the screen: the image scaled by
 * 2^exposure, clamped and sRGB-encoded; albedo and ao sRGB-encoded; normals as n/2 + 1/2
 * and depth divided by its largest value, stored linearly. */
void view_to_srgb8(const float *px, size_t np, view_layer layer, float exposure, unsigned char *out);
/* Text at (x, y) in the current draw colour, each font pixel scale x scale. */
void view_draw_text(SDL_Renderer *ren, int x, int y, int scale, const char *s);
int view_text_width(const char *s, int scale);
/* n lines of white text on a translucent black panel whose top-left corner is (x, y). */
void view_draw_panel(SDL_Renderer *ren, int x, int y, int scale, const char *const *lines, int n);
#endif
