/* SPDX-License-Identifier: MIT */
/*
 * How long a mode rings.  A hybrid image holds the dropped modes' exact
 * response over its head only: what a mode still does past the head is
 * lost unless it stays in the modal recursion (modal/head_split.h ranks
 * the modes by it), whatever its frequency.  On a soft, heavy material the low modes
 * past the first hundred can ring for thousands of ticks, so choosing the
 * kept modes by frequency alone leaves a certified image far off the
 * exact model.  Also: putting the kept modes first.
 */
#ifndef IRDM_TOOLS_DECAY_H
#define IRDM_TOOLS_DECAY_H

#include <stddef.h>

#include "fem/fem.h"
#include "modal/modal.h"

/*
 * The slowest decay rate (1/s) of q'' + 2 z w q' + w^2 q = 0: its roots'
 * real part z w when under- or critically damped (z <= 1); when
 * overdamped the slow root's, w (z - sqrt(z^2 - 1)), computed as
 * w / (z + sqrt(z^2 - 1)) to keep its digits at large z.  w = 0 (a free
 * mass) does not decay: 0.
 */
double irdm_decay_rate(double w_rad_s, double zeta);

/* The envelope left of a free response after t_s: exp(-rate t_s). */
double irdm_decay_left(double rate_per_s, double t_s);

/*
 * The highest angular frequency (rad/s) up to w_max whose free response
 * under damp still has more than `left` of its envelope after horizon_s:
 * every mode ringing that long lies at or below it (the rate need not
 * grow with w: Rayleigh's overdamped modes ring longer again).  0 if none
 * does; w_max if the envelope is still over `left` there.  Scanned on a
 * geometric grid of 4096 points from w_max / 1e6, the crossing then
 * bisected.
 */
double irdm_decay_cutoff(const struct irdm_rayleigh *damp, double horizon_s, double left,
			 double w_max);

/*
 * Put m's modes (omega2 and the columns of phi) in order: mode k becomes
 * the one at order[k].  order must be a permutation of 0 .. m->n_modes - 1.
 * Return: IRDM_OK; IRDM_ENOMEM (m untouched).
 */
int irdm_modes_permute(struct irdm_modes *m, const size_t *order);

#endif
