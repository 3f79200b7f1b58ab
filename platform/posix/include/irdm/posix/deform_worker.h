/* SPDX-License-Identifier: MIT */
/*
 * The deformation worker: the reader of a deformation channel
 * (irdm/deform.h).  It takes the newest snapshot the force tick published
 * and computes every image node's position with OpenBLAS, in its own,
 * lower-priority context at its own rate (irdm_deform_thread_start()), or
 * when the caller asks (irdm_deform_update()).  The force tick never waits
 * for it.
 *
 * Positions are world positions: rest + displacement, and for a floating
 * image (img->rigid != NULL) the rigid pose on top of that:
 *   world = com + R(q) (rest + u - com_rest),  com_rest = img->rigid->com_m.
 * A grounded image ignores the pose (its object frame is the world frame).
 *
 * BLAS threads: OpenBLAS's thread count is process-wide.  The deformation
 * context must not spread over the force loop's core, so
 * irdm_deform_thread_start() sets it to IRDM_DEFORM_BLAS_THREADS (1) before
 * it starts; a caller that runs irdm_deform_update() itself should do the
 * same (openblas_set_num_threads(1)).
 */
#ifndef IRDM_DEFORM_WORKER_H
#define IRDM_DEFORM_WORKER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/deform.h"
#include "irdm/error.h"

#define IRDM_DEFORM_BLAS_THREADS 1

struct irdm_deform_worker; /* opaque, in caller memory */

/*
 * Bytes irdm_deform_worker_init() needs for this image (0 if the update
 * cannot use it): the BLAS operands (an f16 image's mode shapes converted
 * to f32) and the thread's frame buffer.  Any alignment is fine.
 */
size_t irdm_deform_worker_mem_size(const struct irdm_image *img);

/*
 * Initialise the reader of channel d (which must outlive it) in `mem`,
 * pre-faulted here, and run one product so that the first frame does not
 * pay for OpenBLAS's set-up.  At most one worker per channel.
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if d is NULL or its image is not one the update can read
 * (precision, sizes over BLAS's int);
 * IRDM_ENOMEM if mem is NULL or smaller than irdm_deform_worker_mem_size().
 * On error *w is NULL and err says why.
 */
int irdm_deform_worker_init(struct irdm_deform_worker **w, struct irdm_deform *d, void *mem,
			    size_t mem_size, char *err, size_t errlen);

/*
 * If a snapshot newer than the last one taken is there, compute every image
 * node's world position into pos_m (3 n_nodes, node-major) and return true
 * with its tick; false (pos_m untouched) if nothing new was published.
 * Force nodes whose column is out of range are ignored.
 */
bool irdm_deform_update(struct irdm_deform_worker *w, double *pos_m, uint64_t *tick);

/* Rows (image nodes) the positions hold. */
uint32_t irdm_deform_rows(const struct irdm_deform_worker *w);

/*
 * Run irdm_deform_update() at rate_hz (0 < rate <= IRDM_DEFORM_MAX_RATE_HZ,
 * absolute-time clock_nanosleep on CLOCK_MONOTONIC; missed periods are
 * skipped, not caught up) in a thread of lower priority than the caller:
 * SCHED_FIFO one below a SCHED_FIFO/RR caller, else SCHED_OTHER at the
 * caller's nice + 5.  The callback receives each new frame in that thread
 * (pos_m is valid during the call only).  If the priority cannot be set the
 * thread still runs (at SCHED_OTHER, never at the caller's priority),
 * IRDM_OK is returned and err says why.  One thread per worker; its state
 * lives in the worker's memory (no allocation).  Init-time only.
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if frame is NULL or rate_hz is out of range;
 * IRDM_EBUSY if a thread already runs on this worker;
 * IRDM_ETHREAD if the thread could not be created.
 */
struct irdm_deform_thread;
int irdm_deform_thread_start(struct irdm_deform_thread **th, struct irdm_deform_worker *w,
			     double rate_hz, void (*frame)(void *ctx, const double *pos_m, uint64_t tick),
			     void *ctx, char *err, size_t errlen);
/* Stop (within one period) and join.  NULL is fine. */
void irdm_deform_thread_stop(struct irdm_deform_thread *th);

#endif
