/* SPDX-License-Identifier: MIT */
/*
 * How long a mode rings.  A hybrid image holds the dropped modes' exact
 * response over its head only: a mode whose free response outlasts the
 * head must stay in the modal recursion, whatever its frequency, and a
 * mode that has rung down within the head costs less there.  On a soft,
 * heavy material the low modes past the first hundred can ring for
 * thousands of ticks, so choosing the kept modes by frequency alone
 * leaves a certified image far off the exact model.
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
 * Order m's modes for a head of horizon_s: first every mode whose
 * envelope after horizon_s (its Rayleigh damping from damp) is above tol,
 * then the rest, each group in m's order (ascending frequency).
 * order[k] (m->n_modes entries): the index in m of the mode to put k-th.
 * Return: how many ring past the horizon (the first group).
 */
size_t irdm_modes_by_decay(const struct irdm_modes *m, const struct irdm_rayleigh *damp,
			   double horizon_s, double tol, size_t *order);

/*
 * Put m's modes (omega2 and the columns of phi) in order: mode k becomes
 * the one at order[k].  order must be a permutation of 0 .. m->n_modes - 1.
 * Return: IRDM_OK; IRDM_ENOMEM (m untouched).
 */
int irdm_modes_permute(struct irdm_modes *m, const size_t *order);

#endif
