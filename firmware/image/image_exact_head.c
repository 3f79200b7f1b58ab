/* SPDX-License-Identifier: MIT */
/*
 * EXACT_HEAD (format 2.1): the dropped modes' exact response over the first
 * head_samples samples of every kept static-correction block, the hybrid
 * representation's head.  It follows the STATIC_CORR index, so it is
 * checked after it: one [head_samples][3][3] run per kept block, every value
 * finite.  With HEAD_PAIRS (2.5) a symmetric pair of blocks shares one run,
 * and EXACT_HEAD_INDEX says which; every entry is checked against the pair
 * it must name, so the tick may read any block's run without a bound check.
 * Whether the samples sum to the block is the precompute's promise (the
 * certificate and the tests check it), not a format rule.
 */
#include "image_priv.h"

/* Entry k of column c: a block with row r >= c is the next run, stored
 * upright; one with r < c is the run of its mirror (r -> c), transposed. */
static int check_entry(struct parse *p, uint32_t c, uint32_t k, uint32_t *next)
{
	const struct irdm_image *img = &p->img;
	uint32_t r = img->corr_rows[k], v = img->head_index[k];
	long mk;

	if (r >= c) {
		if (v != *next)
			return img_fail(p, IRDM_EFORMAT,
					"EXACT_HEAD_INDEX entry %u (column %u, row %u) is %#x, expected %u (the next stored run)",
					k, c, r, v, *next);
		(*next)++;
		return IRDM_OK;
	}
	mk = irdm_image_corr_block(img, r, c);
	if (mk < 0)
		return img_fail(p, IRDM_EFORMAT,
				"EXACT_HEAD_INDEX entry %u: block (column %u, row %u) has no mirror (column %u, row %u) in STATIC_CORR_INDEX",
				k, c, r, r, c);
	if (v != (img->head_index[mk] | IRDM_HEAD_TRANSPOSED))
		return img_fail(p, IRDM_EFORMAT,
				"EXACT_HEAD_INDEX entry %u (column %u, row %u) is %#x, expected its mirror's run %u transposed",
				k, c, r, v, img->head_index[mk]);
	return IRDM_OK;
}

/* HEAD_PAIRS: the index, entry by entry; the number of runs it names. */
static int check_index(struct parse *p, uint64_t *n_runs)
{
	const struct irdm_meta *m = &p->meta;
	uint64_t n_blocks = p->img.corr_start[m->n_cols];
	uint32_t next = 0;
	int ret;

	ret = img_check_presence(p, IRDM_SEC_EXACT_HEAD_INDEX, true, "meta flags say HEAD_PAIRS");
	if (!ret && (m->flags & IRDM_META_COLUMN_SCALE))
		ret = img_fail(p, IRDM_EFORMAT,
			       "meta flags say both HEAD_PAIRS and COLUMN_SCALE (a shared run has one column's scale)");
	if (!ret)
		ret = img_check_shape(p, IRDM_SEC_EXACT_HEAD_INDEX, (uint64_t[]){ n_blocks }, 1,
				      "blocks in STATIC_CORR_INDEX");
	if (ret)
		return ret;
	p->img.head_index = img_payload(p, IRDM_SEC_EXACT_HEAD_INDEX);
	/* column by column, rows increasing: a mirror (r < c) was seen first */
	for (uint32_t c = 0; c < m->n_cols; c++)
		for (uint32_t k = p->img.corr_start[c]; k < p->img.corr_start[c + 1]; k++) {
			ret = check_entry(p, c, k, &next);
			if (ret)
				return ret;
		}
	*n_runs = next;
	return IRDM_OK;
}

int img_check_exact_head(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	bool head = m->flags & IRDM_META_EXACT_HEAD;
	bool pairs = m->flags & IRDM_META_HEAD_PAIRS;
	uint64_t n_runs;
	int ret;

	ret = img_check_presence(p, IRDM_SEC_EXACT_HEAD, head,
				 head ? "meta flags say EXACT_HEAD" : "meta flags lack EXACT_HEAD");
	if (!ret && !pairs)
		ret = img_check_presence(p, IRDM_SEC_EXACT_HEAD_INDEX, false,
					 "meta flags lack HEAD_PAIRS");
	if (!ret && pairs && !head)
		ret = img_fail(p, IRDM_EFORMAT, "meta flags say HEAD_PAIRS without EXACT_HEAD");
	if (ret || !head)
		return ret;
	n_runs = p->img.corr_start[m->n_cols];
	if (pairs)
		ret = check_index(p, &n_runs);
	if (!ret)
		ret = img_check_shape(p, IRDM_SEC_EXACT_HEAD,
				      (uint64_t[]){ n_runs, m->head_samples, 9 }, 3,
				      pairs ? "runs in EXACT_HEAD_INDEX x head_samples x 9" :
					      "blocks in STATIC_CORR_INDEX x head_samples x 9");
	if (!ret)
		ret = img_check_finite(p, IRDM_SEC_EXACT_HEAD, n_runs * m->head_samples * 9);
	if (ret) {
		p->img.head_index = NULL;
		return ret;
	}
	p->img.exact_head = img_payload(p, IRDM_SEC_EXACT_HEAD);
	return IRDM_OK;
}
