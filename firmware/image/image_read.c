/* SPDX-License-Identifier: MIT */
/*
 * What the tick reads of a parsed image: a section's table entry, the
 * static correction's blocks (kept block, far field, clusters) and the
 * largest spectral radius.  The checks made every read here safe and
 * bounded; nothing here checks.
 */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "image_priv.h"

const struct irdm_image_section *irdm_image_find(const struct irdm_image *img,
						 uint32_t kind)
{
	const struct irdm_image_section *tab;
	struct irdm_image_header h;

	if (!img->base)
		return NULL;
	memcpy(&h, img->base, sizeof(h));
	tab = (const struct irdm_image_section *)(img->base +
						  h.section_table_offset);
	for (uint32_t i = 0; i < h.section_count; i++)
		if (tab[i].kind == kind)
			return &tab[i];
	return NULL;
}

double irdm_image_max_radius(const struct irdm_image *img)
{
	double max = 0;

	for (uint32_t i = 0; img->stability && i < img->meta->n_cols; i++)
		if (img->stability[i].spectral_radius > max)
			max = img->stability[i].spectral_radius;
	return max;
}

long irdm_image_corr_block(const struct irdm_image *img, uint32_t col_force,
			   uint32_t col_disp)
{
	uint32_t lo, hi;

	if (!img->corr_start)
		return -1;
	lo = img->corr_start[col_force];
	hi = img->corr_start[col_force + 1];
	while (lo < hi) {
		uint32_t mid = lo + (hi - lo) / 2;
		if (img->corr_rows[mid] < col_disp)
			lo = mid + 1;
		else
			hi = mid;
	}
	return lo < img->corr_start[col_force + 1] && img->corr_rows[lo] == col_disp ? (long)lo : -1;
}

const struct irdm_corr_pair *irdm_image_corr_pair(const struct irdm_image *img, uint32_t a,
						  uint32_t b)
{
	uint64_t nC = img->corr_clusters->n_clusters;

	if (a > b) {
		uint32_t t = a;
		a = b;
		b = t;
	}
	/* row a of the upper triangle starts after a nC - a (a - 1) / 2 pairs */
	return &img->corr_cl_pairs[irdm_upper_index(nC, a, b)];
}

uint32_t irdm_image_corr_cluster(const struct irdm_image *img, uint32_t col, uint32_t *local)
{
	uint32_t pos = img->corr_cl_pos[col], lo = 0, hi = img->corr_clusters->n_clusters;

	/* the cluster a with start[a] <= pos < start[a + 1] */
	while (hi - lo > 1) {
		uint32_t mid = lo + (hi - lo) / 2;
		if (img->corr_cl_start[mid] <= pos)
			lo = mid;
		else
			hi = mid;
	}
	*local = pos - img->corr_cl_start[lo];
	return lo;
}

/*
 * blk += the pair's value between the two columns.  Entry [x][y] is row
 * 3 i_d + x, col 3 i_f + y of pair (a_d, a_f), or of pair (a_f, a_d)
 * transposed: the same products in the same order either way, so block
 * (f, d) is block (d, f) transposed to the bit.
 */
static void clusters_add(const struct irdm_image *img, uint32_t col_force, uint32_t col_disp,
			 double blk[9])
{
	uint32_t ld, lf, ad = irdm_image_corr_cluster(img, col_disp, &ld);
	uint32_t af = irdm_image_corr_cluster(img, col_force, &lf);
	const struct irdm_corr_pair *q = irdm_image_corr_pair(img, ad, af);
	bool swap = ad > af;
	uint32_t lr = swap ? lf : ld, lc = swap ? ld : lf, ar = swap ? af : ad, ac = swap ? ad : af;
	size_t nr = 3 * (size_t)(img->corr_cl_start[ar + 1] - img->corr_cl_start[ar]);
	size_t ncl = 3 * (size_t)(img->corr_cl_start[ac + 1] - img->corr_cl_start[ac]);
	uint32_t prec = img->meta->precision;
	const void *v = img->corr_cl_values;
	size_t o = (size_t)q->offset;

	for (size_t x = 0; x < 3; x++)
		for (size_t y = 0; y < 3; y++) {
			size_t r = 3 * (size_t)lr + (swap ? y : x), c = 3 * (size_t)lc + (swap ? x : y);
			double s = 0;
			if (ar == ac) {
				size_t i = r < c ? r : c, j = r < c ? c : r;
				s = irdm_elem_get(v, prec, o + irdm_upper_index(nr, i, j));
			} else if (q->rank == IRDM_CORR_PAIR_DENSE) {
				s = irdm_elem_get(v, prec, o + r * ncl + c);
			} else {
				size_t ur = o + r * q->rank, vc = o + nr * q->rank + c * q->rank;
				for (size_t t = 0; t < q->rank; t++)
					s += irdm_elem_get(v, prec, ur + t) * irdm_elem_get(v, prec, vc + t);
			}
			blk[3 * x + y] += s;
		}
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
		blk[i] = k < 0 ? 0.0 : irdm_image_value(img, img->corr_blocks, col_force, (size_t)k * 9 + i);
	if (img->corr_rank)
		add_far_field(img, col_force, col_disp, blk);
	if (img->corr_clusters)
		clusters_add(img, col_force, col_disp, blk);
}
