/* texture.h — owns image textures: loading (PNG/JPEG/TGA/BMP through stb, 8-bit colour
 * decoded from sRGB, data maps kept linear; HDR/EXR/PFM as linear float; images embedded
 * in glTF-binary files from memory), the checkerboard, and lookup: an optional affine map
 * of the texture coordinates, then bilinear or nearest filtering with repeat, mirror or
 * clamp wrapping. Texture coordinates follow OpenGL (v = 0 at the bottom row), which is
 * what Assimp delivers for every format. Texels are RGBA float; images without alpha get 1. */
#ifndef VALO_TEXTURE_H
#define VALO_TEXTURE_H
#include "core/vec.h"
#include "valo/valo.h"

typedef enum tex_wrap { TEX_REPEAT, TEX_CLAMP, TEX_MIRROR } tex_wrap;
typedef enum tex_filter { TEX_BILINEAR, TEX_NEAREST } tex_filter;
/* How a texture is looked up. */
typedef struct tex_sampling {
  tex_wrap wrap;
  tex_filter filter;
  int has_uvm;      /* 1: (u, v) becomes (uvm[0] u + uvm[1] v + uvm[2], uvm[3] u + uvm[4] v + uvm[5]) */
  float uvm[6];
} tex_sampling;

typedef struct texture {
  int w, h;
  int has_alpha;
  float *px;        /* w*h*4, row 0 = top of the image */
  tex_sampling smp;
  int shares_px;    /* px belongs to another texture (the same image sampled another way) */
  char key[512];    /* path (or embedded id) + colour space (+ sampling), for sharing */
} texture;

/* srgb: decode 8-bit values from sRGB (colour maps) or keep them linear (data maps). */
valo_status texture_load_file(texture *t, const char *path, int srgb, valo_error *err);
/* The same, saying "PATH: cannot read WHAT: reason" when the file cannot be decoded
 * (texture_load_file's WHAT is "texture"). */
valo_status texture_load_file_as(texture *t, const char *path, int srgb, const char *what, valo_error *err);
valo_status texture_load_memory(texture *t, const unsigned char *data, size_t len, const char *name, int srgb, valo_error *err);
/* Mitsuba's checkerboard as a 2x2 image looked up nearest: c0 in its top-left and
 * bottom-right texels, c1 in the others. */
valo_status texture_checkerboard(texture *t, const float c0[3], const float c1[3], valo_error *err);
void texture_free(texture *t);
/* RGBA at (u, v), sampled as t->smp says. */
void texture_lookup(const texture *t, float u, float v, float out[4]);
/* The derivatives with respect to u and v of the bilinear lookup of w[0] r + w[1] g +
 * w[2] b at (u, v), within the texel cell holding it, through the map of the texture
 * coordinates (as Mitsuba's bitmap eval_1_grad); 0 for a nearest lookup. */
void texture_gradient(const texture *t, float u, float v, const float w[3], float *du, float *dv);
/* The texel (x, y) itself (x right, y down from the top row). */
void texture_texel(const texture *t, int x, int y, float out[4]);
#endif
