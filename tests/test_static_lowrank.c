/* SPDX-License-Identifier: MIT */
/*
 * The static correction's far field (irdm_static_correction_lowrank)
 * against the dense static correction S (irdm_static_correction) of a
 * small grounded cuboid (0.1 x 0.1 x 0.4 m, 4 x 4 x 16 hexes, 60 modes),
 * every surface node touchable, tol 0.02:
 *  - on the kept blocks, S_near + U diag(lambda) U^T is S (the kept blocks
 *    were stored minus the far field), and the stored matrix stays exactly
 *    symmetric;
 *  - on the dropped blocks, the error left is compared with the best
 *    rank-r approximation of the dense remainder F (LAPACK dsyevr on all
 *    of it: brute force) and with no far field at all;
 *  - the a-posteriori figures it reports are those of the dense S on its
 *    checked columns; U has orthonormal columns, |lambda| decreases, and
 *    the result is the same bit for bit when run again (seeded).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "modal/lapack.h"
#include "modal/response.h"
#include "modal/static_lowrank.h"
#include "modal/static_sparse.h"
#include "support/model_fixture.h"

#define TOL 0.02
#define RANK 24
/* Kept blocks: S_near + far field vs dense S, of the largest diagonal
 * block: 2.4e-14 measured (rounding of the subtraction); limit 12x. */
#define KEPT_TOL 3e-13
/* RMS of the dropped blocks' error (units of sqrt(|S_aa| |S_bb|)) over
 * the best rank-RANK truncation's: 1.08 measured; limit 1.25.  Over no far
 * field: 0.68 measured (265 columns, 46 % of the blocks dropped); limit
 * 0.8. */
#define MAX_OVER_BEST 1.25
#define MAX_OVER_NONE 0.8

static double frob(const double *b)
{
	double s = 0;

	for (int i = 0; i < 9; i++)
		s += b[i] * b[i];
	return sqrt(s);
}

/* Dense D [c][r][3][3] as the matrix A[3r + i][3c + j] (nd x nd). */
static double *as_matrix(const double *D, size_t nc)
{
	size_t nd = 3 * nc;
	double *A = malloc(nd * nd * sizeof(double));

	assert_non_null(A);
	for (size_t c = 0; c < nc; c++)
		for (size_t r = 0; r < nc; r++)
			for (size_t i = 0; i < 3; i++)
				for (size_t j = 0; j < 3; j++)
					A[(3 * r + i) * nd + 3 * c + j] = D[((c * nc + r) * 3 + i) * 3 + j];
	return A;
}

static bool kept(const struct irdm_corr_sparse *s, size_t c, size_t r)
{
	for (uint32_t k = s->start[c]; k < s->start[c + 1]; k++)
		if (s->rows[k] == r)
			return true;
	return false;
}

/* Block (force c -> displacement r) of L = U diag(lambda) U^T (nd x nd). */
static void block_of(const double *L, size_t nd, size_t c, size_t r, double b[9])
{
	for (size_t i = 0; i < 3; i++)
		for (size_t j = 0; j < 3; j++)
			b[3 * i + j] = L[(3 * r + i) * nd + 3 * c + j];
}

/* The best rank-r symmetric approximation of F (nd x nd) by all its
 * eigenpairs: the r of largest |mu|. */
static double *best_rank(const double *F, size_t nd, size_t r)
{
	int n = (int)nd, m = 0, lwork = -1, liwork = -1, info = 0, iwq = 0, il = 0, iu = 0;
	double vl = 0, vu = 0, abstol = 0, wq = 0;
	double *a = malloc(nd * nd * sizeof(double)), *mu = malloc(nd * sizeof(double));
	double *Z = malloc(nd * nd * sizeof(double)), *L = calloc(nd * nd, sizeof(double));
	int *isuppz = malloc(2 * nd * sizeof(int));
	bool *used = calloc(nd, sizeof(bool));

	assert_true(a && mu && Z && L && isuppz && used);
	memcpy(a, F, nd * nd * sizeof(double));
	dsyevr_("V", "A", "L", &n, a, &n, &vl, &vu, &il, &iu, &abstol, &m, mu, Z, &n, isuppz, &wq,
		&lwork, &iwq, &liwork, &info);
	lwork = (int)wq;
	liwork = iwq;
	double *work = malloc((size_t)lwork * sizeof(double));
	int *iwork = malloc((size_t)liwork * sizeof(int));
	assert_true(work && iwork);
	dsyevr_("V", "A", "L", &n, a, &n, &vl, &vu, &il, &iu, &abstol, &m, mu, Z, &n, isuppz,
		work, &lwork, iwork, &liwork, &info);
	assert_int_equal(info, 0);
	for (size_t t = 0; t < r; t++) {
		size_t best = 0;
		for (size_t k = 0; k < nd; k++)
			if (!used[k] && (used[best] || fabs(mu[k]) > fabs(mu[best])))
				best = k;
		used[best] = true;
		for (size_t i = 0; i < nd; i++)
			for (size_t j = 0; j < nd; j++)
				L[i * nd + j] += mu[best] * Z[best * nd + i] * Z[best * nd + j];
	}
	free(a);
	free(mu);
	free(Z);
	free(isuppz);
	free(used);
	free(work);
	free(iwork);
	return L;
}

