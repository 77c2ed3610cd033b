/* mitsuba_internal.h — owns what the Mitsuba XML reader's files share: the translation
 * context and the typed property readers, each error naming the file and the line. The
 * reader translates a Mitsuba scene into valo's JSON scene format (a cJSON tree) and
 * hands it to the JSON loader, so both formats mean the same thing by construction. */
#ifndef VALO_MITSUBA_INTERNAL_H
#define VALO_MITSUBA_INTERNAL_H
#include "load/xml.h"
#include "core/vec.h"
#include "core/strmap.h"
#include <cjson/cJSON.h>

typedef struct mctx {
  const char *path;
  const char *defines; /* the command line's NAME=VALUE ... (replacing <default> values) */
  valo_error *err;
  xml_node *root;
  cJSON *out, *materials, *shapes, *lights, *media;
  const xml_node **shape_at; /* the XML element of each valo shape (error messages) */
  const xml_node **light_at;
  int nshape_at, nlight_at;
  char **included; /* the <include>d files' paths (xml_node.file points at them) */
  int nincluded;
  size_t included_bytes;    /* read through <include>s so far (MI_INCLUDE_BYTES) */
  size_t substituted_bytes; /* attribute text made by $name substitution (MI_SUBST_BYTES) */
  struct mi_id *ids;        /* every element with an id, sorted by id (mi_find_id) */
  int nids;
  const xml_node **bsdf_stack; /* the BSDFs being translated, outermost first (cycles) */
  int nbsdf_stack;
  long bsdf_work;              /* BSDF translations so far (MI_BSDF_WORK) */
  char **search;   /* the folders <path> elements gave, absolute, in document order */
  int nsearch;
  char **found;    /* file names found in those folders (mi_found), absolute */
  int nfound;
  const double *outer; /* while a shapegroup's shapes are read for an instance: its to_world */
  int quiet;           /* no warnings (an instance after a shapegroup's first) */
  struct { const char *id; char name[192]; } *bsdf_names; /* materials made from bsdfs with an id */
  int nbsdf_names;
  strmap bsdf_ids;       /* their ids -> index in bsdf_names */
  strmap material_names; /* the names in "materials" (keys borrowed from its items) */
  int twosided;      /* > 0 inside a twosided BSDF: what is translated there scatters from both sides */
  int vertex_color;  /* set by mi_color (MI_VERTEX) when a colour is the mesh's vertex colours */
} mctx;

/* Bounds that keep a small file from expanding without end, each refused with the line
 * that crosses it: bytes read through <include>s in all (a file included many times
 * counts each time), attribute bytes made by $name substitution in all, BSDFs nested
 * through <ref>s, and BSDF translations in all (a chain of twosided or blend BSDFs that
 * refer to the same next one twice doubles at each link). */
#define MI_INCLUDE_BYTES (64u << 20)
#define MI_SUBST_BYTES (16u << 20)
#define MI_BSDF_DEPTH 32
#define MI_BSDF_WORK 200000

/* The document before its elements are read (load_mitsuba_doc.c): the root is <scene>,
 * 0.6 names upgraded, <include>s spliced in, <default>s (and --define) substituted for
 * $name, every <ref> checked to name an element. */
