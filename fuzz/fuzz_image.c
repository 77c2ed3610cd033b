/* fuzz_image.c — owns the image-decoding fuzz harness: by its first bytes the input goes
 * to valo's Radiance HDR decoder ("#?"), the PFM reader ("PF"), OpenEXRCore through
 * valo's EXR reader (the EXR magic), the density-grid reader ("VOL", Mitsuba's .vol) or,
 * for anything else, stb_image through the texture loader (PNG, JPEG and the rest stb
 * reads). */
#include "fuzz_util.h"
#include "image/hdr.h"
#include "image/image_io.h"
#include "image/texture.h"
#include "scene/volume.h"
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fuzz_quiet();
  valo_error err;
  image im;
  memset(&im, 0, sizeof im);
  static const uint8_t exr_magic[4] = {0x76, 0x2f, 0x31, 0x01};
  if (size >= 2 && data[0] == '#' && data[1] == '?') {
    if (hdr_decode("fuzz.hdr", data, size, &im, &err) == VALO_OK) image_free(&im);
  } else if (size >= 4 && (!memcmp(data, exr_magic, 4) || (data[0] == 'P' && data[1] == 'F'))) {
    const char *path = fuzz_file(data[0] == 'P' ? "fuzz.pfm" : "fuzz.exr", data, size);
    if (path && image_read(path, &im, &err) == VALO_OK) image_free(&im);
  } else if (size >= 3 && !memcmp(data, "VOL", 3)) {
    const char *path = fuzz_file("fuzz.vol", data, size);
    density_grid *g;
    if (path && density_grid_load(path, &g, &err) == VALO_OK) {
      density_grid_at(g, v3(0.1f, 0.2f, 0.3f));
      density_grid_free(g);
    }
  } else {
    texture t;
    if (texture_load_memory(&t, data, size, "fuzz-image", 1, &err) == VALO_OK) texture_free(&t);
  }
  return 0;
}
