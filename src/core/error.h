/* error.h — owns error reporting inside the library: filling a valo_error and sending
 * warnings and notes to the calling handle's handler (log_scope), else the process-wide
 * one (valo_set_warning_handler), else standard error. */
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
/* The process-wide handler (valo_set_warning_handler): used where no handle routes them. */
void log_set_default_handler(valo_log_fn fn, void *user);
/* Warnings of one public handle: log_scope_enter routes this thread's warnings and notes
 * to fn (when not NULL) until log_scope_leave, which restores what was before. */
typedef struct log_scope { valo_log_fn fn; void *user; } log_scope;
void log_scope_enter(log_scope *saved, valo_log_fn fn, void *user);
void log_scope_leave(const log_scope *saved);
#endif
