/* SPDX-License-Identifier: MIT */
/*
 * The far field of the block-sparse static correction: the dropped
 * remainder F = S - S_near (S_near the kept blocks) as a symmetric
 * low-rank term U diag(lambda) U^T over the touchable DoFs.
 */
#ifndef IRDM_TOOLS_STATIC_LOWRANK_H
#define IRDM_TOOLS_STATIC_LOWRANK_H

#include <stdint.h>

#include "irdm/error.h"
#include "modal/modal.h"
#include "modal/static_sparse.h"

/* Default rank (scene key static_correction_rank; 0: no far field). */
#define IRDM_STATIC_CORR_RANK_DEFAULT 96
/* Subspace (power) iterations of the randomized range finder. */
#define IRDM_STATIC_CORR_POWER_ITERS 2

struct irdm_corr_lowrank {
	size_t n_dofs; /* 3 n_cols */
	size_t rank;
	double *lambda; /* rank, |lambda| decreasing */
	double *u;      /* n_dofs x rank, row-major, orthonormal columns */
	/* a-posteriori, over the dropped blocks of the checked columns, in
	 * units of sqrt(|S_aa| |S_bb|): the largest and the RMS dropped
	 * block without the far field and what is left with it */
	size_t n_checked; /* columns checked */
	double max_before, max_after, rms_before, rms_after;
};

/*
 * Fit the far field of s (the kept blocks of S, from
 * irdm_static_correction_sparse with the same model and columns) by a
 * randomized subspace iteration on F = S - S_near: F V costs one solve of
 * V's width with a factor of K, the modal part and a product with the
 * kept blocks, so no n_cols^2 matrix is formed.  The Gaussian start is
 * seeded: the result is deterministic.  The rank is max_rank unless F has
 * fewer eigenvalues above 1e-3 of its largest.  Then every kept block of s
 * gets the far field's value there subtracted, so that S_near + U L U^T is
 * S on the kept blocks (and still exactly symmetric), and a few columns
 * of F are solved to measure what is left on the dropped ones.
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_ENUMERIC (factor, solve, eigensolver);
 * IRDM_EINVAL if max_rank is 0 or above 3 n_cols.
 */
int irdm_static_correction_lowrank(const struct irdm_fem *fem, const struct irdm_modes *m,
				   bool floating, const int64_t *col_dofs,
				   struct irdm_corr_sparse *s, size_t max_rank,
				   irdm_progress_fn progress, void *ctx,
				   struct irdm_corr_lowrank *out, char *err, size_t errlen);

/* The far field's block for a force at column col_f and the displacement
 * of column col_d: out[3i + j] = sum_t u[3 col_d + i][t] u[3 col_f + j][t]
 * lambda[t] (0 for rank 0). */
void irdm_corr_lowrank_block(const struct irdm_corr_lowrank *lr, size_t col_f, size_t col_d,
			     double out[9]);

/* Free what irdm_static_correction_lowrank() allocated and zero lr. */
void irdm_corr_lowrank_free(struct irdm_corr_lowrank *lr);

#endif
