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
#include "modal/window.h"

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

/* One block's H samples: out[s][i][j] = sum_d Pr[i][d] Pc[j][d] h[d][s]. */
static void block_head(const double *Pr, const double *Pc, const double *h, size_t Kd, size_t H,
		       double *w, double *out)
{
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) {
			for (size_t d = 0; d < Kd; d++)
				w[d] = Pr[(size_t)i * Kd + d] * Pc[(size_t)j * Kd + d];
			for (size_t s = 0; s < H; s++) {
				double acc = 0;
				for (size_t d = 0; d < Kd; d++)
					acc += w[d] * h[s * Kd + d];
				out[9 * s + 3 * (size_t)i + (size_t)j] = acc;
			}
		}
}

/*
 * Samples [H, 2H): the dropped response tapered to zero by the Hann
 * window of window.h, and what the taps' sum then misses of the static
 * correction S (the response past 2H and the taper's cut) added along
 * its sine bump: the static compliance is kept exactly, and neither the
 * response nor the correction jumps (a lump at one sample moved a zero of
 * the force recursion out of the unit circle on the 4x4x8 cuboid).
 */
static void taper(double *out, size_t H, const double *S)
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
			out[9 * (H + i) + (size_t)e] += (S[e] - sum) * irdm_window_bump(i, H) / bump_sum;
	}
}

int irdm_exact_head(const struct irdm_modes *modes, const struct irdm_mode *zoh_all, size_t k_kept,
		    const int64_t *col_dofs, const struct irdm_corr_sparse *corr, const double *target,
		    size_t H, irdm_progress_fn progress, void *ctx, double *head)
{
	size_t Kd = modes->n_modes > k_kept ? modes->n_modes - k_kept : 0, n_cols = corr->n_cols;
	double *P = NULL, *h = NULL, *w = NULL, *hd = NULL;
	int ret = IRDM_ENOMEM;

	if (!Kd || H < 1)
		return IRDM_EINVAL;
	P = dropped_shapes(modes, k_kept, col_dofs, n_cols);
	h = malloc(2 * H * Kd * sizeof(double)); /* [s][d]: the inner loop runs over d */
	hd = malloc(2 * H * sizeof(double));
	w = malloc(Kd * sizeof(double));
	if (!P || !h || !hd || !w)
		goto out_free;
	for (size_t d = 0; d < Kd; d++) {
		irdm_zoh_response(&zoh_all[k_kept + d], 2 * H, hd);
		for (size_t s = 0; s < 2 * H; s++)
			h[s * Kd + d] = hd[s];
	}
	for (size_t c = 0; c < n_cols; c++) {
		for (uint32_t k = corr->start[c]; k < corr->start[c + 1]; k++) {
			double *out = &head[(size_t)k * 2 * H * 9];
			block_head(&P[3 * (size_t)corr->rows[k] * Kd], &P[3 * c * Kd], h, Kd, 2 * H, w, out);
			taper(out, H, &target[9 * (size_t)k]);
		}
		if (progress && (c % 16 == 0 || c + 1 == n_cols))
			progress(ctx, "exact head", (double)(c + 1) / (double)n_cols);
	}
	ret = IRDM_OK;
out_free:
	free(P);
	free(h);
	free(hd);
	free(w);
	return ret;
}
