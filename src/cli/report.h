/* report.h — owns the files of a comparison report (report.c): summary.json and the
 * self-contained index.html with its SVG plot. */
#ifndef VALO_CLI_REPORT_H
#define VALO_CLI_REPORT_H
#include "cli/compare.h"

/* Each writes its file into dir; 0, or -1 with a message on stderr naming the file. */
int report_write_summary(const cmp_report *r, const char *dir);
int report_write_html(const cmp_report *r, const char *dir);
#endif
