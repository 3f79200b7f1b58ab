/* SPDX-License-Identifier: MIT */
/*
 * Sparse Cholesky factors of ck K + cm M: the Newmark effective matrix, the
 * Lanczos shift K - sigma M, the static solve K (+ eps M).  K and M may have
 * different patterns (lumped M is diagonal, consistent M shares K's), so
 * the sum is built by merging their columns.
 */
#include <stdio.h>

#include "fem/factor.h"

/*
 * Merge column j of cm M + ck K, rows <= j only (CHOLMOD with stype = 1
 * reads the upper triangle).  Rows are sorted in both inputs, so the result
 * is sorted too.  With rows == NULL only counts.
 */
static size_t merge_upper(const struct irdm_csc *k, const struct irdm_csc *m, double ck,
			  double cm, const double *diag, size_t j, SuiteSparse_long *rows,
			  double *vals)
{
	int64_t pk = k->colptr[j], ek = k->colptr[j + 1];
	int64_t pm = m->colptr[j], em = m->colptr[j + 1];
	size_t n = 0;

	for (;;) {
		int64_t rk = pk < ek ? k->rowind[pk] : INT64_MAX;
		int64_t rm = pm < em ? m->rowind[pm] : INT64_MAX;
		int64_t r = rk < rm ? rk : rm;
		double v = 0.0;

		if (r > (int64_t)j)
			break;
		if (rk == r)
			v += ck * k->val[pk++];
		if (rm == r)
			v += cm * m->val[pm++];
		if (diag && r == (int64_t)j)
			v += diag[j];
		if (rows) {
			rows[n] = r;
			vals[n] = v;
		}
		n++;
	}
	return n;
}

static cholmod_sparse *build_s(const struct irdm_fem *fem, double cm, double ck,
			       const double *diag, cholmod_common *cc)
{
	size_t n = fem->K.n, nnz = 0;
	cholmod_sparse *s;

	for (size_t j = 0; j < n; j++)
		nnz += merge_upper(&fem->K, &fem->M, ck, cm, diag, j, NULL, NULL);
	s = cholmod_l_allocate_sparse(n, n, nnz, 1, 1, 1, CHOLMOD_REAL, cc);
	if (!s)
		return NULL;
	SuiteSparse_long *p = s->p, *i = s->i;
	double *x = s->x;

	p[0] = 0;
	for (size_t j = 0; j < n; j++)
		p[j + 1] = p[j] + (SuiteSparse_long)merge_upper(&fem->K, &fem->M, ck, cm, diag,
								j, &i[p[j]], &x[p[j]]);
	return s;
}

int irdm_fem_factor(const struct irdm_fem *fem, double ck, double cm, const char *what,
		    cholmod_common *cc, cholmod_factor **L, char *err, size_t errlen)
{
	return irdm_fem_factor_diag(fem, ck, cm, NULL, what, cc, L, err, errlen);
}

int irdm_fem_factor_diag(const struct irdm_fem *fem, double ck, double cm, const double *diag,
			 const char *what, cholmod_common *cc, cholmod_factor **L, char *err,
			 size_t errlen)
{
	cholmod_sparse *s = build_s(fem, cm, ck, diag, cc);
	int ret;

	*L = NULL;
	if (!s) {
		snprintf(err, errlen, "%s: out of memory building the matrix (%zu DoFs)",
			 what, fem->K.n);
		return IRDM_ENOMEM;
	}
	/*
	 * Every solve (each time step of each input, each Lanczos step) uses
	 * this factor, so its fill is worth a second ordering: try AMD and
	 * METIS (CHOLMOD's default tries METIS only for very dense factors)
	 * and keep the sparser.  On 3D
	 * meshes METIS typically wins by ~40 %.  Both are deterministic.
	 */
	cc->nmethods = 3; /* given ordering (none: skipped), AMD, METIS */
	*L = cholmod_l_analyze(s, cc);
	if (!*L) {
		snprintf(err, errlen, "%s: CHOLMOD analysis failed (status %d)", what,
			 cc->status);
		ret = cc->status == CHOLMOD_OUT_OF_MEMORY ? IRDM_ENOMEM : IRDM_ENUMERIC;
		goto out_free_s;
	}
	/* factorize returns true on a non-SPD matrix too; the status tells */
	if (!cholmod_l_factorize(s, *L, cc) || cc->status == CHOLMOD_NOT_POSDEF) {
		if (cc->status == CHOLMOD_NOT_POSDEF)
			snprintf(err, errlen,
				 "%s: %g K + %g M is not positive definite at free DoF %ld (too few fixed nodes?)",
				 what, ck, cm, (long)(*L)->minor);
		else
			snprintf(err, errlen, "%s: CHOLMOD factorisation failed (status %d)",
				 what, cc->status);
		ret = cc->status == CHOLMOD_OUT_OF_MEMORY ? IRDM_ENOMEM : IRDM_ENUMERIC;
		goto out_free_l;
	}
	cholmod_l_free_sparse(&s, cc);
	return IRDM_OK;

out_free_l:
	cholmod_l_free_factor(L, cc);
out_free_s:
	cholmod_l_free_sparse(&s, cc);
	return ret;
}