/* RMS over the dropped blocks of |S - L| / sqrt(|S_aa| |S_bb|). */
static double rms_dropped(const struct irdm_corr_sparse *s, const double *S, const double *L,
			  const double *dn, double *max)
{
	size_t nc = s->n_cols, nd = 3 * nc, n = 0;
	double ss = 0;

	*max = 0;
	for (size_t c = 0; c < nc; c++)
		for (size_t r = 0; r < nc; r++) {
			double bs[9], bl[9] = { 0 }, e;
			if (kept(s, c, r))
				continue;
			block_of(S, nd, c, r, bs);
			if (L)
				block_of(L, nd, c, r, bl);
			for (int k = 0; k < 9; k++)
				bs[k] -= bl[k];
			e = frob(bs) / sqrt(dn[c] * dn[r]);
			*max = fmax(*max, e);
			ss += e * e;
			n++;
		}
	return sqrt(ss / (double)n);
}

/* L = U diag(lambda) U^T from the result, nd x nd. */
static double *far_matrix(const struct irdm_corr_lowrank *lr)
{
	size_t nd = lr->n_dofs, r = lr->rank;
	double *L = calloc(nd * nd, sizeof(double));

	assert_non_null(L);
	for (size_t i = 0; i < nd; i++)
		for (size_t j = 0; j < nd; j++)
			for (size_t t = 0; t < r; t++)
				L[i * nd + j] += lr->u[i * r + t] * lr->u[j * r + t] * lr->lambda[t];
	return L;
}

static void check_basis(const struct irdm_corr_lowrank *lr)
{
	size_t nd = lr->n_dofs, r = lr->rank;

	for (size_t t = 0; t + 1 < r; t++)
		assert_true(fabs(lr->lambda[t]) >= fabs(lr->lambda[t + 1]));
	for (size_t a = 0; a < r; a++)
		for (size_t b = 0; b < r; b++) {
			double d = 0;
			for (size_t i = 0; i < nd; i++)
				d += lr->u[i * r + a] * lr->u[i * r + b];
			assert_true(fabs(d - (a == b)) < 1e-12);
		}
}

/* Kept blocks + far field = dense S, and exactly symmetric. */
static void check_kept(const struct irdm_corr_sparse *s, const double *S, const double *L,
		       double scale)
{
	size_t nc = s->n_cols, nd = 3 * nc;
	double worst = 0;

	for (size_t c = 0; c < nc; c++)
		for (uint32_t k = s->start[c]; k < s->start[c + 1]; k++) {
			size_t r = s->rows[k];
			double bs[9], bl[9];
			block_of(S, nd, c, r, bs);
			block_of(L, nd, c, r, bl);
			for (int e = 0; e < 9; e++)
				worst = fmax(worst, fabs(s->blocks[9 * (size_t)k + (size_t)e] + bl[e] - bs[e]));
			for (uint32_t q = s->start[r]; q < s->start[r + 1]; q++)
				if (s->rows[q] == c)
					for (int i = 0; i < 3; i++)
						for (int j = 0; j < 3; j++)
							assert_true(s->blocks[9 * (size_t)k + 3 * (size_t)i + (size_t)j] ==
								    s->blocks[9 * (size_t)q + 3 * (size_t)j + (size_t)i]);
		}
	print_message("kept blocks: S_near + far field vs dense S: %.2e of the largest diagonal (limit %.0e)\n",
		      worst / scale, KEPT_TOL);
	assert_true(worst <= KEPT_TOL * scale);
}

/* The reported a-posteriori figures: the dense ones on the checked columns. */
static void check_report(const struct irdm_corr_lowrank *lr, const struct irdm_corr_sparse *s,
			 const double *S, const double *L, const double *dn)
{
	size_t nc = s->n_cols, nd = 3 * nc, nk = lr->n_checked;
	double mb = 0, ma = 0;

	assert_true(nk >= 1);
	for (size_t j = 0; j < nk; j++) {
		size_t c = (2 * j + 1) * nc / (2 * nk);
		for (size_t r = 0; r < nc; r++) {
			double bs[9], bl[9];
			if (kept(s, c, r))
				continue;
			block_of(S, nd, c, r, bs);
			block_of(L, nd, c, r, bl);
			mb = fmax(mb, frob(bs) / sqrt(dn[c] * dn[r]));
			for (int e = 0; e < 9; e++)
				bs[e] -= bl[e];
			ma = fmax(ma, frob(bs) / sqrt(dn[c] * dn[r]));
		}
	}
	print_message("a-posteriori on %zu columns: max %.4g -> %.4g reported, %.4g -> %.4g dense\n",
		      nk, lr->max_before, lr->max_after, mb, ma);
	assert_true(fabs(lr->max_before - mb) <= 1e-6 * mb);
	assert_true(fabs(lr->max_after - ma) <= 1e-6 * mb);
}

