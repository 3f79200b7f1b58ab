/* SPDX-License-Identifier: MIT */
/*
 * The deformation channel: how the force tick hands its history to the
 * deformation context (irdm/posix/deform_worker.h), which computes the displayed
 * node positions (eq. 9/12) at its own, lower rate.
 *
 * A lock-free triple buffer in caller memory.  Publishing is a bounded copy
 * with no lock, no system call and no wait; the reader takes the newest
 * snapshot and never sees a torn one.  This side needs neither BLAS nor
 * threads: a program that only runs the force tick links without them.
 *
 * Exactly one writer (the force context) and one reader (the worker, or its
 * thread) per struct.
 */
#ifndef IRDM_DEFORM_H
#define IRDM_DEFORM_H

#include <stddef.h>
#include <stdint.h>

#include "irdm/error.h"
#include "irdm/history.h"
#include "irdm/image.h"

/* The highest rate a board may ask the deformation worker for (its
 * deform_rate_hz; the worker: irdm/posix/deform_worker.h). */
#define IRDM_DEFORM_MAX_RATE_HZ 10000.0

struct irdm_deform; /* opaque, in caller memory */

/*
 * Bytes irdm_deform_init() needs for this image: three snapshots of its
 * history.  0 if the image is not a usable FIR or modal image.  Any
 * alignment of the memory is fine.
 */
size_t irdm_deform_mem_size(const struct irdm_image *img);

/*
 * Initialise the channel in `mem` (pre-faulted here: publishing never
 * page-faults).  The image must stay mapped while the channel is used.
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if img is not a usable FIR or modal image;
 * IRDM_ENOMEM if mem is NULL or smaller than irdm_deform_mem_size().
 * On error *d is NULL and err says why.
 */
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
 * cost is bounded by T (IRDM_MAX_FORCE_NODES + 1) small copies.  The
 * engine's ring holds each force times its column's storage scale
 * (irdm_image_col_scale(), 1 unless the image has COLUMN_SCALE), and the
 * worker reads the FIR's stored taps unscaled against it, as the tick does.
 */
void irdm_deform_publish_fir(struct irdm_deform *d, uint64_t tick,
			     const struct irdm_fir_ring *ring, const struct irdm_pose *pose);

#endif
