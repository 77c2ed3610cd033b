/* hdr.h — owns Radiance HDR (RGBE) decoding: see hdr.c for what is read and why valo
 * reads it itself. */
#ifndef VALO_HDR_H
#define VALO_HDR_H
#include "image/image_io.h"
#include <stddef.h>

/* Decodes the n bytes at d (name is used in messages) into out (RGB float, top row
 * first; free with image_free). Returns VALO_OK or an error "name: what is wrong";
 * never reads past d + n and allocates only what the data can fill. */
valo_status hdr_decode(const char *name, const unsigned char *d, size_t n, image *out, valo_error *err);
/* Reads and decodes the file at path. */
valo_status hdr_read(const char *path, image *out, valo_error *err);
#endif
