/* SPDX-License-Identifier: MIT */
/*
 * representation = auto when every mode does not fit in memory: a hybrid
 * of the lowest modes of a Lanczos solve and a head of IRDM_LOWEST_HEAD
 * samples from Chebyshev series in the stiffness (modal/krylov_head.h).
 * Without every mode there is no prediction to size it by
 * (accuracy/split.h reads them all), so the kept modes are every one
 * whose envelope after the head is over a share `left` of its start
 * (modal/decay.h: all of them lie below one frequency, the cutoff),
 * counted by the inertia of K - sigma M (fem/inertia.h) and solved with
 * IRDM_LOWEST_MARGIN more, the image is built and measured against
 * max_error, and a miss lowers
 * `left` by as much as it missed and builds again, IRDM_LOWEST_ROUNDS
 * times at most.
 *
 * The first share is calibrated on what the every-mode choice keeps at
 * the default damping (5 % at the first mode and at 100 Hz) and 1 ms: a
 * 128-sample head with the modes to 55 Hz at 3312 nodes and to about 58
 * Hz at 11,340 (docs/measurements/scale.md), whose envelope after the
 * head is 0.28 and 0.25, measured 9.25e-4 and 6.1e-4 against max_error
 * 1e-3.  200 max_error (0.2 at 1e-3) starts a little under both.
 */
#ifndef IRDM_TOOLS_LOWEST_H
#define IRDM_TOOLS_LOWEST_H

#include <stddef.h>

#include "modal/modal.h"

#define IRDM_LOWEST_HEAD 128  /* the head's samples */
#define IRDM_LOWEST_ROUNDS 3  /* builds at most */
#define IRDM_LOWEST_MARGIN 8  /* modes solved past the cutoff's count */
#define IRDM_LOWEST_SHARE 200 /* the first share, per unit of max_error */
#define IRDM_LOWEST_SHARE_MAX 0.5

/* The first share: IRDM_LOWEST_SHARE max_error, at most IRDM_LOWEST_SHARE_MAX. */
double irdm_lowest_left_first(double max_error);

/*
 * The share after a build measured `measured` (over max_error): `left`
 * times half of max_error over measured, so that a miss by a factor
 * lowers it by twice that, between 2 and 100 times lower.
 */
double irdm_lowest_left_next(double left, double max_error, double measured);

/* How many of m's first n modes (ascending) are at or below w rad/s. */
size_t irdm_lowest_below(const struct irdm_modes *m, size_t n, double w);

#endif
