/* gltf_check_internal.h — owns what the glTF check's files share (gltf_check.c: the
 * container, buffers, views, accessors and meshes; gltf_objects.c: nodes, materials and
 * the other objects; gltf_dequant.c: integer attributes given to Assimp as floats;
 * gltf_draco.c: Draco-compressed primitives): the check's state, the parsed views and accessors, and the helpers
 * that read members as counts and indices with messages naming the object. */
#ifndef VALO_GLTF_CHECK_INTERNAL_H
#define VALO_GLTF_CHECK_INTERNAL_H
#include "load/gltf_check.h"
#include "load/gltf_json.h"
#include <stdint.h>

#define GLB_JSON 0x4E4F534Au /* a .glb's chunk types */
#define GLB_BIN 0x004E4942u
#define GLTF_MAX_NODE_DEPTH 1024 /* Assimp and valo walk the node tree recursively */

typedef struct gbuf { const unsigned char *data; uint64_t len; } gbuf; /* a buffer's bytes as read */
typedef struct gview { uint32_t buf; uint64_t off, len, stride; } gview;
typedef struct gacc {
  int64_t view;
  uint64_t off, count, size, stride;
  int ctype, comps, sparse, normalized;
  const unsigned char *sparse_values; /* a sparse part's values (sparse_n elements of size bytes) */
  const unsigned char *sparse_index;  /* and their indices (sparse_isize bytes each) */
  uint64_t sparse_n;
  int sparse_isize;
} gacc;

/* The top-level arrays the check reads, in this order (gltf_check.c, kinds[]). */
enum { K_BUF, K_VIEW, K_ACC, K_MESH, K_NODE, K_SCENE, K_MAT, K_TEX, K_IMG, K_SMP, K_CAM, K_SKIN, K_ANIM, K_KINDS };

typedef struct gc {
  const char *path;
  valo_error *err;
  obj_check *oc;
  jdoc d;
  const unsigned char *bin;
  uint64_t bin_len;
  int has_bin;
  uint32_t arr[K_KINDS], n[K_KINDS]; /* each top-level array (0 when absent) and its length */
  uint32_t lights, n_light;          /* KHR_lights_punctual's array of lights and its length */
  gbuf *bufs;
  gview *views;
  gacc *accs;
  unsigned char *decoded[64];
  int ndecoded;
  int drop_skins; /* a skin has no inverseBindMatrices: Assimp is given none (gltf_check_file) */
  unsigned char *deq; /* per accessor: 1 when it is a mesh attribute of integers that Assimp
                         must be given as floats, 2 for Draco indices it must be given as
                         unsigned shorts (gl_dequantize) */
  int ndeq;
  unsigned char *draco; /* per accessor: 1 when a KHR_draco_mesh_compression primitive feeds it */
} gc;

static inline const jnode *N(const gc *g, uint32_t i) { return &g->d.nodes[i]; }
/* Sets the error "path: glTF: message"; returns its status. */
valo_status gl_bad(gc *g, const char *fmt, ...);
/* Array member key of o, every entry an object: its count, or -1 (error set). */
int64_t gl_objects(gc *g, uint32_t o, const char *key, const char *what);
/* fn(g, entry, its index, "KIND INDEX") for each entry of array arr, until an error. */
valo_status gl_each(gc *g, uint32_t arr, const char *kind, valo_status (*fn)(gc *, uint32_t, uint32_t, const char *));
/* Member key of o as a whole number (written as one) up to max: 0 (*v = def when absent;
 * an error when required and absent), or -1 (error set). */
int gl_uint(gc *g, uint32_t o, const char *key, uint64_t def, uint64_t max, int required, uint64_t *v, const char *ctx);
/* Member key of o as an index of `count` objects called `of`: -1 when absent (an error
 * when required), -2 (error set) when it names none of them. */
int64_t gl_index(gc *g, uint32_t o, const char *key, uint32_t count, const char *of, int required, const char *ctx);
/* Every element of array member key of o such an index: 0, or -1 (error set). */
int gl_index_array(gc *g, uint32_t o, const char *key, uint32_t count, const char *of, const char *ctx);
int64_t gl_accessor_ref(gc *g, uint32_t o, const char *key, int required, const char *ctx);
/* The little-endian unsigned integer of `bytes` bytes (1, 2 or 4) at p. */
uint32_t gl_le_uint(const unsigned char *p, uint64_t bytes);
/* A data URI "data:TYPE/SUBTYPE;base64,DATA" decoded into g->decoded: its length, or -1. */
int64_t gl_data_uri(gc *g, const char *s, const char *ctx);

/* gltf_objects.c: the nodes (trees of valid references, bounded depth), then scenes,
 * materials, textures, images, cameras, skins, animations and KHR_lights_punctual lights. */
valo_status gl_check_nodes(gc *g);
valo_status gl_check_objects(gc *g);

/* gltf_draco.c: KHR_draco_mesh_compression. gl_draco_mark, before the accessors are
 * checked, checks each primitive's extension object and marks the accessors it feeds;
 * gl_draco_indices marks a Draco primitive's 32-bit indices for Assimp as 16-bit ones
 * (nverts of them at most 65 536, else an error). */
valo_status gl_draco_mark(gc *g);
valo_status gl_draco_indices(gc *g, int64_t ix, uint64_t nverts, const char *ctx);

/* gltf_dequant.c: the accessors marked in g->deq (vertex positions, normals, tangents and
 * texture coordinates stored as integers, normalized or not: glTF's normalized texture
 * coordinates and KHR_mesh_quantization), which Assimp 5.2 reads as if they were floats,
 * decoded to floats in a new buffer served beside the file, and the JSON (text, or a .glb
 * around it) rewritten to point them there: oc->files[0] replaced, the buffer added. */
valo_status gl_dequantize(gc *g, const char *json, size_t json_len, int binary);
#endif
