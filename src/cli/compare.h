/* compare.h — owns the `valo compare` command (compare.c) and the report's data, which
 * report.c writes out. */
#ifndef VALO_CLI_COMPARE_H
#define VALO_CLI_COMPARE_H
#include <stdint.h>

#define CMP_MAX_RUNS 12
#define CMP_MAX_SNAPS 40

/* One integrator's run: its final image and figures, and its error at moments of the run
 * (snap: the images, kept only until the reference is known). */
typedef struct cmp_run {
  char name[32];
  int w, h, spp, nsnap;
  double seconds, relmse, bias;
  uint64_t rays;
  float *px;
  float *snap[CMP_MAX_SNAPS];
  double snap_t[CMP_MAX_SNAPS], snap_err[CMP_MAX_SNAPS];
  int snap_spp[CMP_MAX_SNAPS];
} cmp_run;

typedef struct cmp_report {
  char scene[1024];
  char reference[1024]; /* the reference file, or "" */
  int ref_run;          /* without a file: 1 + the index of the run taken as reference */
  double time_budget;   /* seconds, or 0 */
  int spp_budget;       /* or spp */
  int crop[4];          /* x, y, w, h */
  int nruns;
  cmp_run runs[CMP_MAX_RUNS];
} cmp_report;

/* `valo compare` with argv after "compare"; returns the exit code. */
int cmd_compare(int argc, char **argv);
#endif
