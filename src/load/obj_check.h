/* obj_check.h — owns valo's own reading of OBJ and MTL text before Assimp parses it:
 * input checks with file:line messages in valo's words (faces that refer to missing
 * vertices, non-finite or incomplete vertices, a truncated last line), warnings for what
 * would otherwise vanish (faces with fewer than three vertices, line and point elements,
 * lines it does not understand, usemtl names no MTL defines, unreadable mtllib files),
 * repairs of valid text Assimp 5.2 misreads (numbers with a leading dot such as .8e-1;
 * MTL lines such as `aniso` that stop its MTL parser; MTL statements before the first
 * newmtl, dropped with a warning, since Assimp writes a texture there through a null
 * material; control bytes in MTL text as spaces and OBJ comments as blank lines, since
 * Assimp ends a line at NUL, form feed or a lone carriage return; indented lines without
 * their indent, since Assimp skips indented OBJ lines and a first MTL line whole), and the PBR extension of MTL
 * (Pr, Pm, map_Pr, map_Pm; Ps, Pc, Pcr, aniso noted as ignored), which valo reads itself.
 * The repaired texts are served to Assimp through its file-system callbacks, which open
 * no other file. */
#ifndef VALO_OBJ_CHECK_H
#define VALO_OBJ_CHECK_H
#include "valo/valo.h"
#include <stddef.h>
#include <stdint.h>

typedef struct mtl_pbr {
  char name[64];
  int has_pr, has_pm;
  float pr, pm;                 /* MTL Pr (roughness) and Pm (metallic) */
  char map_pr[512], map_pm[512];/* texture paths as written (relative to the MTL), or "" */
} mtl_pbr;

typedef struct obj_text {
  char path[1024];
  char *text;                   /* repaired text (owned) */
  size_t len;
} obj_text;

/* A glTF material as gltf_check read it: what Assimp's import of it also holds (its name,
 * base colour, metallic, roughness and emissive factors: its signature, by which the
 * loader finds it among Assimp's materials, which Assimp numbers in the order it meets
 * them), and what Assimp does not read (KHR_materials_specular's factor and colour). */
typedef struct gltf_mat {
  char name[128];
  float base[4], metallic, roughness, emissive[3];
  float specular[4];            /* specularFactor, specularColorFactor; 1 where absent */
} gltf_mat;

typedef struct obj_check {
  obj_text files[17];           /* [0] the OBJ, then its MTL files (a glTF: the file, its buffers) */
  int nfiles;
  mtl_pbr *pbr;                 /* one per newmtl of every MTL */
  int npbr;
  gltf_mat *gmat;               /* a glTF's materials, or NULL */
  uint32_t ngmat;
} obj_check;

/* Reads and checks the OBJ at path and the MTL files it names. Returns VALO_OK (with
 * warnings logged) or an error naming file and line. Free with obj_check_free. */
valo_status obj_check_read(const char *path, obj_check *oc, valo_error *err);
void obj_check_free(obj_check *oc);
/* The PBR-extension values of material `name`, or NULL. */
const mtl_pbr *obj_check_pbr(const obj_check *oc, const char *name);
/* The file at path, whole and NUL-terminated (malloc'd; *len bytes before the NUL), or
 * NULL with errno set. */
char *obj_check_read_whole(const char *path, size_t *len);
/* An Assimp file system (struct aiFileIO *) serving the texts in oc->files (repaired
 * OBJ/MTL, a checked glTF and its buffers, a repaired PLY) and opening no other file;
 * valid while oc lives. */
struct aiFileIO;
void obj_check_fileio(obj_check *oc, struct aiFileIO *io);
#endif
