/* SPDX-License-Identifier: MIT */
/*
 * EXACT_HEAD (format 2.1): the dropped modes' exact response over the first
 * head_samples samples of every kept static-correction block, the hybrid
 * representation's head.  It follows the STATIC_CORR index, so it is
 * checked after it: one [head_samples][3][3] run per kept block, every value
 * finite.  Whether the samples sum to the block is the precompute's promise
 * (the certificate and the tests check it), not a format rule.
 */
#include "image_priv.h"

int img_check_exact_head(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	bool head = m->flags & IRDM_META_EXACT_HEAD;
	int ret;

	ret = img_check_presence(p, IRDM_SEC_EXACT_HEAD, head,
				 head ? "meta flags say EXACT_HEAD" : "meta flags lack EXACT_HEAD");
	if (ret || !head)
		return ret;
	uint64_t n_blocks = p->img.corr_start[m->n_cols];
	ret = img_check_shape(p, IRDM_SEC_EXACT_HEAD, (uint64_t[]){ n_blocks, m->head_samples, 9 }, 3,
			      "blocks in STATIC_CORR_INDEX x head_samples x 9");
	if (!ret)
		ret = img_check_finite(p, IRDM_SEC_EXACT_HEAD, n_blocks * m->head_samples * 9);
	if (ret)
		return ret;
	p->img.exact_head = img_payload(p, IRDM_SEC_EXACT_HEAD);
	return IRDM_OK;
}