static void test_cuboid(void **state)
{
	struct irdm_model m;
	struct irdm_corr_sparse s, s2;
	struct irdm_corr_lowrank lr, lr2;
	char err[256];

	(void)state;
	fixture_model(&m, 0.1, 0.1, 0.4, 4, 4, 16, 5, 0.45, false, 60, IRDM_EIG_LANCZOS, 0.001);
	size_t nc = m.n_cols, nd = 3 * nc;
	double *D = malloc(nc * nc * 9 * sizeof(double)), *dn = malloc(nc * sizeof(double));
	double scale = 0, max_none, max_best, max_got;

	assert_non_null(D);
	assert_non_null(dn);
	assert_int_equal(irdm_static_correction(&m.fem, &m.modes, false, m.col_dofs, nc, m.col_dofs,
						nc, D, err, sizeof(err)),
			 0);
	double *S = as_matrix(D, nc);
	for (size_t c = 0; c < nc; c++) {
		dn[c] = frob(&D[(c * nc + c) * 9]);
		scale = fmax(scale, dn[c]);
	}
	assert_int_equal(irdm_static_correction_sparse(&m.fem, &m.modes, false, m.col_dofs, nc, TOL,
						       NULL, NULL, &s, err, sizeof(err)),
			 0);
	assert_int_equal(irdm_static_correction_sparse(&m.fem, &m.modes, false, m.col_dofs, nc, TOL,
						       NULL, NULL, &s2, err, sizeof(err)),
			 0);
	print_message("%zu columns, %zu of %zu blocks kept\n", nc, s.n_blocks, nc * nc);
	assert_true(s.n_blocks < 6 * nc * nc / 10); /* a good part dropped */
	if (irdm_static_correction_lowrank(&m.fem, &m.modes, false, m.col_dofs, &s, RANK, NULL,
					   NULL, &lr, err, sizeof(err)))
		fail_msg("%s", err);
	assert_int_equal(lr.rank, RANK);
	assert_int_equal(lr.n_dofs, nd);
	check_basis(&lr);
	double *L = far_matrix(&lr);
	check_kept(&s, S, L, scale);
	check_report(&lr, &s, S, L, dn);

	/* F: S with the kept blocks zeroed; its best rank-RANK approximation */
	double *F = malloc(nd * nd * sizeof(double));
	assert_non_null(F);
	memcpy(F, S, nd * nd * sizeof(double));
	for (size_t c = 0; c < nc; c++)
		for (uint32_t k = s.start[c]; k < s.start[c + 1]; k++)
			for (size_t i = 0; i < 3; i++)
				memset(&F[(3 * (size_t)s.rows[k] + i) * nd + 3 * c], 0, 3 * sizeof(double));
	double *Lb = best_rank(F, nd, RANK);
	double rms_none = rms_dropped(&s, S, NULL, dn, &max_none);
	double rms_best = rms_dropped(&s, S, Lb, dn, &max_best);
	double rms_got = rms_dropped(&s, S, L, dn, &max_got);
	print_message("%zu columns, %zu of %zu blocks kept; dropped blocks' error RMS (max): none %.4g (%.4g), best rank %d %.4g (%.4g), far field %.4g (%.4g): %.2f of best, %.2f of none\n",
		      nc, s.n_blocks, nc * nc, rms_none, max_none, RANK, rms_best, max_best, rms_got,
		      max_got, rms_got / rms_best, rms_got / rms_none);
	assert_true(rms_got <= MAX_OVER_BEST * rms_best);
	assert_true(rms_got <= MAX_OVER_NONE * rms_none);

	/* seeded: the same again, bit for bit */
	if (irdm_static_correction_lowrank(&m.fem, &m.modes, false, m.col_dofs, &s2, RANK, NULL,
					   NULL, &lr2, err, sizeof(err)))
		fail_msg("%s", err);
	assert_memory_equal(lr.lambda, lr2.lambda, RANK * sizeof(double));
	assert_memory_equal(lr.u, lr2.u, nd * RANK * sizeof(double));
	assert_memory_equal(s.blocks, s2.blocks, s.n_blocks * 9 * sizeof(double));

	irdm_corr_lowrank_free(&lr2);
	/* a rank the DoFs cannot hold is refused */
	assert_int_equal(irdm_static_correction_lowrank(&m.fem, &m.modes, false, m.col_dofs, &s2,
							nd + 1, NULL, NULL, &lr2, err, sizeof(err)),
			 IRDM_EINVAL);
	irdm_corr_lowrank_free(&lr);
	irdm_corr_lowrank_free(&lr2);
	irdm_corr_sparse_free(&s);
	irdm_corr_sparse_free(&s2);
	free(D);
	free(dn);
	free(S);
	free(F);
	free(L);
	free(Lb);
	irdm_model_free(&m);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_cuboid),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
