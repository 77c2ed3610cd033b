/* checkpoint.h — owns the render checkpoint: the film and the state a render needs to go
 * on from a pass boundary (samples done, the adaptive stage and its per-pixel plan, the
 * counters), with what it was made from (valo's version, the scene's path and a hash of
 * its geometry and materials, every option that changes the image), written atomically
 * (a temporary file, fsync, rename) and read back only whole: a file that is truncated,
 * corrupted (a 64-bit FNV-1a checksum over everything) or made by another version, for
 * another scene or with other options is refused, with a message saying which. */
#ifndef VALO_CHECKPOINT_H
#define VALO_CHECKPOINT_H
#include "render/session.h"

/* Writes ss's state to path; ts: this run's per-thread counters so far (opt.threads of
 * them). */
valo_status checkpoint_write(const session *ss, const thread_stats *ts, const char *path, valo_error *err);
/* At a pass boundary (ss->ckpt_state says which): writes the checkpoint to ss->ckpt_path
 * when one is due (ss->ckpt_every); ts are this run's counters, run_t0 its start. A
 * failed write is a warning: the render goes on. */
void checkpoint_tick(session *ss, const thread_stats *ts, double run_t0);
/* Restores ss's state from path (after session_create, before session_run). */
valo_status checkpoint_read(session *ss, const char *path, valo_error *err);
#endif
