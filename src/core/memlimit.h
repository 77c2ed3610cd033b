/* memlimit.h — owns valo's memory limit: the machine's physical memory, or the
 * VALO_MEMORY_LIMIT environment variable (bytes, with an optional K, M or G suffix) when
 * it is set lower. A load or a render whose largest allocations would not fit is refused
 * before they are made, with a message naming the file and the size, instead of being
 * killed by the system when memory runs out. */
#ifndef VALO_MEMLIMIT_H
#define VALO_MEMLIMIT_H
#include "valo/valo.h"
#include <stdint.h>

/* The limit in bytes. */
uint64_t mem_limit(void);
/* VALO_OK when `bytes` fit within the limit; otherwise VALO_ERR_NOMEM with the message
 * "<name>: <what>: <size> needed, more than the <limit> of this machine's memory". */
valo_status mem_check(uint64_t bytes, const char *name, const char *what, valo_error *err);
/* mem_check for w x h pixels of bytes_per_pixel each, described as "W x H pixels". */
valo_status mem_check_pixels(uint64_t w, uint64_t h, uint64_t bytes_per_pixel, const char *name, valo_error *err);
#endif
