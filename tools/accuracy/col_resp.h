/* SPDX-License-Identifier: MIT */
/*
 * Columns' responses to themselves summed from the modes, a batch of
 * columns at a time, as one matrix product per batch (BLAS):
 *   R_c[s] = sum_d phi_d(c) phi_d(c)^T x_d[s]
 * for any per-mode sequence x (a mode's response, or what an image
 * misses of it).  What the screen (screen.h) and the scan (scan.h) run
 * on every touchable column.
 */
#ifndef IRDM_TOOLS_ACCURACY_COL_RESP_H
#define IRDM_TOOLS_ACCURACY_COL_RESP_H

#include <stddef.h>
#include <stdint.h>

#include "modal/modal.h"

/* Columns per batch for m's modes: the outer products stay under 32 MiB. */
size_t irdm_col_resp_batch(const struct irdm_modes *m);

/* The batch's outer products, o (9 nb x n_modes): columns c0 .. c0 + nb - 1
 * of col_dofs (3 free DoFs or -1 each). */
void irdm_col_resp_outer(const struct irdm_modes *m, const int64_t *col_dofs, size_t c0,
			 size_t nb, double *o);

/* out[(9 c + q) n + s] = R_c[s][q] for the batch of o, x: n_modes x n
 * (row-major). */
void irdm_col_resp_apply(const struct irdm_modes *m, const double *o, size_t nb, const double *x,
			 size_t n, double *out);

/* One column's R (n x 9, [s][q]) out of the batch's out. */
void irdm_col_resp_column(const double *out, size_t c, size_t n, double *R);

#endif
