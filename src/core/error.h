/* error.h — owns error reporting inside the library: filling a valo_error and sending
 * warnings to the handler set with valo_set_warning_handler. */
#ifndef VALO_ERROR_H
#define VALO_ERROR_H
#include "valo/valo.h"

/* Fills err (if not NULL) with status s and a printf-style message; returns s. */
valo_status err_set(valo_error *err, valo_status s, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
void log_warning(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Information a user should see (a default that was applied), not a problem: printed as
 * "valo: note: ...", or sent to the warning handler prefixed "note: ". */
void log_note(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
#endif
