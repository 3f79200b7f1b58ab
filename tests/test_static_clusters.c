/* SPDX-License-Identifier: MIT */
/*
 * The clustered static correction (irdm_static_correction_clusters)
 * against the dense static correction S (irdm_static_correction, solved
 * by the other method: the shifted, refined factor instead of the pinned
 * one) on a grounded cuboid (0.1 x 0.1 x 0.4 m, 4 x 4 x 16 hexes, 60
 * modes) and a floating cube, every surface node touchable:
 *  - every 3x3 block, of every pair of columns, within its bound: tol
 *    ((1 - rho) / (1 + rho))^2 sqrt(|S_aa| |S_bb|), rho its ratio;
 *  - the reported largest error is the measured one;
 *  - block (c, r) is block (r, c) transposed to the bit;
 *  - the clusters partition the columns, no larger than asked, and both
 *    dense and low-rank pairs occur; the kept blocks are the zero
 *    diagonal;
 *  - a looser tol stores fewer values.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "irdm/image_format.h"
#include "modal/response.h"
#include "modal/static_clusters.h"
#include "support/model_fixture.h"

#define CLUSTER 16
#define TOL 1e-3
/* A block's error over its bound: at most 1 by construction (the
 * precompute measures the residual); the two dense methods differ by
 * 1e-13 of the diagonal, so the limit is 1 + 1e-6. */
#define MAX_OVER_BOUND (1 + 1e-6)
/* The reported largest error vs the one measured here: 1e-9 relative. */
#define REPORT_TOL 1e-9

static double frob(const double *b)
{
	double s = 0;

	for (int i = 0; i < 9; i++)
		s += b[i] * b[i];
	return sqrt(s);
}

static void check_partition(const struct irdm_corr_clusters *cl, size_t nc)
{
	bool *seen = calloc(nc, sizeof(bool));

	assert_non_null(seen);
	assert_int_equal(cl->start[0], 0);
	assert_int_equal(cl->start[cl->n_clusters], nc);
	for (size_t a = 0; a < cl->n_clusters; a++) {
		assert_true(cl->start[a + 1] > cl->start[a]);
		assert_true(cl->start[a + 1] - cl->start[a] <= CLUSTER);
	}
	for (size_t i = 0; i < nc; i++) {
		assert_false(seen[cl->members[i]]);
		seen[cl->members[i]] = true;
		assert_int_equal(cl->col_pos[cl->members[i]], i);
	}
	free(seen);
}

/* Every block against the dense D [c][r][3][3]; returns the largest plain
 * error in units of sqrt(|S_cc| |S_rr|). */
static double check_blocks(const struct irdm_corr_clusters *cl, const double *D, size_t nc)
{
	double worst_over = 0, worst = 0;

	for (size_t c = 0; c < nc; c++)
		for (size_t r = 0; r < nc; r++) {
			const double *d = &D[(c * nc + r) * 9];
			double b[9], bt[9], e[9];
			double scale = sqrt(frob(&D[(c * nc + c) * 9]) * frob(&D[(r * nc + r) * 9]));
			double rho = fmin(frob(d) / scale, 0.99);
			double bound = TOL * pow((1 - rho) / (1 + rho), 2);
			irdm_corr_clusters_block(cl, c, r, b);
			irdm_corr_clusters_block(cl, r, c, bt);
			for (int i = 0; i < 3; i++)
				for (int j = 0; j < 3; j++) {
					assert_true(b[3 * i + j] == bt[3 * j + i]);
					e[3 * i + j] = b[3 * i + j] - 0.5 * (d[3 * i + j] +
									     D[(r * nc + c) * 9 + 3 * (size_t)j + (size_t)i]);
				}
			worst = fmax(worst, frob(e) / scale);
			worst_over = fmax(worst_over, frob(e) / scale / bound);
		}
	print_message("every block within %.4f of its bound (limit %.6f); largest error %.3g of sqrt(|S_aa| |S_bb|) (tol %g)\n",
		      worst_over, MAX_OVER_BOUND, worst, TOL);
	assert_true(worst_over <= MAX_OVER_BOUND);
	return worst;
}

