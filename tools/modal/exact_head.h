/* SPDX-License-Identifier: MIT */
/*
 * The hybrid representation's head: the exact response of the modes a
 * modal image drops, over its first H samples, at the static correction's
 * kept blocks (scene key exact_head; image section EXACT_HEAD).
 */
#ifndef IRDM_TOOLS_EXACT_HEAD_H
#define IRDM_TOOLS_EXACT_HEAD_H

#include <stddef.h>
#include <stdint.h>

#include "modal/modal.h"
#include "modal/static_sparse.h"

/*
 * head[(k 2H + s) 9 + 3 i + j] for every kept block k of corr (force at
 * column c, displacement at column corr->rows[k]) and s < 2H: for s < H
 *   sum over the dropped modes d = k_kept .. modes->n_modes - 1 of
 *   phi_row,d,i phi_c,d,j h_d[s],
 * h_d the ZOH response of mode d (zoh_all: every mode of modes, discretised);
 * for H <= s < 2H the same tapered to zero by a Hann window, plus what the
 * samples' sum misses of target[9 k ..] (block k's whole static correction:
 * the kept block and the far field's value there) along a sine bump: the
 * head sums to it exactly, so the image's static compliance does not
 * depend on H.  modes holds every elastic mode; col_dofs as for
 * irdm_static_correction_sparse().
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_EINVAL if k_kept >= modes->n_modes.
 */
int irdm_exact_head(const struct irdm_modes *modes, const struct irdm_mode *zoh_all, size_t k_kept,
		    const int64_t *col_dofs, const struct irdm_corr_sparse *corr, const double *target,
		    size_t H, irdm_progress_fn progress, void *ctx, double *head);

#endif
