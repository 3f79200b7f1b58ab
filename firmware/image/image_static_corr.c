/* SPDX-License-Identifier: MIT */
/*
 * The block-sparse static correction: STATIC_CORR_INDEX (column starts, then
 * the rows of each kept block) and STATIC_CORR (the blocks).  The checks make
 * the tick's lookup safe: starts from 0 non-decreasing to the block count,
 * rows in range and strictly increasing per column, the diagonal present,
 * both sizes consistent, every value finite.
 */
#include <stdbool.h>
#include <stdint.h>

#include "image_priv.h"

/* Column c's rows: in range, strictly increasing, c among them. */
static int check_column(struct parse *p, const uint32_t *rows, uint32_t b, uint32_t e,
			uint32_t c)
{
	bool diag = false;

	for (uint32_t k = b; k < e; k++) {
		if (rows[k] >= p->meta.n_cols)
			return img_fail(p, IRDM_EFORMAT,
					"STATIC_CORR_INDEX: column %u block %u: row %u >= n_cols %u",
					c, k, rows[k], p->meta.n_cols);
		if (k > b && rows[k] <= rows[k - 1])
			return img_fail(p, IRDM_EFORMAT,
					"STATIC_CORR_INDEX: column %u: rows not strictly increasing at block %u",
					c, k);
		diag = diag || rows[k] == c;
	}
	if (!diag)
		return img_fail(p, IRDM_EFORMAT,
				"STATIC_CORR_INDEX: column %u lacks its diagonal block", c);
	return IRDM_OK;
}

static int check_index(struct parse *p, uint32_t *n_blocks)
{
	const struct irdm_image_section *s = p->by_kind[IRDM_SEC_STATIC_CORR_INDEX];
	uint64_t nc = p->meta.n_cols, want;
	const uint32_t *start = img_payload(p, IRDM_SEC_STATIC_CORR_INDEX), *rows;
	int ret;

	if (s->elem != IRDM_ELEM_U32)
		return img_fail(p, IRDM_EFORMAT, "section STATIC_CORR_INDEX has element type %s, expected U32",
				img_elem_name(s->elem));
	if (s->size < (nc + 1) * 4)
		return img_fail(p, IRDM_EFORMAT,
				"section STATIC_CORR_INDEX has %llu bytes, fewer than the %llu of n_cols + 1 starts",
				(unsigned long long)s->size, (unsigned long long)(nc + 1) * 4);
	*n_blocks = start[nc];
	want = (nc + 1 + *n_blocks) * 4;
	if (s->size != want)
		return img_fail(p, IRDM_EFORMAT,
				"section STATIC_CORR_INDEX has %llu bytes, expected %llu ((n_cols + 1 + %u blocks) x 4)",
				(unsigned long long)s->size, (unsigned long long)want, *n_blocks);
	if (start[0] != 0)
		return img_fail(p, IRDM_EFORMAT, "STATIC_CORR_INDEX: start of column 0 is %u, not 0",
				start[0]);
	/* all starts first: then every column's range lies inside the rows */
	for (uint32_t c = 0; c < nc; c++)
		if (start[c + 1] < start[c])
			return img_fail(p, IRDM_EFORMAT,
					"STATIC_CORR_INDEX: start of column %u (%u) is below column %u's (%u)",
					c + 1, start[c + 1], c, start[c]);
	rows = start + nc + 1;
	for (uint32_t c = 0; c < nc; c++) {
		ret = check_column(p, rows, start[c], start[c + 1], c);
		if (ret)
			return ret;
	}
	return IRDM_OK;
}

int img_check_static_corr(struct parse *p)
{
	uint32_t n_blocks = 0;
	int ret;

	ret = check_index(p, &n_blocks);
	if (!ret)
		ret = img_check_shape(p, IRDM_SEC_STATIC_CORR, (uint64_t[]){ n_blocks, 9 }, 2,
				      "blocks in STATIC_CORR_INDEX x 9");
	if (!ret)
		ret = img_check_finite(p, IRDM_SEC_STATIC_CORR, (uint64_t)n_blocks * 9);
	if (ret)
		return ret;
	p->img.corr_start = img_payload(p, IRDM_SEC_STATIC_CORR_INDEX);
	p->img.corr_rows = p->img.corr_start + p->meta.n_cols + 1;
	p->img.corr_blocks = img_payload(p, IRDM_SEC_STATIC_CORR);
	return IRDM_OK;
}
