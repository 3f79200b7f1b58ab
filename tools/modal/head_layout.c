/* SPDX-License-Identifier: MIT */
/*
 * The hybrid head's blocks as the image stores them: which a builder
 * computes, which it mirrors, and the taper of the last H samples.
 */
#include "modal/head_layout.h"
#include "modal/window.h"

uint32_t irdm_head_upper_begin(const struct irdm_corr_sparse *corr, size_t c)
{
	uint32_t k = corr->start[c];

	while (k < corr->start[c + 1] && corr->rows[k] < c && irdm_corr_sparse_find(corr, corr->rows[k], (uint32_t)c) >= 0)
		k++;
	return k;
}

void irdm_head_mirror(const struct irdm_corr_sparse *corr, size_t c, uint32_t k_end, size_t S,
		      double *head)
{
	for (uint32_t k = corr->start[c]; k < k_end; k++) {
		const double *src = &head[(size_t)irdm_corr_sparse_find(corr, corr->rows[k], (uint32_t)c) * S * 9];
		double *out = &head[(size_t)k * S * 9];

		for (size_t s = 0; s < S; s++)
			for (int i = 0; i < 3; i++)
				for (int j = 0; j < 3; j++)
					out[9 * s + 3 * (size_t)i + (size_t)j] = src[9 * s + 3 * (size_t)j + (size_t)i];
	}
}

/* A lump at one sample instead of the bump moved a zero of the force
 * recursion out of the unit circle on the 4x4x8 cuboid. */
void irdm_head_taper(double *out, size_t H, const double *target)
{
	double bump_sum = 0;

	for (size_t i = 0; i < H; i++) {
		double w = irdm_window_taper(i, H);
		bump_sum += irdm_window_bump(i, H);
		for (int e = 0; e < 9; e++)
			out[9 * (H + i) + (size_t)e] *= w;
	}
	for (int e = 0; e < 9; e++) {
		double sum = 0;
		for (size_t s = 0; s < 2 * H; s++)
			sum += out[9 * s + (size_t)e];
		for (size_t i = 0; i < H; i++)
			out[9 * (H + i) + (size_t)e] += (target[e] - sum) * irdm_window_bump(i, H) / bump_sum;
	}
}
