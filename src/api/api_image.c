/* api_image.c — owns the public file functions: reading an EXR, PFM or HDR and writing
 * one (EXR, PFM, PNG) from float RGB, and writing any file as valo writes its images, for
 * tools built on valo (valo compare, --stats-json). */
#include "valo/valo.h"
#include "api/api.h"
#include "image/image_io.h"
#include "core/atomicfile.h"
#include "core/error.h"
#include <errno.h>
#include <stdlib.h>
#include <string.h>

VALO_API valo_status valo_image_read(const char *path, int *w, int *h, float **pixels, valo_error *err) {
  *pixels = NULL;
  *w = *h = 0;
  image im;
  valo_status st = image_read(path, &im, err);
  if (st) return st;
  *w = im.w;
  *h = im.h;
  *pixels = im.rgb;
  return VALO_OK;
}

VALO_API valo_status valo_image_write(const char *path, int w, int h, const float *pixels, const valo_output_options *o, valo_error *err) {
  valo_output_options d;
  if (!o) { valo_output_options_init(&d); o = &d; }
  return image_write(path, w, h, pixels, o, err);
}

VALO_API void valo_image_free(float *pixels) { free(pixels); }

VALO_API valo_status valo_file_write(const char *path, const void *data, size_t n, valo_error *err) {
  if (atomic_write(path, data, n)) return err_set(err, VALO_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
  return VALO_OK;
}
