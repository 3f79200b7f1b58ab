/* SPDX-License-Identifier: MIT */
/* FIR responses from modes: one GEMM per sample. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "modal/lapack.h"
#include "modal/response.h"

int irdm_modes_discretise(const struct irdm_modes *m, const struct irdm_rayleigh *damp,
			  double dt_s, struct irdm_mode *out)
{
	for (size_t k = 0; k < m->n_modes; k++) {
		double w = sqrt(fmax(m->omega2[k], 0.0));
		irdm_zoh_mode(w, irdm_rayleigh_ratio(damp, w), dt_s, &out[k]);
	}
	return 0;
}

/* Gather the mode shapes of the selected DoFs: P (3*n x K), column-major. */
static double *gather(const struct irdm_modes *m, const int64_t *dofs, size_t n)
{
	size_t rows = 3 * n;
	double *p = malloc(rows * m->n_modes * sizeof(double));

	if (!p)
		return NULL;
	for (size_t k = 0; k < m->n_modes; k++)
		for (size_t i = 0; i < rows; i++)
			p[k * rows + i] = dofs[i] < 0 ? 0.0 : m->phi[k * m->n + (size_t)dofs[i]];
	return p;
}

int irdm_fir_from_modes(const struct irdm_modes *m, const struct irdm_mode *zoh,
			const int64_t *col_dofs, size_t n_cols, const int64_t *row_dofs,
			size_t n_rows, size_t T, const double *D, double *out,
			irdm_progress_fn progress, void *ctx)
{
	int K = (int)m->n_modes, nr = (int)(3 * n_rows), nc = (int)(3 * n_cols);
	double *pr = gather(m, row_dofs, n_rows), *pc = gather(m, col_dofs, n_cols);
	double *h = malloc((size_t)K * T * sizeof(double));
	double *scaled = malloc((size_t)nc * K * sizeof(double));
	double *blk = malloc((size_t)nr * nc * sizeof(double));
	double one = 1.0, zero = 0.0;
	int ret = IRDM_ENOMEM;

	if (!pr || !pc || !h || !scaled || !blk)
		goto out_free;
	for (int k = 0; k < K; k++)
		irdm_zoh_response(&zoh[k], T, &h[(size_t)k * T]);
	for (size_t s = 0; s < T; s++) {
		/* blk (nr x nc) = Pr diag(h[s]) Pc^T; scaled = Pc diag(h[s]) (nc x K) */
		for (int k = 0; k < K; k++)
			for (int i = 0; i < nc; i++)
				scaled[(size_t)k * nc + i] = pc[(size_t)k * nc + i] * h[(size_t)k * T + s];
		dgemm_("N", "T", &nr, &nc, &K, &one, pr, &nr, scaled, &nc, &zero, blk, &nr);
		for (size_t c = 0; c < n_cols; c++)
			for (size_t r = 0; r < n_rows; r++)
				for (int i = 0; i < 3; i++)
					for (int j = 0; j < 3; j++) {
						size_t o = (((c * n_rows + r) * T + s) * 3 + i) * 3 + j;
						double v = blk[(3 * c + j) * (size_t)nr + 3 * r + i];
						if (s == 0 && D)
							v += D[((c * n_rows + r) * 3 + i) * 3 + j];
						out[o] = v;
					}
		if (progress && (s % 16 == 0 || s + 1 == T))
			progress(ctx, "FIR responses", (double)(s + 1) / T);
	}
	ret = IRDM_OK;
out_free:
	free(pr);
	free(pc);
	free(h);
	free(scaled);
	free(blk);
	return ret;
}
