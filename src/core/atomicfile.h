/* atomicfile.h — owns writing a file atomically: the bytes go to a temporary file beside
 * the target, which is flushed to disk (fsync) and renamed over it, then the folder is
 * flushed so the rename itself is on disk; a crash at any moment leaves the old file or
 * the new one, never a part. Images, checkpoints. */
#ifndef VALO_ATOMICFILE_H
#define VALO_ATOMICFILE_H
#include <stddef.h>

/* A temporary name beside path (".NAME.tmpPID.K" in its folder), unique per process and
 * call; -1 when it does not fit in n. */
int atomic_temp_name(const char *path, char *out, size_t n);
/* Flushes the finished temporary file tmp to disk, renames it over path and flushes the
 * folder. 0, or -1 with errno set and tmp removed. */
int atomic_commit(const char *tmp, const char *path);
#endif
