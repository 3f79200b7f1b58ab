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

/* A LAPACK workspace query's answer as a count; -1 past int. */
static int work_size(double q)
{
	return q < INT_MAX ? (int)q : -1;
}

/*
 * One workspace for dsytrd, dstedc into z and, with_ormtr, dormtr on A
 * (n x n), as their queries ask (dstedc's n^2 is the largest).  Returns
 * 0, or -1 out of memory (*work and *iwork then whatever was allocated).
 */
static int workspace(double *a, int n, double *d, double *e, double *tau, double *z,
		     bool with_ormtr, double **work, int *lwork, int **iwork, int *liwork)
{
	double q[3] = { 0, 0, 0 };
	int query = -1, iq = 0, info = 0;

	dsytrd_("L", &n, a, &n, d, e, tau, &q[0], &query, &info);
	dstedc_("I", &n, d, e, z, &n, &q[1], &query, &iq, &query, &info);
	if (with_ormtr)
		dormtr_("L", "L", "N", &n, &n, a, &n, tau, z, &n, &q[2], &query, &info);
	*lwork = work_size(fmax(q[0], fmax(q[1], q[2])));
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
	if (workspace(a, n, w2, e, tau, phi, true, &work, &lwork, &iwork, &liwork))
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

struct irdm_eig_rest {
	int n;
	double *a;     /* dsytrd's Householder vectors, lower triangle */
	double *tau;   /* their scalar factors, n - 1 */
	double *z;     /* the tridiagonal's eigenvectors, n x n */
	double *dsqrt; /* the lumped mass's square root */
};

void irdm_eig_rest_free(struct irdm_eig_rest *r)
{
	if (!r)
		return;
	free(r->a);
	free(r->tau);
	free(r->z);
	free(r->dsqrt);
	free(r);
}

/* C <- op(Q) C, C n x k; trans "N" or "T".  0, -1 out of memory, or info. */
static int apply_q(const struct irdm_eig_rest *r, const char *trans, double *c, int k)
{
	double q = 0, *work;
	int lwork = -1, info = 0;

	if (k == 0)
		return 0;
	dormtr_("L", "L", trans, &r->n, &k, r->a, &r->n, r->tau, c, &r->n, &q, &lwork, &info);
	lwork = work_size(q);
	work = lwork > 0 ? malloc((size_t)lwork * sizeof(double)) : NULL;
	if (!work)
		return -1;
	dormtr_("L", "L", trans, &r->n, &k, r->a, &r->n, r->tau, c, &r->n, work, &lwork, &info);
	free(work);
	return info;
}

int irdm_eig_rest_fill(const struct irdm_eig_rest *r, const size_t *z_cols, size_t k, double *out)
{
	size_t n = (size_t)r->n;
	int ret;

	for (size_t j = 0; j < k; j++)
		memcpy(&out[j * n], &r->z[z_cols[j] * n], n * sizeof(double));
	ret = apply_q(r, "N", out, (int)k);
	if (ret)
		return ret < 0 ? IRDM_ENOMEM : IRDM_ENUMERIC;
	for (size_t j = 0; j < k; j++)
		for (size_t i = 0; i < n; i++)
			out[j * n + i] /= r->dsqrt[i];
	return IRDM_OK;
}

/* phi's rows at[] of every mode: (Q^T E_at)^T Z, scaled by M^-1/2; NaN
 * at every other row. */
static int rows_at(const struct irdm_eig_rest *r, const int64_t *at, size_t n_at, double *phi)
{
	size_t n = (size_t)r->n;
	int t = (int)n_at, ni = r->n, ret;
	double one = 1.0, zero = 0.0;
	double *c = calloc(n * (n_at ? n_at : 1), sizeof(double));
	double *y = malloc(n * (n_at ? n_at : 1) * sizeof(double));

	ret = -1;
	if (!c || !y)
		goto out;
	for (size_t i = 0; i < n_at; i++)
		c[i * n + (size_t)at[i]] = 1.0;
	ret = apply_q(r, "T", c, t);
	if (ret)
		goto out;
	/* y (t x n) = C^T Z: row i, mode k */
	if (t)
		dgemm_("T", "N", &t, &ni, &ni, &one, c, &ni, r->z, &ni, &zero, y, &t);
	for (size_t i = 0; i < n * n; i++)
		phi[i] = NAN;
	for (size_t k = 0; k < n; k++)
		for (size_t i = 0; i < n_at; i++)
			phi[k * n + (size_t)at[i]] = y[k * n_at + i] / r->dsqrt[at[i]];
out:
	free(c);
	free(y);
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
	lwork = work_size(wq);
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
	bool diag = mass_is_diagonal(&fem->M), all = n_lowest == fem->K.n;
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

/*
 * Every eigenpair of a lumped-mass model, each vector only at the n_at
 * free DoFs at[] (NaN elsewhere, in phi: n x n); *rest makes chosen
 * vectors whole (irdm_eig_rest_fill).  A consistent mass: every vector
 * whole and *rest NULL (its L^-T mixes the rows).  Progress (NULL: none)
 * after each step, by its share of the flops on the paper's cuboid.
 */
int irdm_eig_dense_at(const struct irdm_fem *fem, const int64_t *at, size_t n_at,
		      irdm_progress_fn progress, void *ctx, double *w2, double *phi,
		      struct irdm_eig_rest **rest, char *err, size_t errlen)
{
	struct irdm_eig_rest *r = NULL;
	double *e = NULL, *work = NULL;
	int *iwork = NULL, lwork = -1, liwork = -1, info = 0, n = (int)fem->K.n;
	const char *step = "dsytrd";
	int ret = IRDM_ENOMEM;

	*rest = NULL;
	if (!mass_is_diagonal(&fem->M))
		return irdm_eig_dense(fem, fem->K.n, w2, phi, err, errlen);
	r = calloc(1, sizeof(*r));
	if (!r)
		goto out_nomem;
	r->n = n;
	r->a = irdm_csc_to_dense(&fem->K);
	r->tau = malloc((size_t)n * sizeof(double));
	r->dsqrt = malloc((size_t)n * sizeof(double));
	e = malloc((size_t)n * sizeof(double));
	if (!r->a || !r->tau || !r->dsqrt || !e)
		goto out_nomem;
	reduce_to_standard(fem, r->a, NULL, r->dsqrt, true);
	/* Z first lands in phi, moved out once dstedc's n^2 workspace is
	 * given back: three n x n arrays at most, as the whole solve */
	if (workspace(r->a, n, w2, e, r->tau, phi, false, &work, &lwork, &iwork, &liwork))
		goto out_nomem;
	dsytrd_("L", &n, r->a, &n, w2, e, r->tau, work, &lwork, &info);
	if (!info) {
		if (progress)
			progress(ctx, "dense eigensolve: tridiagonal", 0.75);
		step = "dstedc";
		dstedc_("I", &n, w2, e, phi, &n, work, &lwork, iwork, &liwork, &info);
	}
	free(work);
	work = NULL;
	if (!info) {
		r->z = malloc((size_t)n * (size_t)n * sizeof(double));
		if (!r->z)
			goto out_nomem;
		memcpy(r->z, phi, (size_t)n * (size_t)n * sizeof(double));
		if (progress)
			progress(ctx, "dense eigensolve: its eigenvectors", 0.95);
		step = "dormtr";
		info = rows_at(r, at, n_at, phi);
	}
	if (info < 0)
		goto out_nomem;
	if (info) {
		snprintf(err, errlen, "dense eigensolver: %s failed (info %d)", step, info);
		ret = IRDM_ENUMERIC;
		goto out_free;
	}
	*rest = r;
	r = NULL;
	ret = IRDM_OK;
	goto out_free;

out_nomem:
	snprintf(err, errlen, "dense eigensolver: out of memory for n = %d (needs %.1f GiB)", n,
		 3.0 * n * (double)n * 8 / (1 << 30));
out_free:
	irdm_eig_rest_free(r);
	free(e);
	free(work);
	free(iwork);
	return ret;
}
