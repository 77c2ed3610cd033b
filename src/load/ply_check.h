/* ply_check.h — owns valo's own check of a PLY file before Assimp reads it: the header
 * (format, elements, properties), every element's data against the header (counts against
 * the file's size, ASCII numbers and line lengths, binary lengths), and every face's vertex
 * count and indices. Assimp 5.2.5 (Debian 12, libassimp5 5.2.5~ds0-1+b1) keeps its
 * assertions, and its PLY reader hands faces that disagree with the header to
 * TriangulateProcess, which aborts the process (`numOut != pMesh->mNumFaces`); it reads two
 * vertex (or face) elements into one mesh whose arrays disagree, freeing what it never
 * allocated; it reads an element whose name it does not know as empty, a blank line as an
 * element, and "+3" as an unsigned 0. So a PLY reaches Assimp only when both would read it
 * alike: one format line, one vertex and one face element, no other elements with
 * instances but edge and material, numbers in the forms both read whole, no blank lines
 * within the data, and every face a polygon of valid indices. */
#ifndef VALO_PLY_CHECK_H
#define VALO_PLY_CHECK_H
#include "valo/valo.h"
#include <stddef.h>

/* 1 when the first bytes are a PLY magic ("ply" then a line end). */
int ply_is_ply(const unsigned char *data, size_t len);
/* Checks the PLY held in data (len bytes, read from path, named in messages). Returns
 * VALO_OK or an error "path: what is wrong" (with the line for header and ASCII faults). */
valo_status ply_check(const char *path, const unsigned char *data, size_t len, size_t *cr_at, valo_error *err);
/* Reads path and checks it; VALO_OK for a file that is not a PLY (a name ending in .ply
 * must be one). *fixed (malloc'd, *fixed_len bytes) is NULL, or the file as Assimp must be
 * given it: a binary PLY whose data starts with a line feed, its header ending in "\r\n"
 * (Assimp would skip that byte after a plain "\n"; with ply_check, *cr_at is where the
 * '\r' goes, or 0). */
valo_status ply_check_file(const char *path, char **fixed, size_t *fixed_len, valo_error *err);
#endif
