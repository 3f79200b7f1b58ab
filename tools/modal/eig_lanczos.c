/* SPDX-License-Identifier: MIT */
/*
 * Shift-invert Lanczos for the lowest modes of a large sparse model:
 * ARPACK (implicitly restarted Lanczos, mode 3) with OP = (K - sigma M)^-1 M
 * and B = M, the inverse applied through one CHOLMOD factorisation.  The
 * eigenvectors come out M-orthonormal.
 */
#include <math.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <arpack/arpack.h>
#include <cholmod.h>

#include "fem/factor.h"

#include "modal/modal.h"

struct op_ctx {
	cholmod_common cc;
	cholmod_factor *f;
	cholmod_dense *b;
	size_t n;
};

static int apply_inverse(struct op_ctx *o, const double *x, double *y)
{
	memcpy(o->b->x, x, o->n * sizeof(double));
	cholmod_dense *s = cholmod_l_solve(CHOLMOD_A, o->f, o->b, &o->cc);

	if (!s)
		return -1;
	memcpy(y, s->x, o->n * sizeof(double));
	cholmod_l_free_dense(&s, &o->cc);
	return 0;
}

static int run_arpack(struct op_ctx *o, const struct irdm_fem *fem, int nev, double sigma,
		      irdm_progress_fn progress, void *pctx, double *w2, double *phi,
		      char *err, size_t errlen)
{
	int n = (int)o->n, ncv = 2 * nev + 20, ido = 0, info = 0, lworkl;
	int iparam[11] = { 0 }, ipntr[11] = { 0 };
	double tol = 0.0;
	int ret = IRDM_ENUMERIC;

	if (ncv > n)
		ncv = n;
	lworkl = ncv * (ncv + 8);
	double *resid = malloc((size_t)n * sizeof(double));
	double *v = malloc((size_t)n * ncv * sizeof(double));
	double *workd = malloc(3 * (size_t)n * sizeof(double));
	double *workl = malloc((size_t)lworkl * sizeof(double));
	double *d = malloc((size_t)ncv * sizeof(double));
	int *select = calloc((size_t)ncv, sizeof(int));
	if (!resid || !v || !workd || !workl || !d || !select) {
		snprintf(err, errlen, "Lanczos: out of memory (n = %d, %d vectors)", n, ncv);
		ret = IRDM_ENOMEM;
		goto out_free;
	}
	/*
	 * A start vector of our own (info = 1): ARPACK's random one comes
	 * from a seed it keeps between calls, so the second solve in a
	 * process (a measurement's reference, a test) would start elsewhere
	 * and round differently from the first.  A fixed pseudo-random
	 * sequence has a part along every mode as a random one has.
	 */
	for (int i = 0; i < n; i++)
		resid[i] = (double)(((uint32_t)i * 2654435761u) >> 8) / (double)(1u << 24) - 0.5;
	info = 1;
	iparam[0] = 1;     /* exact shifts */
	iparam[2] = 10000; /* max restarts */
	iparam[6] = 3;     /* shift-invert, generalised */
	size_t ops = 0;
	for (;;) {
		dsaupd_c(&ido, "G", n, "LM", nev, tol, resid, ncv, v, n, iparam, ipntr,
			 workd, workl, lworkl, &info);
		double *x = &workd[ipntr[0] - 1], *y = &workd[ipntr[1] - 1];
		if (ido == -1) {
			/* y = OP x = (K - sigma M)^-1 M x */
			irdm_csc_matvec(&fem->M, x, y);
			if (apply_inverse(o, y, y))
				goto out_chol;
		} else if (ido == 1) {
			/* B x is given in workd[ipntr[2]] */
			if (apply_inverse(o, &workd[ipntr[2] - 1], y))
				goto out_chol;
		} else if (ido == 2) {
			irdm_csc_matvec(&fem->M, x, y);
		} else {
			break;
		}
		if (progress && (++ops % 64) == 0)
			progress(pctx, "Lanczos iterations", fmin(0.99, (double)ops / (4.0 * ncv)));
	}
	if (info < 0 || info == 1) {
		snprintf(err, errlen, "Lanczos (ARPACK dsaupd) failed: info %d after %zu operator applications",
			 info, ops);
		goto out_free;
	}
	dseupd_c(1, "A", select, d, v, n, sigma, "G", n, "LM", nev, tol, resid, ncv, v, n,
		 iparam, ipntr, workd, workl, lworkl, &info);
	if (info || iparam[4] < nev) {
		snprintf(err, errlen, "Lanczos (ARPACK dseupd) failed: info %d, %d of %d converged",
			 info, iparam[4], nev);
		goto out_free;
	}
	/* dseupd returns ascending eigenvalues of K x = l M x for mode 3. */
	memcpy(w2, d, (size_t)nev * sizeof(double));
	memcpy(phi, v, (size_t)n * nev * sizeof(double));
	ret = IRDM_OK;
	goto out_free;

out_chol:
	snprintf(err, errlen, "Lanczos: sparse solve failed");
out_free:
	free(resid);
	free(v);
	free(workd);
	free(workl);
	free(d);
	free(select);
	return ret;
}

int irdm_eig_lanczos(const struct irdm_fem *fem, size_t n_lowest, double sigma,
		     irdm_progress_fn progress, void *pctx, double *w2, double *phi,
		     char *err, size_t errlen)
{
	struct op_ctx o = { .n = fem->K.n };
	int ret;

	if (n_lowest >= fem->K.n) {
		snprintf(err, errlen, "Lanczos: %zu modes asked of a model with %zu DoFs; use the dense solver",
			 n_lowest, fem->K.n);
		return IRDM_EINVAL;
	}
	cholmod_l_start(&o.cc);
	o.cc.print = 0;
	if (progress)
		progress(pctx, "sparse factorisation", 0.0);
	ret = irdm_fem_factor(fem, 1.0, -sigma, "Lanczos", &o.cc, &o.f, err, errlen);
	if (ret)
		goto out_free;
	o.b = cholmod_l_allocate_dense(o.n, 1, o.n, CHOLMOD_REAL, &o.cc);
	if (!o.b) {
		snprintf(err, errlen, "Lanczos: out of memory");
		ret = IRDM_ENOMEM;
		goto out_free;
	}
	ret = run_arpack(&o, fem, (int)n_lowest, sigma, progress, pctx, w2, phi, err, errlen);
out_free:
	cholmod_l_free_dense(&o.b, &o.cc);
	cholmod_l_free_factor(&o.f, &o.cc);
	cholmod_l_finish(&o.cc);
	return ret;
}
