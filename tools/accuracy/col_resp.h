/* SPDX-License-Identifier: MIT */
/*
 * Columns' responses to themselves summed from the modes, a batch of
 * columns at a time, by matrix products (BLAS):
 *   R_c[s] = sum_d phi_d(c) phi_d(c)^T x_d[s]
 * for per-mode sequences x (a mode's response, or an image's version of
 * it).  What the screen (screen.h) and the scan (scan.h) run on every
 * touchable column.
 *
 * Most modes of a stiffness-damped model die within a few ticks, so the
 * modes are put longest-lasting first and each stretch of samples (0-3,
 * 4-15, 16-63, ...) sums only the modes still over 1e-12 of their own
 * peak in it: the same sums, less the samples below that.
 */
#ifndef IRDM_TOOLS_ACCURACY_COL_RESP_H
#define IRDM_TOOLS_ACCURACY_COL_RESP_H

#include <stddef.h>
#include <stdint.h>

#include "modal/modal.h"

#define IRDM_COL_RESP_MAX_X 2 /* sequences per mode */

struct irdm_col_resp {
	const struct irdm_modes *m;
	size_t n, n_x;                  /* samples; sequences per mode */
	double *x[IRDM_COL_RESP_MAX_X]; /* n_modes x n each, row-major */
	size_t *perm;                   /* after ready: longest-lasting first */
	size_t *alive;                  /* samples that count, in perm's order */
	size_t batch;                   /* columns a run takes at most */
	double *o;                      /* 9 batch x n_modes: the outer products */
};

/*
 * r for m's modes, n_x sequences of n samples each: the caller fills
 * r->x[k][d n + s] for mode d (m's order), then calls ready.
 * Return: IRDM_OK; IRDM_ENOMEM (r freed).
 */
int irdm_col_resp_init(struct irdm_col_resp *r, const struct irdm_modes *m, size_t n, size_t n_x);
int irdm_col_resp_ready(struct irdm_col_resp *r);
void irdm_col_resp_free(struct irdm_col_resp *r);

/* Columns c0 .. c0 + nb - 1 of col_dofs (3 free DoFs or -1 each; nb at
 * most r->batch): out[k][(9 c + q) n + s] = R_c[s][q] of sequence k. */
void irdm_col_resp_run(struct irdm_col_resp *r, const int64_t *col_dofs, size_t c0, size_t nb,
		       double *const *out);

/* Samples of x[0..n) up to its last over 1e-12 of its peak: past them
 * a mode adds nothing the forces can show. */
size_t irdm_col_resp_alive_len(const double *x, size_t n);

/* One column's R (n x 9, [s][q]) out of a run's out[k]. */
void irdm_col_resp_column(const double *out, size_t c, size_t n, double *R);

#endif
