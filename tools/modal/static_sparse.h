/* SPDX-License-Identifier: MIT */
/*
 * Block-sparse static correction: the residual compliance of the dropped
 * modes between touchable nodes, keeping only the 3x3 blocks that matter.
 */
#ifndef IRDM_TOOLS_STATIC_SPARSE_H
#define IRDM_TOOLS_STATIC_SPARSE_H

#include <stdint.h>

#include "irdm/error.h"
#include "modal/modal.h"

/* Default drop tolerance (scene key static_correction_tol). */
#define IRDM_STATIC_CORR_TOL_DEFAULT 0.02

/*
 * Column c's kept blocks are k in [start[c], start[c+1]): row rows[k] (a
 * column index, increasing, c itself always present), block blocks[9k..]
 * entry [i][j] = displacement along i at column rows[k] per unit force
 * along j at column c: the layout of the image's STATIC_CORR sections.
 */
struct irdm_corr_sparse {
	size_t n_cols;
	size_t n_blocks;
	uint32_t *start;        /* n_cols + 1, then rows: the image's index */
	uint32_t *rows;         /* n_blocks, = start + n_cols + 1 */
	double *blocks;         /* n_blocks x 9 */
	double max_dropped_rel; /* largest |S_rc| / sqrt(|S_cc| |S_rr|) dropped */
};

/*
 * The static correction of irdm_static_correction() between the columns
 * (col_dofs: 3 per column, free DoF or -1), computed in batches of columns
 * without the dense n_cols^2 matrix.  Block (c, r) is dropped when its
 * Frobenius norm is below tol sqrt(|S_cc| |S_rr|) (the diagonal blocks'
 * norms); the diagonal is always kept.  The result is exactly symmetric:
 * each pair is decided once and mirrored.  Memory: O(n x batch + kept).
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_ENUMERIC (factor or solve); IRDM_EINVAL
 * if the kept blocks overflow the image's 32-bit index.
 */
int irdm_static_correction_sparse(const struct irdm_fem *fem, const struct irdm_modes *m,
				  bool floating, const int64_t *col_dofs, size_t n_cols,
				  double tol, irdm_progress_fn progress, void *ctx,
				  struct irdm_corr_sparse *out, char *err, size_t errlen);

/* The kept modes at the columns: P[3c + i][k] = phi_k at column c, axis i
 * (0 at a fixed DoF), Ps = P / omega_k^2, both 3 n_cols x n_modes and
 * allocated here (free them).  Return: IRDM_OK; IRDM_ENOMEM. */
int irdm_corr_modal_basis(const struct irdm_modes *m, const int64_t *col_dofs, size_t n_cols,
			  double **P, double **Ps);

/* Block (column c, row r)'s index in s, or -1 if dropped (a column's
 * rows increase: a binary search). */
long irdm_corr_sparse_find(const struct irdm_corr_sparse *s, size_t c, uint32_t r);

/* Free what irdm_static_correction_sparse() allocated and zero s. */
void irdm_corr_sparse_free(struct irdm_corr_sparse *s);

#endif
