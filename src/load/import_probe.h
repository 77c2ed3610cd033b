/* import_probe.h — owns the trial import of mesh files valo does not check itself (every
 * format but OBJ, PLY and glTF: FBX, Collada, STL, OFF, 3DS, ...). Assimp reads them as
 * they come, and some damaged files crash it, make it allocate without bound or never
 * return. So such a file is first imported in a child process, under valo's memory limit
 * and a time limit; only when that import finishes does valo import it itself (Assimp's
 * import is deterministic, so the second one finishes too). A crash, a hang or the memory
 * limit becomes an error naming the file, and the caller's process is never harmed. */
#ifndef VALO_IMPORT_PROBE_H
#define VALO_IMPORT_PROBE_H
#include "valo/valo.h"

/* Imports `path` with Assimp's aiImportFile(path, flags) in a child process. VALO_OK when
 * Assimp returned a scene; VALO_ERR_PARSE with Assimp's message when it refused the file;
 * VALO_ERR_PARSE when it crashed (the signal named), VALO_ERR_NOMEM when it went past the
 * memory limit, and VALO_ERR_PARSE when it took longer than the time limit: 30 s plus 2 s
 * per MiB of the file, or VALO_IMPORT_TIMEOUT seconds when that is set. */
valo_status import_probe(const char *path, unsigned flags, valo_error *err);

#endif
