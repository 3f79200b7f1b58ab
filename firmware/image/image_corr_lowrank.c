/* SPDX-License-Identifier: MIT */
/*
 * The static correction's far field, STATIC_CORR_LOWRANK: a symmetric
 * low-rank term U diag(lambda) U^T over the touchable DoFs (values in the
 * image's precision) that every block adds (image_read.c reads it).  The
 * checks make the reads safe: a rank the tick can afford, the size exactly
 * that of the rank and n_cols, every value finite.
 */
#include <stdbool.h>
#include <stdint.h>

#include "image_priv.h"

#define HDR sizeof(struct irdm_corr_lowrank_header)

static int check_rank(struct parse *p, const struct irdm_corr_lowrank_header *h)
{
	uint64_t nd = 3 * (uint64_t)p->meta.n_cols;
	uint64_t max = nd < IRDM_CORR_LOWRANK_MAX ? nd : IRDM_CORR_LOWRANK_MAX;
	uint64_t want;

	if (h->rank < 1 || h->rank > max)
		return img_fail(p, IRDM_EFORMAT,
				"STATIC_CORR_LOWRANK: rank %u is not in 1..%llu (3 n_cols, at most %u)",
				h->rank, (unsigned long long)max, IRDM_CORR_LOWRANK_MAX);
	if (p->strict && !all_zero(h->reserved, sizeof(h->reserved)))
		return img_fail(p, IRDM_EFORMAT, "STATIC_CORR_LOWRANK: reserved header words not 0");
	want = HDR + p->es * (uint64_t)h->rank * (1 + nd);
	if (p->by_kind[IRDM_SEC_STATIC_CORR_LOWRANK]->size != want)
		return img_fail(p, IRDM_EFORMAT,
				"section STATIC_CORR_LOWRANK has %llu bytes, expected %llu (16 + rank %u x (1 + 3 n_cols) x %zu)",
				(unsigned long long)p->by_kind[IRDM_SEC_STATIC_CORR_LOWRANK]->size,
				(unsigned long long)want, h->rank, p->es);
	return IRDM_OK;
}

static int check_values(struct parse *p, const uint8_t *lambda, uint32_t rank)
{
	uint64_t n = 3 * (uint64_t)p->meta.n_cols * rank;
	const uint8_t *u = lambda + p->es * rank;
	uint32_t prec = p->meta.precision;

	for (uint32_t k = 0; k < rank; k++)
		if (!f64_finite(irdm_elem_get(lambda, prec, k)))
			return img_fail(p, IRDM_EFORMAT, "STATIC_CORR_LOWRANK: lambda[%u] is not finite",
					k);
	for (uint64_t i = 0; i < n; i++)
		if (!f64_finite(irdm_elem_get(u, prec, (size_t)i)))
			return img_fail(p, IRDM_EFORMAT,
					"STATIC_CORR_LOWRANK: U element (column %llu, axis %llu, term %llu) is not finite",
					(unsigned long long)(i / rank / 3),
					(unsigned long long)(i / rank % 3),
					(unsigned long long)(i % rank));
	return IRDM_OK;
}

int img_check_corr_lowrank(struct parse *p)
{
	const struct irdm_image_section *s = p->by_kind[IRDM_SEC_STATIC_CORR_LOWRANK];
	const uint8_t *pl = img_payload(p, IRDM_SEC_STATIC_CORR_LOWRANK);
	struct irdm_corr_lowrank_header h;
	int ret;

	if (!s)
		return IRDM_OK;
	if (s->elem != IRDM_ELEM_BYTES)
		return img_fail(p, IRDM_EFORMAT,
				"section STATIC_CORR_LOWRANK has element type %s, expected BYTES",
				img_elem_name(s->elem));
	if (s->size < HDR)
		return img_fail(p, IRDM_EFORMAT,
				"section STATIC_CORR_LOWRANK has %llu bytes, fewer than its 16-byte header",
				(unsigned long long)s->size);
	memcpy(&h, pl, HDR);
	ret = check_rank(p, &h);
	if (!ret)
		ret = check_values(p, pl + HDR, h.rank);
	if (ret)
		return ret;
	p->img.corr_rank = h.rank;
	p->img.corr_lambda = pl + HDR;
	p->img.corr_u = pl + HDR + p->es * h.rank;
	return IRDM_OK;
}
