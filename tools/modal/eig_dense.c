/* SPDX-License-Identifier: MIT */
/*
 * Dense generalised eigensolver: M = L L^T (diagonal square root for a
 * lumped mass, Cholesky otherwise), A = L^-1 K L^-T, the lowest eigenpairs
 * of A, phi = L^-T y.  O(n^3); used for small models, for "all modes", and
 * as the independent check of the Lanczos solver.
 *
 * Every mode: dsyevd's steps (Householder tridiagonalisation dsytrd,
 * divide and conquer dstedc on the tridiagonal, back-transformation
 * dormtr), written out so that the tridiagonal's eigenvectors land in phi
 * and no second n x n copy is made.  Not dsyevr: on some meshes' spectra,
 * full of nearly equal eigenvalues, its MRRR step (dstemr) gives up and
 * it starts again by bisection and inverse iteration, about 3 times
 * slower in all (the 8 x 8 x 16 cuboid: IRDM_BENCH_RES=8,8,16
 * build/bench/bench_eig_dense); where dstemr succeeds (the paper's
 * cuboid) the two take the same time, the reduction and the
 * back-transformation being most of it (make bench_eig_dense).  A subset
 * (n_lowest < n): dsyevr, RANGE = I, which computes only the vectors
 * asked for.
 */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "modal/lapack.h"
#include "modal/eig_dense_priv.h"
#include "modal/modal.h"

bool irdm_eig_mass_is_diagonal(const struct irdm_csc *m)
{
	for (size_t j = 0; j < m->n; j++)
		for (int64_t p = m->colptr[j]; p < m->colptr[j + 1]; p++)
			if ((size_t)m->rowind[p] != j && m->val[p] != 0.0)
				return false;
	return true;
}

void irdm_eig_mass_sqrt(const struct irdm_csc *m, double *dsqrt)
{
	for (size_t j = 0; j < m->n; j++)
		for (int64_t p = m->colptr[j]; p < m->colptr[j + 1]; p++)
			if ((size_t)m->rowind[p] == j)
				dsqrt[j] = sqrt(m->val[p]);
}