valo_status mi_document_prepare(mctx *c);
/* "file:line: <tag name="..">: what" */
valo_status mi_bad(mctx *c, const xml_node *n, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
void mi_warn(mctx *c, const xml_node *n, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* The file n was read from: the scene file's path, or an included file's. */
const char *mi_file(const mctx *c, const xml_node *n);
/* A file name as the scene gives it, resolved as Mitsuba's file resolver does: a relative
 * name in the folders of the <path> elements read so far, the last first, then in the main
 * scene file's folder (where every relative name starts, included files' too). Malloc'd,
 * NULL when out of memory. */
char *mi_resolve(const mctx *c, const char *name);
/* name (relative, or absolute: as it is) from the folder of file: malloc'd, NULL when out
 * of memory. */
char *mi_beside(const char *file, const char *name);
/* The name to give the JSON scene for a file the scene names (relative names there start
 * at the main file's folder): the absolute path when a <path> folder holds it (kept in c),
 * else the name as given. NULL when out of memory. */
const char *mi_found(mctx *c, const char *name);
/* r = a b (4x4, row-major; r may be a or b). */
void mi_mat_mul(double r[16], const double a[16], const double b[16]);
/* Where n is, for names of the materials and media made from unnamed elements: "line12",
 * or "part.xml:line12" in an included file (so two files' line 12 are told apart). */
const char *mi_where(const mctx *c, const xml_node *n, char *buf, size_t len);
/* mi_where and the column: a name no other element of the files shares (an anonymous
 * material's, a medium's). */
const char *mi_place(const mctx *c, const xml_node *n, char *buf, size_t len);
/* The node with id (any tag but <ref>), the first in document order, or NULL; from the
 * index that mi_index_ids makes of the prepared document (a walk of the tree before). */
xml_node *mi_find_id(mctx *c, const char *id);
valo_status mi_index_ids(mctx *c);
/* The property child named `name` of plugin p (marked used), following a <ref name=..>
 * to its target; NULL when absent. */
xml_node *mi_prop(mctx *c, xml_node *p, const char *name);
/* Typed properties: absent leaves *out as it is; present of the wrong kind is an error. */
valo_status mi_float(mctx *c, xml_node *p, const char *name, double *out);
valo_status mi_int(mctx *c, xml_node *p, const char *name, int *out);
valo_status mi_bool(mctx *c, xml_node *p, const char *name, int *out);
valo_status mi_string(mctx *c, xml_node *p, const char *name, const char **out);
valo_status mi_point(mctx *c, xml_node *p, const char *name, vec3 *out);
/* A 4x4 transform (row-major) from a <transform name=..> child; identity when absent. */
valo_status mi_transform(mctx *c, xml_node *p, const char *name, double m[16], int *given);
/* A colour property as valo JSON: [r, g, b], or a texture object (a bitmap or a
 * checkerboard, with Mitsuba's raw, wrap_mode, filter_type and to_uv); *out stays NULL
 * when absent. how: MI_RGB_ONLY, a texture is an error; MI_EMITTER, an emitter's colour,
 * where Mitsuba reads a one-value <spectrum> as that much of the equal-energy spectrum
 * (a pinkish white in sRGB's D65 terms), not as grey; MI_SCALAR, a number Mitsuba reads
 * from a texture as its luminance, alpha ignored (the object gets "luminance"); MI_VERTEX,
 * a diffuse colour, where a mesh_attribute texture of the mesh's "vertex_color" is read as
 * [scale, scale, scale] and sets c->vertex_color (valo's vertex_colors over that colour). */
enum { MI_RGB_ONLY = 1, MI_EMITTER = 2, MI_SCALAR = 4, MI_VERTEX = 8 };
valo_status mi_color(mctx *c, xml_node *p, const char *name, int how, cJSON **out);
/* Parses up to n numbers separated by commas and/or spaces; returns how many. */
int mi_numbers(const char *s, double *v, int n);
/* The child plugins of p with this tag (bsdf, emitter, ...), following <ref> children
 * whose target has the tag; nth from 0; marks it used. */
xml_node *mi_child(mctx *c, xml_node *p, const char *tag, int nth);
/* Warns about p's children that nothing read (properties valo does not use). */
void mi_warn_unused(mctx *c, xml_node *p);

/* BSDFs, media and emitters (load_mitsuba_plugins.c). */
/* The name of the valo material for bsdf node b (made on first use); with an area
 * emitter's radiance `emit` (NULL: none) a material of its own. b NULL: Mitsuba's default
 * (diffuse 0.5). */
valo_status mi_material(mctx *c, xml_node *b, cJSON *emit, const xml_node *at, char *name, size_t n);
/* Adds the medium node m (once) to "media"; its name in *name. */
valo_status mi_medium(mctx *c, xml_node *m, char *name, size_t n);
/* A top-level emitter: a light or the environment. */
valo_status mi_emitter(mctx *c, xml_node *e);
#endif
