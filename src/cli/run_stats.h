/* run_stats.h — owns what the command line reports about a finished run beside the
 * image: the peak memory of the process and the machine-readable `--stats-json` file,
 * and the JSON string writer and the file writer it shares with the compare report
 * (report.c). */
#ifndef VALO_CLI_RUN_STATS_H
#define VALO_CLI_RUN_STATS_H
#include "valo/valo.h"
#include <stdint.h>
#include <stdio.h>

/* s as a JSON string, quoted (quotes, backslashes and control characters escaped). */
void json_put_string(FILE *f, const char *s);

/* A text file made in memory, then written as valo writes its images (valo_file_write:
 * atomically, links followed, FIFOs and /dev/stdout in place). cli_out_open: the stream
 * to print into, or NULL after saying so on stderr; cli_out_write: closes it, writes
 * path and frees the text; 0, or -1 after saying why, naming path. */
typedef struct cli_out { FILE *f; char *buf; size_t len; } cli_out;
FILE *cli_out_open(cli_out *o, const char *path);
int cli_out_write(cli_out *o, const char *path);

/* The process's peak resident memory so far, bytes (0 when the system does not say). */
uint64_t run_peak_memory(void);

/* One run as --stats-json writes it. */
typedef struct run_report {
  const char *scene;
  const char *status;       /* "ok", "interrupted" or "error" */
  int exit_code;
  double load_seconds;
  const valo_stats *st;
  uint64_t peak_memory;     /* bytes */
  const valo_rank_stats *ranks; /* under MPI: every rank's share (nranks), else NULL, 0 */
  int nranks;
} run_report;

/* Writes the report as JSON to path (cli_out_write). 0, or -1 with a message on stderr
 * naming the file. */
int run_stats_write_json(const char *path, const run_report *r);
#endif
