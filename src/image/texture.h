/* texture.h — owns image textures: loading (PNG/JPEG/TGA/BMP through stb, 8-bit colour
 * decoded from sRGB, data maps kept linear; HDR/EXR/PFM as linear float; images embedded
 * in glTF-binary files from memory), bilinear lookup with repeat, mirror or clamp
 * wrapping. Texture coordinates follow OpenGL (v = 0 at the bottom row), which is what
 * Assimp delivers for every format. Texels are RGBA float; images without alpha get 1. */
#ifndef VALO_TEXTURE_H
#define VALO_TEXTURE_H
#include "core/vec.h"
#include "valo/valo.h"

typedef enum tex_wrap { TEX_REPEAT, TEX_CLAMP, TEX_MIRROR } tex_wrap;
typedef struct texture {
  int w, h;
  int has_alpha;
  float *px;        /* w*h*4, row 0 = top of the image */
  tex_wrap wrap;
  char key[512];    /* path (or embedded id) + colour space, for sharing */
} texture;

/* srgb: decode 8-bit values from sRGB (colour maps) or keep them linear (data maps). */
valo_status texture_load_file(texture *t, const char *path, int srgb, valo_error *err);
/* The same, saying "PATH: cannot read WHAT: reason" when the file cannot be decoded
 * (texture_load_file's WHAT is "texture"). */
valo_status texture_load_file_as(texture *t, const char *path, int srgb, const char *what, valo_error *err);
valo_status texture_load_memory(texture *t, const unsigned char *data, size_t len, const char *name, int srgb, valo_error *err);
void texture_free(texture *t);
/* Bilinear RGBA at (u, v). */
void texture_lookup(const texture *t, float u, float v, float out[4]);
/* The texel (x, y) itself (x right, y down from the top row). */
void texture_texel(const texture *t, int x, int y, float out[4]);
#endif