static void run(bool floating)
{
	struct irdm_model m;
	struct irdm_corr_clusters cl, loose;
	struct irdm_corr_sparse kept, kept2;
	char err[256];

	if (floating)
		fixture_model(&m, 0.1, 0.1, 0.1, 5, 5, 5, 5, 0.45, true, 40, IRDM_EIG_LANCZOS, 0.001);
	else
		fixture_model(&m, 0.1, 0.1, 0.4, 4, 4, 16, 5, 0.45, false, 60, IRDM_EIG_LANCZOS, 0.001);
	size_t nc = m.n_cols;
	double *D = malloc(nc * nc * 9 * sizeof(double)), *pos = malloc(3 * nc * sizeof(double));
	assert_non_null(D);
	assert_non_null(pos);
	for (size_t c = 0; c < nc; c++)
		memcpy(&pos[3 * c], &m.mesh.pos_m[3 * (size_t)m.rows[m.cols[c]]], 3 * sizeof(double));
	assert_int_equal(irdm_static_correction(&m.fem, &m.modes, floating, m.col_dofs, nc,
						m.col_dofs, nc, D, err, sizeof(err)),
			 0);
	if (irdm_static_correction_clusters(&m.fem, &m.modes, floating, m.col_dofs, pos, nc,
					    CLUSTER, TOL, NULL, NULL, &kept, &cl, err, sizeof(err)))
		fail_msg("%s", err);
	check_partition(&cl, nc);
	size_t dense_values = 9 * nc * (nc + 1) / 2;
	print_message("%s: %zu columns, %zu clusters, %zu of %zu pairs dense, largest rank %zu; %zu values (upper half dense: %zu)\n",
		      floating ? "floating cube" : "grounded cuboid", nc, cl.n_clusters, cl.n_dense,
		      cl.n_pairs, cl.max_rank, cl.n_values, dense_values);
	assert_true(cl.n_dense >= cl.n_clusters && cl.n_dense < cl.n_pairs);
	assert_true(cl.max_rank > 0);
	double worst = check_blocks(&cl, D, nc);
	assert_true(fabs(cl.max_err - worst) <= REPORT_TOL * TOL + 1e-6 * worst);
	assert_true(cl.max_err <= TOL);
	/* the kept index: the diagonal, zero */
	assert_int_equal(kept.n_blocks, nc);
	for (size_t c = 0; c < nc; c++) {
		assert_int_equal(kept.start[c], c);
		assert_int_equal(kept.rows[c], c);
		for (int e = 0; e < 9; e++)
			assert_true(kept.blocks[9 * c + (size_t)e] == 0.0);
	}
	/* ten times looser: fewer values */
	if (irdm_static_correction_clusters(&m.fem, &m.modes, floating, m.col_dofs, pos, nc,
					    CLUSTER, 10 * TOL, NULL, NULL, &kept2, &loose, err,
					    sizeof(err)))
		fail_msg("%s", err);
	print_message("tol %g: %zu values, tol %g: %zu\n", TOL, cl.n_values, 10 * TOL,
		      loose.n_values);
	assert_true(loose.n_values < cl.n_values);
	assert_true(loose.max_err <= 10 * TOL && loose.max_err > TOL);
	irdm_corr_clusters_free(&cl);
	irdm_corr_clusters_free(&loose);
	irdm_corr_sparse_free(&kept);
	irdm_corr_sparse_free(&kept2);
	irdm_model_free(&m);
	free(D);
	free(pos);
}

static void test_grounded(void **state)
{
	(void)state;
	run(false);
}

static void test_floating(void **state)
{
	(void)state;
	run(true);
}

/* Out-of-range cluster sizes: a clear error, nothing allocated. */
static void test_refusals(void **state)
{
	struct irdm_model m;
	struct irdm_corr_clusters cl;
	struct irdm_corr_sparse kept;
	char err[256];
	double pos[3] = { 0 };

	(void)state;
	memset(&m, 0, sizeof(m));
	assert_int_equal(irdm_static_correction_clusters(&m.fem, &m.modes, false, NULL, pos, 1, 3,
							 TOL, NULL, NULL, &kept, &cl, err,
							 sizeof(err)),
			 IRDM_EINVAL);
	assert_non_null(strstr(err, "3 nodes per cluster is not in 4..1024"));
	assert_null(cl.values);
	assert_null(kept.start);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_grounded),
		cmocka_unit_test(test_floating),
		cmocka_unit_test(test_refusals),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
