/* view.h — `valo view` (view.c): the interactive viewer. */
#ifndef VALO_CLI_VIEW_H
#define VALO_CLI_VIEW_H
/* argv[0] is the first argument after "view"; returns the exit code. */
int cmd_view(int argc, char **argv);
#endif
