/* SPDX-License-Identifier: MIT */
/* The windowed FIR tail with its static-compliance correction (fir_tail.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "irdm/error.h"
#include "modal/response.h"
#include "modal/window.h"
#include "precompute/fir_tail.h"

/* X (n x n_in): static compliance columns of the columns' free DoFs;
 * slot[3 c + j]: the X column of DoF j of column c (unused if fixed). */
static int compliance(const struct irdm_model *m, bool floating, double **X, size_t *slot,
		      char *err, size_t errlen)
{
	size_t n = m->modes.n, n_in = 0;
	int64_t *in = malloc(3 * m->n_cols * sizeof(int64_t));
	int ret;

	*X = NULL;
	if (!in)
		goto out_nomem;
	for (size_t c = 0; c < 3 * m->n_cols; c++)
		if (m->col_dofs[c] >= 0) {
			slot[c] = n_in;
			in[n_in++] = m->col_dofs[c];
		}
	*X = malloc(n * (n_in ? n_in : 1) * sizeof(double));
	if (!*X)
		goto out_nomem;
	ret = n_in ? irdm_compliance_solve(&m->fem, &m->modes, floating, in, n_in, *X, err, errlen) : IRDM_OK;
	free(in);
	return ret;
out_nomem:
	free(in);
	snprintf(err, errlen, "FIR tail window: out of memory for the static compliance");
	return IRDM_ENOMEM;
}

/* One (col, row) response: taper the window, then add the missing sum
 * S - sum_s R[s] along the bump. */
static void window_one(double *R, size_t T, size_t L, const double S[9], double bump_sum)
{
	double miss[9];

	for (int e = 0; e < 9; e++)
		miss[e] = S[e];
	for (size_t s = 0; s < T + L; s++) {
		double w = s < T ? 1.0 : irdm_window_taper(s - T, L);
		for (int e = 0; e < 9; e++) {
			R[9 * s + (size_t)e] *= w;
			miss[e] -= R[9 * s + (size_t)e];
		}
	}
	for (size_t i = 0; i < L; i++) {
		double a = irdm_window_bump(i, L) / bump_sum;
		for (int e = 0; e < 9; e++)
			R[9 * (T + i) + (size_t)e] += a * miss[e];
	}
}

int irdm_fir_tail_window(const struct irdm_model *m, bool floating, size_t T, size_t L,
			 double *fir, char *err, size_t errlen)
{
	size_t n = m->modes.n, *slot = malloc(3 * m->n_cols * sizeof(size_t));
	double *X = NULL, bump_sum = 0;
	int ret;

	if (!slot) {
		snprintf(err, errlen, "FIR tail window: out of memory");
		return IRDM_ENOMEM;
	}
	ret = compliance(m, floating, &X, slot, err, errlen);
	if (ret)
		goto out_free;
	for (size_t i = 0; i < L; i++)
		bump_sum += irdm_window_bump(i, L);
	for (size_t c = 0; c < m->n_cols; c++)
		for (size_t r = 0; r < m->n_rows; r++) {
			double S[9];
			for (int i = 0; i < 3; i++)
				for (int j = 0; j < 3; j++) {
					int64_t ri = m->row_dofs[3 * r + (size_t)i];
					int64_t cj = m->col_dofs[3 * c + (size_t)j];
					S[3 * i + j] = ri >= 0 && cj >= 0 ? X[slot[3 * c + (size_t)j] * n + (size_t)ri] : 0.0;
				}
			window_one(&fir[(c * m->n_rows + r) * (T + L) * 9], T, L, S, bump_sum);
		}
out_free:
	free(slot);
	free(X);
	return ret;
}
