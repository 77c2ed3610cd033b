/* error.c — see error.h. */
#include "core/error.h"
#include <stdarg.h>
#include <stdio.h>

static valo_log_fn g_warn_fn;
static void *g_warn_user;

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
  if (!g_warn_fn) { fprintf(stderr, "valo: %s: %s\n", kind, buf); return; }
  char msg[1100];
  snprintf(msg, sizeof msg, "%s%s", handler_prefix, buf);
  g_warn_fn(g_warn_user, msg);
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

VALO_API void valo_set_warning_handler(valo_log_fn fn, void *user) { g_warn_fn = fn; g_warn_user = user; }

VALO_API const char *valo_status_string(valo_status s) {
  switch (s) {
  case VALO_OK: return "ok";
  case VALO_ERR_IO: return "i/o error";
  case VALO_ERR_PARSE: return "parse error";
  case VALO_ERR_INVALID: return "invalid input";
  case VALO_ERR_UNSUPPORTED: return "unsupported";
  case VALO_ERR_NOMEM: return "out of memory";
  case VALO_ERR_CANCELLED: return "cancelled";
  }
  return "unknown";
}
