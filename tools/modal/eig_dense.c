/* SPDX-License-Identifier: MIT */
/*
 * Dense generalised eigensolver: M = L L^T (diagonal square root for a
 * lumped mass, Cholesky otherwise), A = L^-1 K L^-T, MRRR (dsyevr) for the
 * lowest eigenpairs of A, phi = L^-T y.  O(n^3); used for small models, for
 * "all modes", and as the independent check of the Lanczos solver.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "modal/lapack.h"
#include "modal/modal.h"

static bool mass_is_diagonal(const struct irdm_csc *m)
{
	for (size_t j = 0; j < m->n; j++)
		for (int64_t p = m->colptr[j]; p < m->colptr[j + 1]; p++)
			if ((size_t)m->rowind[p] != j && m->val[p] != 0.0)
				return false;
	return true;
}

/* A <- L^-1 K L^-T in place; l holds the factor (dense) or NULL when diag. */
static int reduce_to_standard(const struct irdm_fem *fem, double *a, double *l,
			      double *dsqrt, bool diag)
{
	int n = (int)fem->K.n, info = 0, one = 1;

	if (diag) {
		for (size_t j = 0; j < fem->M.n; j++)
			for (int64_t p = fem->M.colptr[j]; p < fem->M.colptr[j + 1]; p++)
				if ((size_t)fem->M.rowind[p] == j)
					dsqrt[j] = sqrt(fem->M.val[p]);
		for (int j = 0; j < n; j++)
			for (int i = 0; i < n; i++)
				a[(size_t)j * n + i] /= dsqrt[i] * dsqrt[j];
		return 0;
	}
	dpotrf_("L", &n, l, &n, &info);
	if (info)
		return info;
	dsygst_(&one, "L", &n, a, &n, l, &n, &info);
	return info;
}

int irdm_eig_dense(const struct irdm_fem *fem, size_t n_lowest, double *w2, double *phi,
		   char *err, size_t errlen)
{
	int n = (int)fem->K.n, il = 1, iu = (int)n_lowest, m = 0, info = 0;
	int lwork = -1, liwork = -1, iwq = 0;
	double abstol = 0, vl = 0, vu = 0, wq = 0, one = 1.0;
	bool diag = mass_is_diagonal(&fem->M);
	double *a = irdm_csc_to_dense(&fem->K);
	double *l = diag ? NULL : irdm_csc_to_dense(&fem->M);
	double *dsqrt = malloc((size_t)n * sizeof(double));
	int *isuppz = malloc(2 * (size_t)n * sizeof(int));
	double *work = NULL;
	int *iwork = NULL;
	int ret = IRDM_ENUMERIC;

	if (!a || (!diag && !l) || !dsqrt || !isuppz)
		goto out_nomem;
	info = reduce_to_standard(fem, a, l, dsqrt, diag);
	if (info) {
		snprintf(err, errlen, "dense eigensolver: mass matrix not positive definite (LAPACK info %d)", info);
		goto out_free;
	}
	dsyevr_("V", "I", "L", &n, a, &n, &vl, &vu, &il, &iu, &abstol, &m, w2, phi, &n,
		isuppz, &wq, &lwork, &iwq, &liwork, &info);
	lwork = (int)wq;
	liwork = iwq;
	work = malloc((size_t)lwork * sizeof(double));
	iwork = malloc((size_t)liwork * sizeof(int));
	if (!work || !iwork)
		goto out_nomem;
	dsyevr_("V", "I", "L", &n, a, &n, &vl, &vu, &il, &iu, &abstol, &m, w2, phi, &n,
		isuppz, work, &lwork, iwork, &liwork, &info);
	if (info || m != iu) {
		snprintf(err, errlen, "dense eigensolver: dsyevr failed (info %d, %d of %d modes)",
			 info, m, iu);
		goto out_free;
	}
	/* Back-transform: phi = L^-T y. */
	if (diag) {
		for (int j = 0; j < m; j++)
			for (int i = 0; i < n; i++)
				phi[(size_t)j * n + i] /= dsqrt[i];
	} else {
		dtrsm_("L", "L", "T", "N", &n, &m, &one, l, &n, phi, &n);
	}
	ret = IRDM_OK;
	goto out_free;

out_nomem:
	snprintf(err, errlen, "dense eigensolver: out of memory for n = %d (needs %.1f GiB)",
		 n, 2.0 * n * (double)n * 8 / (1 << 30));
	ret = IRDM_ENOMEM;
out_free:
	free(a);
	free(l);
	free(dsqrt);
	free(isuppz);
	free(work);
	free(iwork);
	return ret;
}
