/* api_error.c — owns the public error helpers: status names and the process-wide warning
 * handler (core/error.c routes the messages). */
#include "valo/valo.h"
#include "core/error.h"

VALO_API void valo_set_warning_handler(valo_log_fn fn, void *user) { log_set_default_handler(fn, user); }

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
