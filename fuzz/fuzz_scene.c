/* fuzz_scene.c — owns the scene-file fuzz harness: the input is written as a scene file
 * and loaded through the public API (valo_scene_load), which checks it, reads it and
 * commits the scene. FUZZ_NAME (set by the build) picks the file name, and so the path
 * the loader takes: scene.json (the JSON loader), scene.xml (the Mitsuba reader), mesh.obj (valo's OBJ/MTL pre-reader,
 * then Assimp), mesh.ply (valo's PLY check, then Assimp), mesh.gltf or mesh.glb (valo's
 * glTF check, then Assimp), mesh.serialized (Mitsuba's serialized meshes, every shape). With FUZZ_MTL the input is mesh.mtl, the material library of
 * a fixed OBJ that names it (valo's MTL reading, then Assimp's MTL reader, which a fuzzed
 * OBJ reaches only through a file already on disk). With FUZZ_OTHER the first byte picks a
 * format valo does not check (mesh.stl, .off, .dae, .x, .fbx, .3ds: the trial import in a
 * child process, import_probe.h, then Assimp and valo's conversion) and the rest is the
 * file; libFuzzer sees only the parent's code, so the child's crashes are not findings
 * (the child drops libFuzzer's death callback and signal handlers, which would keep each
 * as a crash file). */
#include "fuzz_util.h"
#ifdef FUZZ_OTHER
#include <pthread.h>
#include <signal.h>
#include <stddef.h>
void __sanitizer_set_death_callback(void (*callback)(void)) __attribute__((weak)); /* absent without the sanitizers */
static void child_keeps_nothing(void) {
  if (__sanitizer_set_death_callback) __sanitizer_set_death_callback(NULL);
  static const int faults[] = {SIGABRT, SIGILL, SIGFPE, SIGBUS}; /* libFuzzer's handlers keep crash files too */
  for (size_t i = 0; i < sizeof faults / sizeof faults[0]; i++) signal(faults[i], SIG_DFL);
}
#endif

#ifndef FUZZ_NAME
#define FUZZ_NAME "scene.json"
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fuzz_quiet();
#ifdef FUZZ_MTL
  static const char obj[] = "mtllib mesh.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
                            "usemtl m\nf 1/1/1 2/2/1 3/3/1\nusemtl light\nf 1/1/1 3/3/1 2/2/1\n";
  if (!fuzz_file(FUZZ_NAME, data, size)) return 0;
  const char *path = fuzz_file("mesh.obj", (const uint8_t *)obj, sizeof obj - 1);
#elif defined(FUZZ_OTHER)
  static int atfork;
  if (!atfork++) pthread_atfork(NULL, NULL, child_keeps_nothing);
  static const char *const names[] = {"mesh.stl", "mesh.off", "mesh.dae", "mesh.x", "mesh.fbx", "mesh.3ds"};
  if (size < 1) return 0;
  const char *path = fuzz_file(names[data[0] % (sizeof names / sizeof names[0])], data + 1, size - 1);
#else
  const char *path = fuzz_file(FUZZ_NAME, data, size);
#endif
  if (!path) return 0;
  valo_scene *s = NULL;
  valo_error err;
  if (valo_scene_load(path, &s, &err) == VALO_OK) valo_scene_destroy(s);
  return 0;
}
