/* SPDX-License-Identifier: MIT */
/*
 * Static compliance and the static correction of a truncated modal basis.
 *
 * Grounded: G = K^-1 by one sparse Cholesky factorisation.
 * Floating: K is singular (rigid motion).  The elastic compliance G solves
 * K x = P f with P = I - M Phi_r Phi_r^T removing the rigid part of the load
 * and x M-orthogonal to the rigid modes.  We factor the definite K + eps M
 * and refine: x <- (K + eps M)^-1 (P f + eps M x), which converges by
 * eps / (w1^2 + eps) per step on elastic modes; eps = 1e-2 w1^2 keeps the
 * factor well conditioned and reaches double precision in 8 steps.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cholmod.h>

#include "fem/factor.h"

#include "modal/response.h"

#define REFINE_STEPS 8

/* x <- x - Phi_r Phi_r^T M x for each of the n_in columns. */
static void remove_rigid(const struct irdm_fem *fem, const struct irdm_modes *m,
			 double *x, size_t n_in, double *tmp)
{
	size_t n = m->n;

	for (size_t c = 0; c < n_in; c++) {
		double *xc = &x[c * n];
		irdm_csc_matvec(&fem->M, xc, tmp);
		for (size_t r = 0; r < m->n_rigid; r++) {
			const double *phi = &m->rigid_phi[r * n];
			double a = 0;
			for (size_t i = 0; i < n; i++)
				a += phi[i] * tmp[i];
			for (size_t i = 0; i < n; i++)
				xc[i] -= a * phi[i];
		}
	}
}

/* P e_j: the load e_j without its rigid part, M Phi_r Phi_r^T e_j removed. */
static void elastic_load(const struct irdm_fem *fem, const struct irdm_modes *m, int64_t j,
			 double *f, double *tmp)
{
	size_t n = m->n;

	memset(f, 0, n * sizeof(double));
	f[j] = 1.0;
	if (!m->n_rigid)
		return;
	memset(tmp, 0, n * sizeof(double));
	for (size_t r = 0; r < m->n_rigid; r++)
		for (size_t i = 0; i < n; i++)
			tmp[i] += m->rigid_phi[r * n + i] * m->rigid_phi[r * n + (size_t)j];
	double *mt = malloc(n * sizeof(double));
	if (!mt)
		return;
	irdm_csc_matvec(&fem->M, tmp, mt);
	for (size_t i = 0; i < n; i++)
		f[i] -= mt[i];
	free(mt);
}

int irdm_compliance_solve(const struct irdm_fem *fem, const struct irdm_modes *m,
			  bool floating, const int64_t *in, size_t n_in, double *X,
			  char *err, size_t errlen)
{
	size_t n = fem->K.n;
	double eps = floating ? 1e-2 * m->omega2[0] : 0.0;
	cholmod_common cc;
	cholmod_factor *f = NULL;
	cholmod_dense *rhs = NULL, *sol = NULL;
	double *tmp = malloc(n * sizeof(double)), *load = NULL;
	int ret;

	cholmod_l_start(&cc);
	cc.print = 0;
	rhs = cholmod_l_allocate_dense(n, n_in, n, CHOLMOD_REAL, &cc);
	load = malloc(n * n_in * sizeof(double));
	if (!rhs || !tmp || !load) {
		snprintf(err, errlen, "static compliance: out of memory");
		ret = IRDM_ENOMEM;
		goto out_free;
	}
	ret = irdm_fem_factor(fem, 1.0, eps, "static compliance", &cc, &f, err, errlen);
	if (ret)
		goto out_free;
	for (size_t c = 0; c < n_in; c++)
		elastic_load(fem, m, in[c], &load[c * n], tmp);
	memset(X, 0, n * n_in * sizeof(double));
	for (int step = 0; step < (floating ? REFINE_STEPS : 1); step++) {
		double *b = rhs->x;
		for (size_t c = 0; c < n_in; c++) {
			irdm_csc_matvec(&fem->M, &X[c * n], tmp);
			for (size_t i = 0; i < n; i++)
				b[c * n + i] = load[c * n + i] + eps * tmp[i];
		}
		cholmod_l_free_dense(&sol, &cc);
		sol = cholmod_l_solve(CHOLMOD_A, f, rhs, &cc);
		if (!sol) {
			snprintf(err, errlen, "static compliance: sparse solve failed");
			ret = cc.status == CHOLMOD_OUT_OF_MEMORY ? IRDM_ENOMEM : IRDM_ENUMERIC;
			goto out_free;
		}
		memcpy(X, sol->x, n * n_in * sizeof(double));
		if (floating)
			remove_rigid(fem, m, X, n_in, tmp);
	}
	ret = IRDM_OK;
out_free:
	free(tmp);
	free(load);
	cholmod_l_free_dense(&sol, &cc);
	cholmod_l_free_dense(&rhs, &cc);
	cholmod_l_free_factor(&f, &cc);
	cholmod_l_finish(&cc);
	return ret;
}

int irdm_static_correction(const struct irdm_fem *fem, const struct irdm_modes *m,
			   bool floating, const int64_t *col_dofs, size_t n_cols,
			   const int64_t *row_dofs, size_t n_rows, double *out,
			   char *err, size_t errlen)
{
	size_t n = m->n, n_in = 0;
	int64_t *in = malloc(3 * n_cols * sizeof(int64_t));
	size_t *slot = malloc(3 * n_cols * sizeof(size_t));
	double *X = NULL;
	const double *Xr;
	int ret = IRDM_OK;

	if (!in || !slot)
		goto out_nomem;
	for (size_t c = 0; c < 3 * n_cols; c++)
		if (col_dofs[c] >= 0) {
			slot[c] = n_in;
			in[n_in++] = col_dofs[c];
		}
	if (m->compliance && m->n_compliance == n_in) {
		/* solved over the MPI ranks with the eigensolve's factor */
		Xr = m->compliance;
	} else {
		X = malloc(n * (n_in ? n_in : 1) * sizeof(double));
		if (!X)
			goto out_nomem;
		if (n_in)
			ret = irdm_compliance_solve(fem, m, floating, in, n_in, X, err, errlen);
		if (ret)
			goto out_free;
		Xr = X;
	}
	for (size_t c = 0; c < n_cols; c++)
		for (size_t r = 0; r < n_rows; r++)
			for (int i = 0; i < 3; i++)
				for (int j = 0; j < 3; j++) {
					int64_t ri = row_dofs[3 * r + i], cj = col_dofs[3 * c + j];
					double v = 0;
					if (ri >= 0 && cj >= 0) {
						v = Xr[slot[3 * c + j] * n + (size_t)ri];
						for (size_t k = 0; k < m->n_modes; k++)
							v -= m->phi[k * n + (size_t)ri] * m->phi[k * n + (size_t)cj]
							     / m->omega2[k];
					}
					out[((c * n_rows + r) * 3 + i) * 3 + j] = v;
				}
	goto out_free;
out_nomem:
	snprintf(err, errlen, "static correction: out of memory");
	ret = IRDM_ENOMEM;
out_free:
	free(in);
	free(slot);
	free(X);
	return ret;
}
