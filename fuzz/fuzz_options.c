/* fuzz_options.c — owns the command-line fuzz harness: the input is split at line ends
 * into arguments and parsed as `valo render`'s (cli_parse_render, src/cli/args.c: the
 * declared options, -o and its formats, AOV prefixes and frame patterns, the checkpoint
 * and stats flags, --help); when that accepts them, the integrator parameters are
 * checked as the command line does (valo_integrator_check_params). */
#include "fuzz_util.h"
#include "cli/args.h"
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fuzz_quiet();
  static FILE *sink;
  if (!sink && !(sink = fopen("/dev/null", "w"))) return 0;
  if (size > 4096) return 0;
  char *buf = malloc(size + 1);
  if (!buf) return 0;
  memcpy(buf, data, size);
  buf[size] = 0;
  char *argv[256];
  int argc = 0;
  for (char *p = buf; argc < 256;) {
    argv[argc++] = p;
    char *nl = strchr(p, '\n');
    if (!nl) break;
    *nl = 0;
    p = nl + 1;
  }
  cli_args ca;
  if (cli_parse_render(argc, argv, &ca, sink, sink) < 0 && ca.opt.params[0]) {
    valo_error err;
    valo_integrator_check_params(ca.opt.integrator[0] ? ca.opt.integrator : "path", ca.opt.params, &err);
  }
  free(buf);
  return 0;
}