/* A <- L^-1 K L^-T in place; l holds the factor (dense) or NULL when diag. */
static int reduce_to_standard(const struct irdm_fem *fem, double *a, double *l,
			      double *dsqrt, bool diag)
{
	int n = (int)fem->K.n, info = 0, one = 1;

	if (diag) {
		irdm_eig_mass_sqrt(&fem->M, dsqrt);
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

/* A LAPACK workspace query's answer as a count; -1 past int. */
int irdm_eig_work_size(double q)
{
	return q < INT_MAX ? (int)q : -1;
}

/*
 * One workspace for dsytrd, dstedc into z and, with_ormtr, dormtr on A
 * (n x n), as their queries ask (dstedc's n^2 is the largest).  Returns
 * 0, or -1 out of memory (*work and *iwork then whatever was allocated).
 */
int irdm_eig_workspace(double *a, int n, double *d, double *e, double *tau, double *z,
		       bool with_ormtr, double **work, int *lwork, int **iwork, int *liwork)
{
	double q[3] = { 0, 0, 0 };
	int query = -1, iq = 0, info = 0;

	dsytrd_("L", &n, a, &n, d, e, tau, &q[0], &query, &info);
	dstedc_("I", &n, d, e, z, &n, &q[1], &query, &iq, &query, &info);
	if (with_ormtr)
		dormtr_("L", "L", "N", &n, &n, a, &n, tau, z, &n, &q[2], &query, &info);
	*lwork = irdm_eig_work_size(fmax(q[0], fmax(q[1], q[2])));
	*liwork = iq;
	if (*lwork < 0)
		return -1;
	*work = malloc((size_t)*lwork * sizeof(double));
	*iwork = malloc((size_t)*liwork * sizeof(int));
	return *work && *iwork ? 0 : -1;
}

/*
 * Every eigenpair of A (destroyed: it keeps the Householder vectors):
 * w2 ascending, y in phi.  Returns 0, -1 out of memory, or LAPACK's info
 * (> 0: dstedc failed to converge).
 */
static int solve_all(double *a, int n, double *w2, double *phi, const char **step)
{
	double *e = malloc((size_t)n * sizeof(double));
	double *tau = malloc((size_t)n * sizeof(double));
	double *work = NULL;
	int *iwork = NULL, lwork = -1, liwork = -1, info = 0, ret = -1;

	if (!e || !tau)
		goto out;
	if (irdm_eig_workspace(a, n, w2, e, tau, phi, true, &work, &lwork, &iwork, &liwork))
		goto out;
	*step = "dsytrd";
	dsytrd_("L", &n, a, &n, w2, e, tau, work, &lwork, &info);
	if (!info) {
		*step = "dstedc";
		dstedc_("I", &n, w2, e, phi, &n, work, &lwork, iwork, &liwork, &info);
	}
	if (!info) {
		*step = "dormtr";
		dormtr_("L", "L", "N", &n, &n, a, &n, tau, phi, &n, work, &lwork, &info);
	}
	ret = info;
out:
	free(e);
	free(tau);
	free(work);
	free(iwork);
	return ret;
}

/* The lowest iu eigenpairs of A (destroyed), MRRR.  Same returns; m:
 * how many it found. */
static int solve_lowest(double *a, int n, int iu, double *w2, double *phi, int *m)
{
	int il = 1, lwork = -1, liwork = -1, iwq = 0, info = 0, ret = -1;
	double abstol = 0, vl = 0, vu = 0, wq = 0;
	int *isuppz = malloc(2 * (size_t)n * sizeof(int));
	double *work = NULL;
	int *iwork = NULL;

	if (!isuppz)
		goto out;
	dsyevr_("V", "I", "L", &n, a, &n, &vl, &vu, &il, &iu, &abstol, m, w2, phi, &n,
		isuppz, &wq, &lwork, &iwq, &liwork, &info);
	lwork = irdm_eig_work_size(wq);
	liwork = iwq;
	if (lwork < 0)
		goto out;
	work = malloc((size_t)lwork * sizeof(double));
	iwork = malloc((size_t)liwork * sizeof(int));
	if (!work || !iwork)
		goto out;
	dsyevr_("V", "I", "L", &n, a, &n, &vl, &vu, &il, &iu, &abstol, m, w2, phi, &n,
		isuppz, work, &lwork, iwork, &liwork, &info);
	ret = info;
out:
	free(isuppz);
	free(work);
	free(iwork);
	return ret;
}

int irdm_eig_dense(const struct irdm_fem *fem, size_t n_lowest, double *w2, double *phi,
		   char *err, size_t errlen)
{
	int n = (int)fem->K.n, m = (int)n_lowest, info = 0;
	double one = 1.0;
	bool diag = irdm_eig_mass_is_diagonal(&fem->M), all = n_lowest == fem->K.n;
	double *a = irdm_csc_to_dense(&fem->K);
	double *l = diag ? NULL : irdm_csc_to_dense(&fem->M);
	double *dsqrt = malloc((size_t)n * sizeof(double));
	const char *step = "dsyevr";
	int ret = IRDM_ENUMERIC;

	if (!a || (!diag && !l) || !dsqrt)
		goto out_nomem;
	info = reduce_to_standard(fem, a, l, dsqrt, diag);
	if (info) {
		snprintf(err, errlen, "dense eigensolver: mass matrix not positive definite (LAPACK info %d)", info);
		goto out_free;
	}
	if (all)
		info = solve_all(a, n, w2, phi, &step);
	else
		info = solve_lowest(a, n, (int)n_lowest, w2, phi, &m);
	if (info < 0)
		goto out_nomem;
	if (info || m != (int)n_lowest) {
		snprintf(err, errlen, "dense eigensolver: %s failed (info %d, %d of %zu modes)",
			 step, info, info ? 0 : m, n_lowest);
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
		 n, ((all ? 2.0 : 1.0) + !diag) * n * (double)n * 8 / (1 << 30));
	ret = IRDM_ENOMEM;
out_free:
	free(a);
	free(l);
	free(dsqrt);
	return ret;
}
