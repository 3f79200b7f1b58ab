/* SPDX-License-Identifier: MIT */
/*
 * The screen (accuracy/screen.h) and the measurement that uses it, on
 * the soft, heavy 4 x 4 x 8 cuboid (2 ms, the whole surface touchable:
 * 137 columns), the lowest 300 of 600 modes kept:
 *  - with heads of 32 and 8 samples and with the static correction
 *    alone, its figures are the prediction (accuracy/split.h, its own
 *    probe, not cut) on the screen's shorter runs, nothing it leaves out
 *    predicts more than the last it keeps, and the column worst over the
 *    measurement's whole runs is its first; nothing dropped, nothing
 *    screened;
 *  - the measurement of a built hybrid (8-sample head, f64) at its 18
 *    sampled columns finds the figure and the node that measuring every
 *    column (error_columns = every) finds, where the spread and the
 *    worst-conditioned alone measure 0.9 of it or less.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "accuracy/measure.h"
#include "accuracy/screen.h"
#include "accuracy/split.h"
#include "irdm/posix/image_map.h"
#include "modal/response.h"
#include "precompute/model.h"
#include "scene/scene.h"
#include "precompute/precompute.h"
#include "support/model_fixture.h"
#include "support/test_files.h"

static char dir[64];

#define N_ALL 600
#define KEPT 300

/* The prediction at column c alone, the modes from KEPT on dropped into a
 * head of H. */
static double predicted_at(const struct irdm_model *m, const struct irdm_mode *zoh, size_t c,
			   unsigned H, size_t N)
{
	struct irdm_split_probe p;
	size_t drop[N_ALL], n_drop = 0;
	double e;

	for (size_t d = KEPT; d < m->modes.n_modes; d++)
		drop[n_drop++] = d;
	assert_int_equal(irdm_split_probe_init(&p, &m->modes, zoh, &m->col_dofs[3 * c], 1, N), 0);
	irdm_split_begin(&p);
	e = irdm_split_try(&p, drop, n_drop, H);
	irdm_split_probe_free(&p);
	return e;
}

static void test_screen_finds_the_worst(void **state)
{
	static const unsigned heads[] = { 32, 8, 0 };
	struct irdm_scene sc;
	struct irdm_model m;
	struct irdm_mode zoh[N_ALL];
	bool dropped[N_ALL];
	uint32_t cols[IRDM_MEASURE_SCREENED];
	double est[IRDM_MEASURE_SCREENED], *pred, *full;
	char err[256];
	size_t N;

	(void)state;
	fixture_soft_scene(&sc, (const char *const[]){ "touch", "surface", NULL });
	assert_int_equal(irdm_model_build(&sc, 0, NULL, NULL, &m, err, sizeof(err)), 0);
	assert_int_equal(m.modes.n_modes, N_ALL);
	irdm_modes_discretise(&m.modes, &m.damping, sc.dt_s, zoh);
	N = irdm_measure_ticks(sc.dt_s);
	pred = malloc(m.n_cols * sizeof(*pred));
	full = malloc(m.n_cols * sizeof(*full));
	assert_non_null(pred);
	assert_non_null(full);
	for (size_t d = 0; d < N_ALL; d++)
		dropped[d] = false;
	assert_int_equal(irdm_screen_columns(&m.modes, zoh, dropped, 8, m.col_dofs, m.n_cols, N,
					     IRDM_MEASURE_SCREENED, cols, est),
			 0);
	for (size_t d = 0; d < N_ALL; d++)
		dropped[d] = d >= KEPT;
	for (size_t h = 0; h < sizeof(heads) / sizeof(heads[0]); h++) {
		size_t Ns = irdm_screen_ticks(heads[h], N), worst = 0, at = IRDM_MEASURE_SCREENED;
		size_t n = irdm_screen_columns(&m.modes, zoh, dropped, heads[h], m.col_dofs,
					       m.n_cols, N, IRDM_MEASURE_SCREENED, cols, est);

		assert_int_equal(n, IRDM_MEASURE_SCREENED);
		assert_true(Ns < N);
		for (size_t c = 0; c < m.n_cols; c++) {
			pred[c] = predicted_at(&m, zoh, c, heads[h], Ns);
			full[c] = predicted_at(&m, zoh, c, heads[h], N);
			if (full[c] > full[worst])
				worst = c;
		}
		/* the screen's figures are the prediction on its runs, at
		 * every column: nothing it left out predicts more */
		for (size_t i = 0; i < n; i++) {
			print_message("head %u: screened #%zu column %u: %.4g (%zu ticks), %.4g (%zu)\n",
				      heads[h], i, cols[i], est[i], Ns, full[cols[i]], N);
			assert_float_equal(est[i], pred[cols[i]], 1e-9 * pred[cols[i]]);
			if (cols[i] == worst)
				at = i;
		}
		for (size_t c = 0; c < m.n_cols; c++) {
			bool in = false;
			for (size_t i = 0; i < n; i++)
				in |= cols[i] == c;
			assert_true(in || pred[c] <= est[n - 1]);
		}
		/* and on the measurement's longer runs the worst is among them */
		print_message("head %u: worst of %zu columns over %zu ticks %.4g at column %zu: screened #%zu\n",
			      heads[h], m.n_cols, N, full[worst], worst, at);
		assert_true(at < n);
	}
	free(pred);
	free(full);
	irdm_model_free(&m);
}

