/* gltf_check.h — owns valo's own check of a glTF file (.gltf or .glb) before Assimp reads
 * it. Assimp 5.2.5's glTF 2.0 reader trusts the file: a .glb chunk length is allocated
 * as written (4 GB), and a .gltf it cannot parse is handed to whichever other importer
 * claims its bytes (its OpenGEX reader read past its buffer on 16 of them). So a glTF reaches
 * Assimp only when it is what its name says: a .glb container whose header and chunks
 * fit the file, JSON in strict RFC 8259 syntax (as Assimp's parser reads it, nested at
 * most 512 deep), glTF 2.0 by its asset version, every index it holds naming an existing
 * object, buffers as long as they say, accessors and buffer views inside their buffers,
 * primitive indices inside the vertex count and enough vertices for the primitive's mode,
 * nodes forming trees, and the values Assimp reads without looking well formed (data URI
 * media types, an embedded image's mimeType, KHR_texture_transform vectors, a skin's
 * inverse bind matrices). A UTF-8 byte-order mark is dropped and a buffer URI's %XX
 * escapes are decoded, which Assimp does not do. The file and its buffer files are then
 * served to Assimp from what valo read (obj_check's file system), so Assimp opens nothing
 * valo has not checked. */
#ifndef VALO_GLTF_CHECK_H
#define VALO_GLTF_CHECK_H
#include "load/obj_check.h"
#include "valo/valo.h"

/* Reads and checks the glTF at path (binary: a .glb). On VALO_OK, oc holds the file
 * (files[0]) and the buffer files it names, to be served by obj_check_fileio and freed
 * by obj_check_free; on an error, a message naming the file and what is wrong. */
valo_status gltf_check_file(const char *path, int binary, obj_check *oc, valo_error *err);
#endif
