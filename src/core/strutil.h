/* strutil.h — owns small string helpers the library shares. */
#ifndef VALO_STRUTIL_H
#define VALO_STRUTIL_H
#include <string.h>
#include <strings.h>

/* 1 when s ends with suf, ignoring case (file extensions). */
static inline int str_ends_with(const char *s, const char *suf) {
  size_t n = strlen(s), m = strlen(suf);
  return n >= m && !strcasecmp(s + n - m, suf);
}
#endif
