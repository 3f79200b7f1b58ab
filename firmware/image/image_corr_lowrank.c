/* SPDX-License-Identifier: MIT */
/*
 * The static correction's far field, STATIC_CORR_LOWRANK: a symmetric
 * low-rank term U diag(lambda) U^T over the touchable DoFs (values in the
 * image's precision) that every block adds, and the one function that
 * reads a whole correction block (kept block plus far field).  The checks
 * make the reads safe: a rank the tick can afford, the size exactly that
 * of the rank and n_cols, every value finite.
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

/* blk += U[col_disp] diag(lambda) U[col_force]^T, entry [i][j] summed as
 * (u_disp,i u_force,j) lambda: block (a, b) is block (b, a) transposed to
 * the bit, so R[0] stays exactly symmetric. */
static void add_far_field(const struct irdm_image *img, uint32_t col_force, uint32_t col_disp,
			  double blk[9])
{
	size_t r = img->corr_rank, d = 3 * (size_t)col_disp * r, f = 3 * (size_t)col_force * r;
	uint32_t prec = img->meta->precision;
	const void *u = img->corr_u;
	/* the nine sums in registers (blk may alias nothing the loop reads,
	 * but the compiler cannot know), each in the order of k */
	double a0 = blk[0], a1 = blk[1], a2 = blk[2], a3 = blk[3], a4 = blk[4];
	double a5 = blk[5], a6 = blk[6], a7 = blk[7], a8 = blk[8];

	for (size_t k = 0; k < r; k++) {
		double l = irdm_elem_get(img->corr_lambda, prec, k);
		double d0 = irdm_elem_get(u, prec, d + k), f0 = irdm_elem_get(u, prec, f + k);
		double d1 = irdm_elem_get(u, prec, d + r + k), f1 = irdm_elem_get(u, prec, f + r + k);
		double d2 = irdm_elem_get(u, prec, d + 2 * r + k);
		double f2 = irdm_elem_get(u, prec, f + 2 * r + k);

		a0 += (d0 * f0) * l, a1 += (d0 * f1) * l, a2 += (d0 * f2) * l;
		a3 += (d1 * f0) * l, a4 += (d1 * f1) * l, a5 += (d1 * f2) * l;
		a6 += (d2 * f0) * l, a7 += (d2 * f1) * l, a8 += (d2 * f2) * l;
	}
	blk[0] = a0, blk[1] = a1, blk[2] = a2, blk[3] = a3, blk[4] = a4;
	blk[5] = a5, blk[6] = a6, blk[7] = a7, blk[8] = a8;
}

void irdm_image_corr_value(const struct irdm_image *img, uint32_t col_force,
			   uint32_t col_disp, double blk[9])
{
	long k = irdm_image_corr_block(img, col_force, col_disp);

	for (size_t i = 0; i < 9; i++)
		blk[i] = k < 0 ? 0.0 : irdm_elem_get(img->corr_blocks, img->meta->precision,
						      (size_t)k * 9 + i);
	if (img->corr_rank)
		add_far_field(img, col_force, col_disp, blk);
	if (img->corr_clusters)
		img_corr_clusters_add(img, col_force, col_disp, blk);
}
