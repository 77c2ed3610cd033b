/* error.c — see error.h. */
#include "core/error.h"
#include <stdarg.h>
#include <stdio.h>

static valo_log_fn g_warn_fn;
static void *g_warn_user;
static _Thread_local valo_log_fn t_warn_fn; /* the calling handle's (log_scope) */
static _Thread_local void *t_warn_user;

void log_scope_enter(log_scope *saved, valo_log_fn fn, void *user) {
  saved->fn = t_warn_fn;
  saved->user = t_warn_user;
  if (fn) { t_warn_fn = fn; t_warn_user = user; }
}
void log_scope_leave(const log_scope *saved) {
  t_warn_fn = saved->fn;
  t_warn_user = saved->user;
}

valo_status err_set(valo_error *err, valo_status s, const char *fmt, ...) {
  if (err) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
    err->status = s;
  }
  return s;
}

/* Formats a message and sends it to the handler (prefixed by handler_prefix) or to
 * standard error as "valo: <kind>: ...". */
static void log_emit(const char *kind, const char *handler_prefix, const char *fmt, va_list ap) {
  char buf[1024];
  vsnprintf(buf, sizeof buf, fmt, ap);
  valo_log_fn fn = t_warn_fn ? t_warn_fn : g_warn_fn;
  void *user = t_warn_fn ? t_warn_user : g_warn_user;
  if (!fn) { fprintf(stderr, "valo: %s: %s\n", kind, buf); return; }
  char msg[1100];
  snprintf(msg, sizeof msg, "%s%s", handler_prefix, buf);
  fn(user, msg);
}

void log_warning(const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  log_emit("warning", "", fmt, ap);
  va_end(ap);
}

void log_note(const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  log_emit("note", "note: ", fmt, ap);
  va_end(ap);
}

void log_set_default_handler(valo_log_fn fn, void *user) {
  g_warn_fn = fn;
  g_warn_user = user;
}
