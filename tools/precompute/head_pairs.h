/* SPDX-License-Identifier: MIT */
/*
 * A hybrid image's head stored by pairs (meta flag HEAD_PAIRS, sections
 * EXACT_HEAD and EXACT_HEAD_INDEX): R[s] is symmetric, so the head of
 * block (force c, displacement r) is that of (r, c) transposed, and the
 * static correction keeps both of a pair or neither.  Storing the blocks
 * with r >= c alone halves the head, which is most of a hybrid image.
 */
#ifndef IRDM_TOOLS_HEAD_PAIRS_H
#define IRDM_TOOLS_HEAD_PAIRS_H

#include <stddef.h>
#include <stdint.h>

#include "modal/static_sparse.h"

struct irdm_head_pairs {
	uint32_t *index; /* n_blocks: EXACT_HEAD_INDEX */
	void *runs;      /* the stored runs, in the precision */
	size_t n_runs, bytes;
};

/*
 * The runs of head ([k][s][3][3], S samples, every kept block of sp) with
 * r >= c, in the order of k, stored in precision elem, and the index of
 * every block; head is then overwritten with what the image holds (each
 * block as stored, its mirror the stored run transposed), so that the
 * certificate judges the image's values.
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_EINVAL if a block's mirror is not
 * kept (out is then zeroed).
 */
int irdm_head_pairs_store(const struct irdm_corr_sparse *sp, size_t S, uint32_t elem, double *head,
			  struct irdm_head_pairs *out);

void irdm_head_pairs_free(struct irdm_head_pairs *hp);

#endif /* IRDM_TOOLS_HEAD_PAIRS_H */
