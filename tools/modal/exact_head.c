/* SPDX-License-Identifier: MIT */
/*
 * The dropped modes' exact head.  The static correction puts everything
 * the dropped modes do into R[0], which misses their impulsive response
 * after a step (the first ticks' forces) and their ringing after it.
 * Their response over H samples, summed mode by mode at the kept blocks
 * only, restores both; H more samples taper it off and keep the rest of
 * the static compliance.  H must outlast the ringing: on a soft material
 * the first dropped modes ring for hundreds of ticks, and a shorter head
 * is unstable (the precompute's certificate refuses it).
 */
#include <stdlib.h>
#include <string.h>

#include "modal/exact_head.h"
#include "modal/head_layout.h"
#include "modal/lapack.h"

/* P[(3 c + i) Kd + d] = phi of dropped mode k_kept + d at column c, axis i. */
static double *dropped_shapes(const struct irdm_modes *m, size_t k_kept, const int64_t *col_dofs,
			      size_t n_cols)
{
	size_t Kd = m->n_modes - k_kept;
	double *P = malloc(3 * n_cols * Kd * sizeof(double));

	if (!P)
		return NULL;
	for (size_t r = 0; r < 3 * n_cols; r++)
		for (size_t d = 0; d < Kd; d++)
			P[r * Kd + d] = col_dofs[r] < 0 ? 0.0 : m->phi[(k_kept + d) * m->n + (size_t)col_dofs[r]];
	return P;
}

#define HEAD_CHUNK 128 /* blocks gathered per product: bounds the scratch */

/*
 * Blocks [k_begin, end) of column c as one product per chunk, so that BLAS
 * does the Kd-long sums (a block's head is 9 x 2H such sums, and a column
 * has hundreds of blocks):
 *   C[(3 b + i), (j, s)] = sum_d P[rows_b, i][d] W[d, (j, s)],
 *   W[d, (j, s)] = Pc[j][d] h[s][d].
 * P is [dof][d]: a column-major Kd x (3 n_cols) matrix, so a block's rows
 * are gathered (G) before the product.
 */
static void column_head(const struct irdm_corr_sparse *corr, uint32_t k_begin, size_t c,
			const double *P, const double *W, size_t Kd, size_t S, double *G, double *C,
			double *head)
{
	for (uint32_t k0 = k_begin; k0 < corr->start[c + 1]; k0 += HEAD_CHUNK) {
		uint32_t nb = corr->start[c + 1] - k0 < HEAD_CHUNK ? corr->start[c + 1] - k0 : HEAD_CHUNK;
		int m = (int)(3 * nb), n = (int)(3 * S), kd = (int)Kd;
		double one = 1.0, zero = 0.0;

		for (uint32_t b = 0; b < nb; b++)
			memcpy(&G[3 * (size_t)b * Kd], &P[3 * (size_t)corr->rows[k0 + b] * Kd],
			       3 * Kd * sizeof(double));
		dgemm_("T", "N", &m, &n, &kd, &one, G, &kd, W, &kd, &zero, C, &m);
		for (uint32_t b = 0; b < nb; b++) {
			double *out = &head[(size_t)(k0 + b) * S * 9];
			for (size_t s = 0; s < S; s++)
				for (int i = 0; i < 3; i++)
					for (int j = 0; j < 3; j++)
						out[9 * s + 3 * (size_t)i + (size_t)j] =
							C[(size_t)(3 * b + (uint32_t)i) +
							  (size_t)m * ((size_t)j * S + s)];
		}
	}
}

/* W[d, (j, s)] = Pc[j][d] h[s][d], for column c's force axes j. */
static void column_weights(const double *Pc, const double *h, size_t Kd, size_t S, double *W)
{
	for (int j = 0; j < 3; j++)
		for (size_t s = 0; s < S; s++)
			for (size_t d = 0; d < Kd; d++)
				W[((size_t)j * S + s) * Kd + d] = Pc[(size_t)j * Kd + d] * h[s * Kd + d];
}

int irdm_exact_head(const struct irdm_modes *modes, const struct irdm_mode *zoh_all, size_t k_kept,
		    const int64_t *col_dofs, const struct irdm_corr_sparse *corr, const double *target,
		    size_t H, irdm_progress_fn progress, void *ctx, double *head)
{
	size_t Kd = modes->n_modes > k_kept ? modes->n_modes - k_kept : 0, n_cols = corr->n_cols;
	size_t S = 2 * H;
	double *P = NULL, *h = NULL, *hd = NULL, *W = NULL, *G = NULL, *C = NULL;
	int ret = IRDM_ENOMEM;

	if (!Kd || H < 1)
		return IRDM_EINVAL;
	P = dropped_shapes(modes, k_kept, col_dofs, n_cols);
	h = malloc(S * Kd * sizeof(double)); /* [s][d]: d runs fastest */
	hd = malloc(S * sizeof(double));
	W = malloc(3 * S * Kd * sizeof(double));
	G = malloc(3 * HEAD_CHUNK * Kd * sizeof(double));
	C = malloc(3 * HEAD_CHUNK * 3 * S * sizeof(double));
	if (!P || !h || !hd || !W || !G || !C)
		goto out_free;
	for (size_t d = 0; d < Kd; d++) {
		irdm_zoh_response(&zoh_all[k_kept + d], S, hd);
		for (size_t s = 0; s < S; s++)
			h[s * Kd + d] = hd[s];
	}
	/* the blocks on and below the diagonal (row >= column), then the
	 * rest mirrored, then every block tapered: its own target */
	for (size_t c = 0; c < n_cols; c++) {
		column_weights(&P[3 * c * Kd], h, Kd, S, W);
		column_head(corr, irdm_head_upper_begin(corr, c), c, P, W, Kd, S, G, C, head);
		if (progress && (c % 16 == 0 || c + 1 == n_cols))
			progress(ctx, "exact head", (double)(c + 1) / (double)n_cols);
	}
	for (size_t c = 0; c < n_cols; c++)
		irdm_head_mirror(corr, c, irdm_head_upper_begin(corr, c), S, head);
	for (size_t k = 0; k < corr->n_blocks; k++)
		irdm_head_taper(&head[k * S * 9], H, &target[9 * k]);
	ret = IRDM_OK;
out_free:
	free(P);
	free(h);
	free(hd);
	free(W);
	free(G);
	free(C);
	return ret;
}
