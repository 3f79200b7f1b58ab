/* SPDX-License-Identifier: MIT */
/*
 * The block-sparse static correction against the dense one
 * (irdm_static_correction: one loop per entry over the kept modes, itself
 * checked against LAPACK in test_response) on small grounded and floating
 * boxes whose surfaces span several batches of columns:
 *  - tol = 0 keeps every non-zero block, equal to the dense one;
 *  - tol > 0 keeps exactly the blocks at or above tol sqrt(|S_cc| |S_rr|)
 *    and drops the rest; the largest dropped ratio is reported right;
 *  - the index is what the image needs: rows increasing, the diagonal in
 *    every column, the matrix exactly symmetric.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "modal/response.h"
#include "modal/static_sparse.h"
#include "support/model_fixture.h"

/* Kept blocks vs dense, of the largest diagonal block: 3.9e-15 grounded
 * (the same solve, the modes summed in another order), 5.8e-14 floating
 * (pinned support vs shifted, refined solves) measured; limit about 17x. */
#define MATCH_TOL 1e-12

static double frob(const double *b)
{
	double s = 0;

	for (int i = 0; i < 9; i++)
		s += b[i] * b[i];
	return sqrt(s);
}

/* The sparse column c as a dense row of blocks (NAN where dropped). */
static void expand(const struct irdm_corr_sparse *s, size_t c, double *row)
{
	for (size_t i = 0; i < 9 * s->n_cols; i++)
		row[i] = NAN;
	for (uint32_t k = s->start[c]; k < s->start[c + 1]; k++)
		memcpy(&row[9 * (size_t)s->rows[k]], &s->blocks[9 * (size_t)k], 9 * sizeof(double));
}

static void check_index(const struct irdm_corr_sparse *s)
{
	assert_int_equal(s->start[0], 0);
	assert_int_equal(s->start[s->n_cols], s->n_blocks);
	for (size_t c = 0; c < s->n_cols; c++) {
		bool diag = false;
		for (uint32_t k = s->start[c]; k < s->start[c + 1]; k++) {
			assert_true(s->rows[k] < s->n_cols);
			if (k > s->start[c])
				assert_true(s->rows[k] > s->rows[k - 1]);
			diag = diag || s->rows[k] == c;
		}
		assert_true(diag);
	}
}

/*
 * Compare with the dense D ([c][r][3][3]); return the number of dropped
 * off-diagonal blocks that were not zero.
 */
static size_t compare(const struct irdm_corr_sparse *s, const double *D, double tol)
{
	size_t nc = s->n_cols, dropped = 0;
	double *row = malloc(9 * nc * sizeof(double)), *row_t = malloc(9 * nc * sizeof(double));
	double scale = 0, max_rel = 0, worst = 0;

	assert_non_null(row);
	assert_non_null(row_t);
	for (size_t c = 0; c < nc; c++)
		scale = fmax(scale, frob(&D[(c * nc + c) * 9]));
	for (size_t c = 0; c < nc; c++) {
		expand(s, c, row);
		for (size_t r = 0; r < nc; r++) {
			const double *d = &D[(c * nc + r) * 9];
			double nrm = frob(d);
			double lim = tol * sqrt(frob(&D[(c * nc + c) * 9]) * frob(&D[(r * nc + r) * 9]));
			if (isnan(row[9 * r])) {
				/* dropped: below the tolerance (a relative 1e-9 for
				 * the two ways of summing) */
				assert_true(r != c);
				if (nrm > lim * (1 + 1e-9) + 1e-9 * scale)
					fail_msg("block (%zu, %zu) dropped at %.6g of its scale, tol %g",
						 c, r, nrm / (lim / tol), tol);
				if (nrm > 1e-9 * scale) {
					dropped++;
					max_rel = fmax(max_rel, nrm / (lim / tol));
				}
				continue;
			}
			if (r != c && nrm < lim * (1 - 1e-9))
				fail_msg("block (%zu, %zu) kept at %.6g of its scale, tol %g",
					 c, r, nrm / (lim / tol), tol);
			for (int e = 0; e < 9; e++)
				worst = fmax(worst, fabs(row[9 * r + (size_t)e] - d[e]));
			/* exactly symmetric: column r holds the transpose */
			expand(s, r, row_t);
			for (int i = 0; i < 3; i++)
				for (int j = 0; j < 3; j++)
					assert_true(row[9 * r + 3 * (size_t)i + (size_t)j] ==
						    row_t[9 * c + 3 * (size_t)j + (size_t)i]);
		}
	}
	print_message("tol %-6g: %zu of %zu blocks kept, largest kept difference %.2e of the largest diagonal, largest dropped %.3g (reported %.3g)\n",
		      tol, s->n_blocks, nc * nc, worst / scale, max_rel, s->max_dropped_rel);
	assert_true(worst <= MATCH_TOL * scale);
	if (tol > 0)
		assert_true(fabs(s->max_dropped_rel - max_rel) <= 1e-6 * tol);
	free(row);
	free(row_t);
	return dropped;
}

static void run_case(const char *what, struct irdm_model *m, bool floating)
{
	size_t nc = m->n_cols;
	double *D = malloc(nc * nc * 9 * sizeof(double));
	char err[256];
	struct irdm_corr_sparse s;

	print_message("%s: %zu columns, %zu modes of %zu\n", what, nc, m->modes.n_modes,
		      m->modes.n_elastic_total);
	assert_true(nc > 64); /* more than one batch */
	assert_non_null(D);
	assert_int_equal(irdm_static_correction(&m->fem, &m->modes, floating, m->col_dofs, nc,
						m->col_dofs, nc, D, err, sizeof(err)),
			 0);
	/* tol = 0: every block that is not exactly zero */
	assert_int_equal(irdm_static_correction_sparse(&m->fem, &m->modes, floating, m->col_dofs,
						       nc, 0.0, NULL, NULL, &s, err, sizeof(err)),
			 0);
	check_index(&s);
	assert_int_equal(compare(&s, D, 0.0), 0);
	irdm_corr_sparse_free(&s);
	/* a tolerance that drops a good part: the boundary is exact */
	for (double tol = 1e-3; tol <= 0.11; tol *= 10) {
		assert_int_equal(irdm_static_correction_sparse(&m->fem, &m->modes, floating,
							       m->col_dofs, nc, tol, NULL, NULL, &s,
							       err, sizeof(err)),
				 0);
		check_index(&s);
		size_t dropped = compare(&s, D, tol);
		if (tol >= 0.1)
			assert_true(dropped > nc * nc / 4);
		assert_true(s.max_dropped_rel < tol);
		irdm_corr_sparse_free(&s);
	}
	free(D);
}

static void test_grounded(void **state)
{
	struct irdm_model m;

	(void)state;
	fixture_model(&m, 0.1, 0.1, 0.3, 3, 3, 9, 5, 0.49, false, 20, IRDM_EIG_LANCZOS, 0.001);
	run_case("grounded 0.1 x 0.1 x 0.3", &m, false);
	irdm_model_free(&m);
}

static void test_floating(void **state)
{
	struct irdm_model m;

	(void)state;
	fixture_model(&m, 0.12, 0.12, 0.12, 4, 4, 4, 5, 0.49, true, 20, IRDM_EIG_LANCZOS, 0.001);
	run_case("floating 0.12 cube", &m, true);
	irdm_model_free(&m);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_grounded),
		cmocka_unit_test(test_floating),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