/* The hybrid of the lowest 300 modes with an 8-sample head on the whole
 * surface, f64, measured: res. */
static void measured(const char *every, struct irdm_precompute_report *rep)
{
	struct irdm_precompute_opts o = { 0 };
	struct irdm_scene sc;
	char err[512], path[128];

	fixture_soft_scene(&sc, (const char *const[]){ "touch", "surface", "representation", "modal:300",
						       "exact_head", "8", "precision", "f64",
						       "max_error", "1", "error_columns", every,
						       NULL });
	snprintf(path, sizeof(path), "%s/h.img", dir);
	o.out_path = path;
	if (irdm_precompute(&sc, &o, rep, err, sizeof(err)))
		fail_msg("%s", err);
}

/*
 * The measurement looks where the screen says: on the same hybrid, the
 * sampled measurement (4 spread, 12 screened, 2 worst-conditioned of 137
 * columns) finds the figure and the node that measuring every column
 * finds; the spread alone does not.
 */
static void test_measured_where_worst(void **state)
{
	struct irdm_precompute_report sampled, every, by_default;
	struct irdm_measure res;
	struct irdm_scene sc;
	struct irdm_image img;
	char err[512], path[128], ref[128];

	(void)state;
	measured("sample", &sampled);
	measured("every", &every);
	measured("auto", &by_default); /* 137 columns: every one */
	assert_true(by_default.error_every_column);
	assert_int_equal(by_default.error_cols, every.error_cols);
	print_message("sampled: %.6g at mesh node %u over %zu columns; every column: %.6g at %u over %zu (median %.3g)\n",
		      sampled.measured_error, sampled.error_worst_node, sampled.error_cols,
		      every.measured_error, every.error_worst_node, every.error_cols,
		      every.error_median);
	assert_true(every.error_every_column);
	assert_true(sampled.error_cols < every.error_cols / 4);
	assert_int_equal(sampled.error_worst_node, every.error_worst_node);
	assert_float_equal(sampled.measured_error, every.measured_error,
			   1e-9 * every.measured_error);
	/* the spread and the worst-conditioned alone (what the measurement
	 * was without the screen) miss it */
	snprintf(path, sizeof(path), "%s/h.img", dir);
	snprintf(ref, sizeof(ref), "%s/exact.img", dir);
	assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)), 0);
	fixture_soft_scene(&sc, (const char *const[]){ "touch", "surface", NULL });
	assert_int_equal(irdm_measure_error(&sc, &img, ref, fixture_exact_by_precompute, NULL, NULL,
					    NULL, &res, err, sizeof(err)),
			 0);
	irdm_image_unmap(&img);
	print_message("spread alone: %.6g at mesh node %u over %zu columns\n", res.error,
		      res.worst_node, res.n_cols);
	assert_true(res.error < 0.9 * every.measured_error);
}

static int setup(void **state)
{
	(void)state;
	return tf_tmpdir(dir, sizeof(dir), "screen");
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_screen_finds_the_worst),
		cmocka_unit_test(test_measured_where_worst),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
