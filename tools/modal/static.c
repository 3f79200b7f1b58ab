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
 *
 * Pinned (the batched static correction): one solve instead of eight.  Six
 * DoFs chosen so that the rigid modes restricted to them are well
 * conditioned (a statically determinate support) get a spring to ground.
 * A self-equilibrated load P f needs no reaction from such a support, so
 * the solution of (K + springs) x = P f is an exact solution of K x = P f
 * (for any spring stiffness) and differs from the elastic one by rigid
 * motion only, which remove_rigid takes out.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cholmod.h>

#include "fem/factor.h"

#include "modal/response.h"

#define REFINE_STEPS 8
/* CHOLMOD's pivot-ratio estimate of the pinned factor: 1.0e-2 measured on
 * the floating cube of test_static_sparse, 1.8e-15 with no springs */
#define MIN_RCOND 1e-10

/* y <- y + s (phi . v) phi, n entries. */
static void add_projection(const double *phi, size_t n, const double *v, double s, double *y)
{
	double a = 0;

	for (size_t i = 0; i < n; i++)
		a += phi[i] * v[i];
	for (size_t i = 0; i < n; i++)
		y[i] += s * a * phi[i];
}

/* x <- x - Phi_r Phi_r^T M x for each of the n_in columns. */
static void remove_rigid(const struct irdm_fem *fem, const struct irdm_modes *m,
			 double *x, size_t n_in, double *tmp)
{
	size_t n = m->n;

	for (size_t c = 0; c < n_in; c++) {
		irdm_csc_matvec(&fem->M, &x[c * n], tmp);
		for (size_t r = 0; r < m->n_rigid; r++)
			add_projection(&m->rigid_phi[r * n], n, tmp, -1.0, &x[c * n]);
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

/* A factor of K (+ eps M, or + pin springs) kept for batches of columns. */
struct irdm_compliance {
	const struct irdm_fem *fem;
	const struct irdm_modes *m;
	bool floating;
	int steps; /* solves per batch */
	double eps;
	cholmod_common cc;
	cholmod_factor *f;
	double *tmp;
};

/* Diagonal entry j of the CSC matrix a (0 if not stored). */
static double csc_diag(const struct irdm_csc *a, size_t j)
{
	for (int64_t p = a->colptr[j]; p < a->colptr[j + 1]; p++)
		if (a->rowind[p] == (int64_t)j)
			return a->val[p];
	return 0.0;
}

/*
 * Springs at n_rigid DoFs picked greedily (pivoted Gram-Schmidt on the rows
 * of the rigid modes): each next DoF is the one whose rigid-mode row is
 * largest outside the span of those already picked, so the rigid modes
 * restricted to the pins are as well conditioned as the mesh allows.  Each
 * spring is as stiff as K's own diagonal there.  diag: n, zeroed here.
 */
static void pin_springs(const struct irdm_fem *fem, const struct irdm_modes *m, double *diag)
{
	size_t n = m->n, nr = m->n_rigid;
	double q[6][6];

	memset(diag, 0, n * sizeof(double));
	for (size_t s = 0; s < nr && s < 6; s++) {
		double best = -1, v[6], bv[6];
		size_t bi = 0;
		for (size_t i = 0; i < n; i++) {
			double nrm = 0;
			for (size_t r = 0; r < nr; r++)
				v[r] = m->rigid_phi[r * n + i];
			for (size_t t = 0; t < s; t++) {
				double d = 0;
				for (size_t r = 0; r < nr; r++)
					d += v[r] * q[t][r];
				for (size_t r = 0; r < nr; r++)
					v[r] -= d * q[t][r];
			}
			for (size_t r = 0; r < nr; r++)
				nrm += v[r] * v[r];
			if (nrm > best && diag[i] == 0) {
				best = nrm;
				bi = i;
				memcpy(bv, v, sizeof(v));
			}
		}
		for (size_t r = 0; r < nr; r++)
			q[s][r] = bv[r] / sqrt(best);
		diag[bi] = csc_diag(&fem->K, bi);
	}
}

static int factor(struct irdm_compliance *c, enum irdm_compliance_method method, char *err,
		  size_t errlen)
{
	double *diag;
	int ret;

	c->steps = 1;
	if (!c->floating)
		return irdm_fem_factor(c->fem, 1.0, 0.0, "static compliance", &c->cc, &c->f,
				       err, errlen);
	if (method == IRDM_COMPLIANCE_SHIFTED) {
		c->eps = 1e-2 * c->m->omega2[0];
		c->steps = REFINE_STEPS;
		return irdm_fem_factor(c->fem, 1.0, c->eps, "static compliance", &c->cc, &c->f,
				       err, errlen);
	}
	diag = malloc(c->m->n * sizeof(double));
	if (!diag) {
		snprintf(err, errlen, "static compliance: out of memory");
		return IRDM_ENOMEM;
	}
	pin_springs(c->fem, c->m, diag);
	ret = irdm_fem_factor_diag(c->fem, 1.0, 0.0, diag, "static compliance (pinned)", &c->cc,
				   &c->f, err, errlen);
	free(diag);
	/* a support that leaves a rigid motion free factors K's rounding
	 * noise: refuse a pivot ratio no elastic mesh comes near */
	if (!ret && cholmod_l_rcond(c->f, &c->cc) < MIN_RCOND) {
		snprintf(err, errlen, "static compliance: the pinned support leaves K singular (rcond %.3g)",
			 cholmod_l_rcond(c->f, &c->cc));
		ret = IRDM_ENUMERIC;
	}
	return ret;
}

int irdm_compliance_open(const struct irdm_fem *fem, const struct irdm_modes *m,
			 bool floating, enum irdm_compliance_method method,
			 struct irdm_compliance **out, char *err, size_t errlen)
{
	struct irdm_compliance *c = calloc(1, sizeof(*c));
	int ret;

	*out = NULL;
	if (!c || !(c->tmp = malloc(fem->K.n * sizeof(double)))) {
		free(c);
		snprintf(err, errlen, "static compliance: out of memory");
		return IRDM_ENOMEM;
	}
	c->fem = fem;
	c->m = m;
	c->floating = floating;
	cholmod_l_start(&c->cc);
	c->cc.print = 0;
	ret = factor(c, method, err, errlen);
	if (ret) {
		irdm_compliance_close(c);
		return ret;
	}
	*out = c;
	return IRDM_OK;
}

void irdm_compliance_close(struct irdm_compliance *c)
{
	if (!c)
		return;
	cholmod_l_free_factor(&c->f, &c->cc);
	cholmod_l_finish(&c->cc);
	free(c->tmp);
	free(c);
}

/* f <- P f = f - M Phi_r Phi_r^T f for each of the n_rhs loads: their
 * rigid part removed. */
static int elastic_loads(const struct irdm_fem *fem, const struct irdm_modes *m, double *f,
			 size_t n_rhs, double *tmp)
{
	size_t n = m->n;
	double *mt = m->n_rigid ? malloc(n * sizeof(double)) : NULL;

	if (m->n_rigid && !mt)
		return IRDM_ENOMEM;
	for (size_t c = 0; c < n_rhs && m->n_rigid; c++) {
		memset(tmp, 0, n * sizeof(double));
		for (size_t r = 0; r < m->n_rigid; r++)
			add_projection(&m->rigid_phi[r * n], n, &f[c * n], 1.0, tmp);
		irdm_csc_matvec(&fem->M, tmp, mt);
		for (size_t i = 0; i < n; i++)
			f[c * n + i] -= mt[i];
	}
	free(mt);
	return IRDM_OK;
}

static int solve_loads(struct irdm_compliance *c, const double *load, size_t n_in, double *X,
		       char *err, size_t errlen);

int irdm_compliance_columns(struct irdm_compliance *c, const int64_t *in, size_t n_in,
			    double *X, char *err, size_t errlen)
{
	const struct irdm_fem *fem = c->fem;
	size_t n = fem->K.n;
	double *load = malloc(n * n_in * sizeof(double));
	int ret;

	if (!load) {
		snprintf(err, errlen, "static compliance: out of memory");
		return IRDM_ENOMEM;
	}
	for (size_t k = 0; k < n_in; k++)
		elastic_load(fem, c->m, in[k], &load[k * n], c->tmp);
	ret = solve_loads(c, load, n_in, X, err, errlen);
	free(load);
	return ret;
}

int irdm_compliance_loads(struct irdm_compliance *c, double *F, size_t n_rhs, double *X,
			  char *err, size_t errlen)
{
	if (elastic_loads(c->fem, c->m, F, n_rhs, c->tmp)) {
		snprintf(err, errlen, "static compliance: out of memory");
		return IRDM_ENOMEM;
	}
	return solve_loads(c, F, n_rhs, X, err, errlen);
}

/* X = G load for n_in elastic (self-equilibrated) loads. */
static int solve_loads(struct irdm_compliance *c, const double *load, size_t n_in, double *X,
		       char *err, size_t errlen)
{
	const struct irdm_fem *fem = c->fem;
	size_t n = fem->K.n;
	cholmod_dense *rhs, *sol = NULL;
	double *tmp = c->tmp;
	int ret;

	rhs = cholmod_l_allocate_dense(n, n_in ? n_in : 1, n, CHOLMOD_REAL, &c->cc);
	if (!rhs) {
		snprintf(err, errlen, "static compliance: out of memory");
		ret = IRDM_ENOMEM;
		goto out_free;
	}
	memset(X, 0, n * n_in * sizeof(double));
	for (int step = 0; step < c->steps; step++) {
		double *b = rhs->x;
		for (size_t k = 0; k < n_in; k++) {
			if (c->eps > 0)
				irdm_csc_matvec(&fem->M, &X[k * n], tmp);
			for (size_t i = 0; i < n; i++)
				b[k * n + i] = load[k * n + i] + (c->eps > 0 ? c->eps * tmp[i] : 0.0);
		}
		cholmod_l_free_dense(&sol, &c->cc);
		sol = cholmod_l_solve(CHOLMOD_A, c->f, rhs, &c->cc);
		if (!sol) {
			snprintf(err, errlen, "static compliance: sparse solve failed");
			ret = c->cc.status == CHOLMOD_OUT_OF_MEMORY ? IRDM_ENOMEM : IRDM_ENUMERIC;
			goto out_free;
		}
		memcpy(X, sol->x, n * n_in * sizeof(double));
		if (c->floating)
			remove_rigid(fem, c->m, X, n_in, tmp);
	}
	ret = IRDM_OK;
out_free:
	cholmod_l_free_dense(&sol, &c->cc);
	cholmod_l_free_dense(&rhs, &c->cc);
	return ret;
}

int irdm_compliance_solve(const struct irdm_fem *fem, const struct irdm_modes *m,
			  bool floating, const int64_t *in, size_t n_in, double *X,
			  char *err, size_t errlen)
{
	struct irdm_compliance *c;
	int ret;

	ret = irdm_compliance_open(fem, m, floating, IRDM_COMPLIANCE_SHIFTED, &c, err, errlen);
	if (ret)
		return ret;
	ret = irdm_compliance_columns(c, in, n_in, X, err, errlen);
	irdm_compliance_close(c);
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
							v -= m->phi[k * n + (size_t)ri] * m->phi[k * n + (size_t)cj] / m->omega2[k];
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
