/* SPDX-License-Identifier: MIT */
/*
 * Deformation of the displayed nodes (eq. 9/12) in its own, lower-priority
 * context at its own rate.  The force tick publishes the history through a
 * lock-free triple buffer (irdm_deform_publish_*: a bounded copy, no lock,
 * no system call, no wait); the deformation context takes the newest
 * snapshot and computes the displaced positions with OpenBLAS.  The force
 * tick never waits for it, and the reader never sees a torn snapshot.
 *
 * Exactly one writer (the force context) and one reader (the deformation
 * context, or the thread of irdm_deform_thread_start()) per struct.
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
#ifndef IRDM_DEFORM_H
#define IRDM_DEFORM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/history.h"
#include "irdm/image.h"

#define IRDM_DEFORM_BLAS_THREADS 1
#define IRDM_DEFORM_MAX_RATE_HZ 10000.0

enum irdm_deform_error {
	IRDM_DEFORM_OK = 0,
	IRDM_DEFORM_EINVAL = -1,    /* bad image or argument */
	IRDM_DEFORM_ENOMEM = -2,    /* memory smaller than irdm_deform_mem_size() */
	IRDM_DEFORM_EBUSY = -3,     /* a deformation thread already runs on it */
	IRDM_DEFORM_ETHREAD = -4,   /* the thread could not be created */
};

struct irdm_deform;   /* opaque, in caller memory */

/*
 * Bytes irdm_deform_init() needs for this image (0 if the image is not
 * usable): three snapshots, the BLAS operands (an f16 image's mode shapes
 * converted to f32), the thread's frame buffer.  Any alignment is fine.
 */
size_t irdm_deform_mem_size(const struct irdm_image *img);

/* Initialise in `mem` (pre-faulted here); the image must stay mapped. */
int irdm_deform_init(struct irdm_deform **d, const struct irdm_image *img, void *mem,
		     size_t mem_size, char *err, size_t errlen);

/*
 * Force context (writer).  Modal: the mode states x[t+1] (2 n_modes, as
 * (q, q') pairs) after tick `tick`, and this tick's forces f[t] (for the
 * static correction; NULL = none).  Cost: 2 n_modes doubles copied.
 * pose NULL = identity.  A call that does not fit the image's
 * representation is ignored.
 */
void irdm_deform_publish_modal(struct irdm_deform *d, uint64_t tick, const double *x,
			       const struct irdm_force_tick *f, const struct irdm_pose *pose);
/*
 * FIR: the ring (ring[(head - s) mod T] = tick t - s), copied newest first:
 * min(ring->T, image T) ticks, and of each only its n force nodes, so the
 * cost is bounded by T (IRDM_MAX_FORCE_NODES + 1) small copies.
 */
void irdm_deform_publish_fir(struct irdm_deform *d, uint64_t tick,
			     const struct irdm_fir_ring *ring, const struct irdm_pose *pose);

/*
 * Deformation context (reader): if a snapshot newer than the last one taken
 * is there, compute every image node's world position into pos_m
 * (3 n_nodes, node-major) and return true with its tick; false (pos_m
 * untouched) if nothing new was published.  Force nodes whose column is out
 * of range are ignored.
 */
bool irdm_deform_update(struct irdm_deform *d, double *pos_m, uint64_t *tick);

/* Rows (image nodes) the positions hold. */
uint32_t irdm_deform_rows(const struct irdm_deform *d);

/*
 * Run irdm_deform_update() at rate_hz (0 < rate <= IRDM_DEFORM_MAX_RATE_HZ,
 * absolute-time clock_nanosleep on CLOCK_MONOTONIC; missed periods are
 * skipped, not caught up) in a thread of lower priority than the caller:
 * SCHED_FIFO one below a SCHED_FIFO/RR caller, else SCHED_OTHER at the
 * caller's nice + 5.  The callback receives each new frame in that thread
 * (pos_m is valid during the call only).  If the priority cannot be set the
 * thread still runs (at SCHED_OTHER, never at the caller's priority), 0 is
 * returned and err says why.  One thread per struct irdm_deform; its state
 * lives in the deform memory (no allocation).  Init-time only.
 */
struct irdm_deform_thread;
int irdm_deform_thread_start(struct irdm_deform_thread **th, struct irdm_deform *d,
			     double rate_hz, void (*frame)(void *ctx, const double *pos_m,
							   uint64_t tick),
			     void *ctx, char *err, size_t errlen);
/* Stop (within one period) and join.  NULL is fine. */
void irdm_deform_thread_stop(struct irdm_deform_thread *th);

#endif
