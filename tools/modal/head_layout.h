/* SPDX-License-Identifier: MIT */
/*
 * The hybrid head's blocks as the image stores them (EXACT_HEAD): what a
 * head builder computes, what it mirrors, and the taper of its last H
 * samples.  Shared by the head from every mode (exact_head.h) and the
 * head from a Krylov run (krylov_head.h), so both write the same image.
 */
#ifndef IRDM_TOOLS_HEAD_LAYOUT_H
#define IRDM_TOOLS_HEAD_LAYOUT_H

#include <stddef.h>
#include <stdint.h>

#include "modal/static_sparse.h"

/*
 * The first of column c's blocks to compute: R[s] is symmetric, so block
 * (c, r) with r < c is block (r, c) transposed, once column r has it
 * (irdm_head_mirror()); the static correction keeps both of a pair or
 * neither.  The diagonal block is always at or after it.
 */
uint32_t irdm_head_upper_begin(const struct irdm_corr_sparse *corr, size_t c);

/* Column c's blocks before k_end, from their mirror images (head holds
 * S samples of 9 per block). */
void irdm_head_mirror(const struct irdm_corr_sparse *corr, size_t c, uint32_t k_end, size_t S,
		      double *head);

/*
 * Samples [H, 2H) of one block (out: 2H samples of 9): the response
 * tapered to zero by the Hann window of window.h, and what the samples'
 * sum then misses of target (the block's whole static correction) added
 * along its sine bump: the static compliance is kept exactly, and neither
 * the response nor the correction jumps.
 */
void irdm_head_taper(double *out, size_t H, const double *target);

#endif
