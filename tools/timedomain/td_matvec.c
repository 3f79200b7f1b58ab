/* SPDX-License-Identifier: MIT */
/* Block sparse products for the time-domain integrator. */
#include "timedomain/td_priv.h"

/* Y = A X for k columns (n x k, column-major): one pass over A. */
void irdm_td_matvec_block(const struct irdm_csc *a, const double *x, double *y, size_t k)
{
	size_t n = a->n;

	for (size_t i = 0; i < n * k; i++)
		y[i] = 0.0;
	for (size_t j = 0; j < n; j++) {
		for (int64_t p = a->colptr[j]; p < a->colptr[j + 1]; p++) {
			size_t r = (size_t)a->rowind[p];
			double v = a->val[p];

			for (size_t c = 0; c < k; c++)
				y[c * n + r] += v * x[c * n + j];
		}
	}
}
