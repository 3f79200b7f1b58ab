/* SPDX-License-Identifier: MIT */
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "image/elem_store.h"
#include "irdm/error.h"
#include "irdm/image.h"
#include "irdm/precision.h"
#include "precompute/head_pairs.h"

/* Every block's entry: r >= c the next run, r < c its mirror's, flagged. */
static int fill_index(const struct irdm_corr_sparse *sp, uint32_t *index, size_t *n_runs)
{
	uint32_t next = 0;

	for (size_t c = 0; c < sp->n_cols; c++)
		for (uint32_t k = sp->start[c]; k < sp->start[c + 1]; k++) {
			long mk;
			if (sp->rows[k] >= c) {
				index[k] = next++;
				continue;
			}
			mk = irdm_corr_sparse_find(sp, sp->rows[k], (uint32_t)c);
			if (mk < 0)
				return IRDM_EINVAL;
			index[k] = index[mk] | IRDM_HEAD_TRANSPOSED;
		}
	*n_runs = next;
	return IRDM_OK;
}

/* The stored runs back into head: block k upright or transposed. */
static void write_back(const struct irdm_corr_sparse *sp, size_t S, const uint32_t *index,
		       const double *runs, double *head)
{
	for (size_t k = 0; k < sp->n_blocks; k++) {
		bool tr = index[k] & IRDM_HEAD_TRANSPOSED;
		const double *src = &runs[(size_t)(index[k] & IRDM_HEAD_RUN_MASK) * S * 9];
		double *out = &head[k * S * 9];
		for (size_t s = 0; s < S; s++)
			for (size_t i = 0; i < 9; i++)
				out[9 * s + i] = src[9 * s + irdm_head_elem(tr, i)];
	}
}

int irdm_head_pairs_store(const struct irdm_corr_sparse *sp, size_t S, uint32_t elem, double *head,
			  struct irdm_head_pairs *out)
{
	size_t es = irdm_elem_size(elem), per = S * 9;
	double *runs = NULL;
	int ret = IRDM_ENOMEM;

	memset(out, 0, sizeof(*out));
	out->index = malloc((sp->n_blocks ? sp->n_blocks : 1) * sizeof(uint32_t));
	if (!out->index)
		goto out_fail;
	ret = fill_index(sp, out->index, &out->n_runs);
	if (ret)
		goto out_fail;
	ret = IRDM_ENOMEM;
	runs = malloc((out->n_runs ? out->n_runs : 1) * per * sizeof(double));
	out->bytes = out->n_runs * per * es;
	out->runs = malloc(out->bytes ? out->bytes : 1);
	if (!runs || !out->runs)
		goto out_fail;
	for (size_t k = 0; k < sp->n_blocks; k++)
		if (!(out->index[k] & IRDM_HEAD_TRANSPOSED))
			memcpy(&runs[out->index[k] * per], &head[k * per], per * sizeof(double));
	for (size_t i = 0; i < out->n_runs * per; i++)
		runs[i] = irdm_elem_put(out->runs, elem, i, runs[i]);
	write_back(sp, S, out->index, runs, head);
	free(runs);
	return IRDM_OK;
out_fail:
	free(runs);
	irdm_head_pairs_free(out);
	return ret;
}

void irdm_head_pairs_free(struct irdm_head_pairs *hp)
{
	free(hp->index);
	free(hp->runs);
	memset(hp, 0, sizeof(*hp));
}
