/* dist.h — owns rendering across processes (MPI, when valo is built with OpenMPI): every
 * rank loads the scene and builds the same session; rank 0 runs the render (budgets,
 * passes, adaptive plans, progress, checkpoints, outputs) and hands out tiles on demand,
 * each with the pixels' film state (sums, counts, squares, AOVs), to its own threads and
 * to the other ranks, which take each pixel's next samples in sample order and send the
 * state back. Each pixel's samples are therefore summed in the same order as in one
 * process, and the image is byte-identical. Integrators with prepare (photon, vpl, vsl)
 * run it on every rank for every pass (a pure function of the sample index). Without
 * MPI, or outside an MPI launcher, there is one rank and none of this runs. */
#ifndef VALO_DIST_H
#define VALO_DIST_H
#include "render/tiles.h"

/* Joins the MPI job when the process was started by an MPI launcher (mpirun, srun);
 * returns the number of processes the launcher started (1 outside one). dist_size is
 * how many share the work (1 when valo was built without MPI). */
int dist_init(int *argc, char ***argv);
int dist_rank(void);
int dist_size(void);
/* 1 when valo was built with MPI. */
int dist_built(void);
void dist_finalize(void);
/* Collective: every rank passes its status (err its message when rc != 0). Returns the
 * status of the lowest failing rank (0 when none failed); on every rank err then holds
 * that rank's message, prefixed "rank K (host): " when K is not this rank. */
int dist_agree(int rc, valo_error *err);
/* Rank 0, more than one rank: the tile source (render/tiles.h) that takes each pass's
 * samples on every rank. */
extern const tile_source dist_master;
/* Ranks above 0: renders what rank 0 hands out until it says stop. */
valo_status dist_worker(session *ss, thread_stats *ts, valo_error *err);
/* Rank 0, at the end of a run: stops the other ranks and adds their counters to sum,
 * and records each rank's share in ss->ranks. */
void dist_finish(session *ss, thread_stats *sum);
#endif
