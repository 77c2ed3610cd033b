/* args.h — owns the parsed form of `valo render`'s command line (args.c), what the
 * other commands parse through it, and the commands' clock. */
#ifndef VALO_CLI_ARGS_H
#define VALO_CLI_ARGS_H
#include "valo/valo.h"
#include <stddef.h>
#include <stdio.h>
#include <time.h>

#define EXIT_USAGE 2

/* Seconds on a monotonic clock (the commands' timing). */
static inline double cli_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
#define CLI_MAX_OUTPUTS 16

typedef struct cli_args {
  valo_options opt;
  valo_output_options oo;
  valo_load_options lo;
  const char *scene_path;
  const char *outputs[CLI_MAX_OUTPUTS]; /* -o, in order (the default name when none) */
  int nout;
  int quiet;
  int denoise;                          /* --denoise: the image outputs are written denoised */
  char denoised[CLI_MAX_OUTPUTS][1040]; /* their "denoised:" names */
  const char *stats_json, *ckpt, *resume;
  double ckpt_every;
  char default_out[1024];
} cli_args;

/* Parses `valo render`'s arguments (argv[0] is the first after "render"). Returns -1 to
 * go on and render, or the exit code: 0 after --help or --help-integrators (printed to
 * out), EXIT_USAGE after a usage error (said on err). */
int cli_parse_render(int argc, char **argv, cli_args *ca, FILE *out, FILE *err);
/* For commands that take render flags and flags of their own (valo compare, valo view):
 * own is a NULL-ended list of the command's flags, each taking a value stored in
 * values[k] (left alone when absent); the rest goes to cli_parse_render. Returns what it
 * does, or CLI_HELP for --help or -h (the caller prints its own usage). */
#define CLI_HELP 1000
int cli_parse_with_own(int argc, char **argv, const char *const *own, const char **values, cli_args *ca, FILE *err);
/* The render --help text. */
void usage_render(FILE *f);
/* Length of an output's AOV prefix ("albedo:", "normal:", "depth:", "ao:", "bent:",
 * "spp:"), or 0. */
size_t aov_prefix(const char *out);
/* Where the frame number goes in an output name (a "%d" or "%0Nd"): the offset of the
 * '%' with the conversion's length in *len; -1 when there is none, -2 when the name has
 * another '%'. */
int frame_pattern(const char *name, int *len);
/* name with its frame pattern replaced by frame f. */
void frame_name(const char *name, int f, char *out, size_t n);
#endif
