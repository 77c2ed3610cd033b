/* image_io.h — owns image files: linear float EXR through OpenEXRCore (read and write),
 * PFM (read and write), Radiance HDR (read through hdr.c, written by stb_image_write),
 * and 8-bit sRGB PNG and JPEG written by stb_image_write. Every write goes through
 * atomicfile.h (a temporary file renamed over the target), so readers never see a
 * partial image. Pixels are RGB float, row-major, top row first. */
#ifndef VALO_IMAGE_IO_H
#define VALO_IMAGE_IO_H
#include "valo/valo.h"

typedef struct image { int w, h; float *rgb; } image;

valo_status image_write(const char *path, int w, int h, const float *px, const valo_output_options *o, valo_error *err);
/* Reads an EXR (any compression OpenEXR supports; half/float/uint; R,G,B or Y), PFM or
 * Radiance HDR. */
valo_status image_read(const char *path, image *out, valo_error *err);
/* 1 when path's extension is one image_read reads (.exr, .hdr, .pfm), else 0. */
int image_is_float_file(const char *path);
void image_free(image *im);
/* Display transform used for PNG: exposure, tone map, sRGB encode, 8-bit. */
void image_to_srgb8(int w, int h, const float *px, const valo_output_options *o, unsigned char *out);
#endif
