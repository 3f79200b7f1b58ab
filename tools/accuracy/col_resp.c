/* SPDX-License-Identifier: MIT */
/* Columns' responses to themselves from the modes (col_resp.h). */
#include "accuracy/col_resp.h"
#include "modal/lapack.h"

#define BATCH_VALUES (1 << 22) /* a batch's outer products: at most this many doubles */
#define BATCH_MAX 64

size_t irdm_col_resp_batch(const struct irdm_modes *m)
{
	size_t b = BATCH_VALUES / (9 * (m->n_modes ? m->n_modes : 1));

	return b < 1 ? 1 : (b > BATCH_MAX ? BATCH_MAX : b);
}

void irdm_col_resp_outer(const struct irdm_modes *m, const int64_t *col_dofs, size_t c0,
			 size_t nb, double *o)
{
	size_t nm = m->n_modes;

	for (size_t c = 0; c < nb; c++) {
		const int64_t *dofs = &col_dofs[3 * (c0 + c)];

		for (size_t d = 0; d < nm; d++) {
			double p[3];

			for (int a = 0; a < 3; a++)
				p[a] = dofs[a] < 0 ? 0.0 : m->phi[d * m->n + (size_t)dofs[a]];
			for (int i = 0; i < 3; i++)
				for (int j = 0; j < 3; j++)
					o[(9 * c + (size_t)(3 * i + j)) * nm + d] = p[i] * p[j];
		}
	}
}

void irdm_col_resp_apply(const struct irdm_modes *m, const double *o, size_t nb, const double *x,
			 size_t n, double *out)
{
	const double one = 1, zero = 0;
	int rows = (int)(9 * nb), len = (int)n, inner = (int)m->n_modes;

	/* column-major: out (n x 9 nb) = x (n x nm) o (nm x 9 nb) */
	dgemm_("N", "N", &len, &rows, &inner, &one, x, &len, o, &inner, &zero, out, &len);
}

void irdm_col_resp_column(const double *out, size_t c, size_t n, double *R)
{
	const double *rt = &out[9 * c * n];

	for (size_t s = 0; s < n; s++)
		for (size_t q = 0; q < 9; q++)
			R[9 * s + q] = rt[q * n + s];
}
