/* SPDX-License-Identifier: MIT */
/*
 * Which modes a hybrid image keeps in its modal recursion.  The head
 * holds the dropped modes' exact response for H samples, then tapers it
 * to their static value (modal/exact_head.h): what a dropped mode still
 * does past the head is lost.  So the modes are ranked by how much of
 * their envelope is left after the head (modal/decay.h), whatever their
 * frequency, and a hybrid keeps the first k of that rank; how many is
 * for the force error to say (accuracy/split.h).
 */
#ifndef IRDM_TOOLS_HEAD_SPLIT_H
#define IRDM_TOOLS_HEAD_SPLIT_H

#include <stdbool.h>
#include <stddef.h>

#include "fem/fem.h"
#include "modal/modal.h"

/*
 * rank (m->n_modes entries): m's modes, the most envelope left after
 * horizon_s first (damping from damp; a free mass, w = 0, leaves all of
 * it), ties in m's order.
 * Return: IRDM_OK; IRDM_ENOMEM.
 */
int irdm_head_split_rank(const struct irdm_modes *m, const struct irdm_rayleigh *damp,
			 double horizon_s, size_t *rank);

/*
 * order (n entries): rank's first k in ascending index, then the rest in
 * ascending index: the permutation that puts a hybrid's kept modes first
 * (modal/decay.h irdm_modes_permute()).  dropped (n entries): set true
 * for the modes not kept.
 */
void irdm_head_split_order(const size_t *rank, size_t n, size_t k, size_t *order, bool *dropped);

#endif
