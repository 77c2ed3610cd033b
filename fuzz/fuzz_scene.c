/* fuzz_scene.c — owns the scene-file fuzz harness: the input is written as a scene file
 * and loaded through the public API (valo_scene_load), which checks it, reads it and
 * commits the scene. FUZZ_NAME (set by the build) picks the file name, and so the path
 * the loader takes: scene.json (the JSON loader), mesh.obj (valo's OBJ/MTL pre-reader,
 * then Assimp) or mesh.ply (valo's PLY check, then Assimp). */
#include "fuzz_util.h"

#ifndef FUZZ_NAME
#define FUZZ_NAME "scene.json"
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fuzz_quiet();
  const char *path = fuzz_file(FUZZ_NAME, data, size);
  if (!path) return 0;
  valo_scene *s = NULL;
  valo_error err;
  if (valo_scene_load(path, &s, &err) == VALO_OK) valo_scene_destroy(s);
  return 0;
}
