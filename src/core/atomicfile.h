/* atomicfile.h — owns writing a file atomically: the bytes go to a temporary file beside
 * the target, which is flushed to disk (fsync) and renamed over it, then the folder is
 * flushed so the rename itself is on disk; a crash at any moment leaves the old file or
 * the new one, never a part. A symbolic link is followed, so the file it names is
 * replaced and the link kept; a FIFO, a device or an open file named through /proc
 * (/dev/stdout) is written in place, from a temporary file in TMPDIR (or /tmp), since
 * there is no file to replace. Images, checkpoints, the CLI's JSON and report files. */
#ifndef VALO_ATOMICFILE_H
#define VALO_ATOMICFILE_H
#include <stddef.h>

/* A temporary name beside path's target (".NAME.tmpPID.K" in its folder), unique per
 * process and call; -1 when it does not fit in n or a link cannot be read. */
int atomic_temp_name(const char *path, char *out, size_t n);
/* Flushes the finished temporary file tmp to disk, renames it over path and flushes the
 * folder. 0, or -1 with errno set and tmp removed. */
int atomic_commit(const char *tmp, const char *path);
/* n bytes written to path atomically as above: 0, or -1 with errno set. */
int atomic_write(const char *path, const void *data, size_t n);
#endif
