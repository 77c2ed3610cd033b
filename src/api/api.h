/* api.h — owns the definitions of the public handles (opaque in valo/valo.h), shared by
 * the files of src/api/. */
#ifndef VALO_API_API_H
#define VALO_API_API_H
#include "valo/valo.h"
#include "scene/scene.h"

struct valo_scene {
  scene *s;
  valo_options file_opts;  /* the render settings the file asked for */
  valo_log_fn warn_fn;     /* the load options' warning handler (renders of the scene
                              inherit it), or NULL */
  void *warn_user;
};
#endif
