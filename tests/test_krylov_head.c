/* SPDX-License-Identifier: MIT */
/*
 * The hybrid's head without every mode (eigensolver = lanczos with
 * exact_head: modal/krylov_head.h) against the head summed from every
 * mode of a dense eigensolve, on the paper's cuboid at 4 x 4 x 8 hexes
 * (600 elastic modes), 2 ms, the top face touchable, the lowest 101 modes
 * kept and a 64-sample head, f64:
 *  - the precompute took the Krylov path: one Chebyshev run per touchable
 *    DoF, and only the kept modes solved (ARPACK, not a dense solve);
 *  - the series has about the terms theory gives: cos(w t) in T_k of the
 *    spectrum's interval has Bessel coefficients J_2k(w_up t), which die
 *    out past k = w_up t / 2, and the cut leaves at most its tolerance;
 *  - the head is the same bit for bit built by one thread or two (the
 *    columns go in batches of 8 over the threads: 4 batches here);
 *  - every kept block's response over the head's 2H samples (kept modes,
 *    static correction and head, as the image holds them) is the
 *    every-mode hybrid's to the series' cut;
 *  - the forces of a step and of a release at the top centre, by direct
 *    convolution of each image's responses, agree likewise, and both are
 *    certified on every column;
 *  - measured (max_error set), the image's figure is taken against a
 *    reference of the same kind (the kept modes and Chebyshev series over the
 *    whole run, every block): measured again here at the same nodes
 *    against the exact model of every mode (a dense eigensolve of its
 *    own), the figure is the same;
 *  - at a reference's length (1000 samples at 1 ms, as a measurement
 *    computes), straight through modal/krylov_head.h on the same cuboid
 *    at the default material: the top centre's own block against the
 *    dropped modes' response summed from every mode, for cuts at 1e-6,
 *    1e-8 and 1e-10, each within its tolerance, and each with about
 *    w_up t / 2 terms (a tighter cut adds a few: the coefficients die out
 *    faster than geometrically; rounding noise must not be summed as if
 *    it were coefficients);
 *  - the scene refuses the Krylov head where it cannot be built: over
 *    MPI ranks (slepc), on a floating object, with a consistent mass.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "accuracy/measure.h"
#include "modal/krylov_head.h"
#include "modal/response.h"
#include "image/image_response.h"
#include "irdm/posix/image_map.h"
#include "precompute/precompute.h"
#include "scene/scene.h"
#include "support/engine_fixture.h"
#include "support/model_fixture.h"

#define N_TICKS 1500 /* 3 s at 2 ms */
#define RELEASE_TICK 500

/*
 * Limits, measured 2026-11-29 (gcc -O2): the kept blocks' responses over
 * 2H samples 4.4e-12 of max |R| apart (limit 1e-11: the series is cut at
 * 1e-8 of the largest dropped response, and the kept modes come from two
 * eigensolvers); forces at the top centre 4.6e-12 (step) and 6.0e-12
 * (release) relative RMS apart (limit 2e-11).  101 modes, not 100:
 * modes 100 and 101 are a pair of one frequency (the cuboid's x <-> y
 * mirror), and two eigensolvers may split such a pair differently, which
 * moves blocks by 5.9e-4 while leaving the forces alike.  The hybrid
 * itself is 2.4e-2 off the exact model here (test_hybrid holds a hybrid
 * to the exact model).
 */
#define TOL_R 1e-11
#define TOL_FORCE 2e-11
/* The figure against Chebyshev series and against every mode: 0.0245
 * both, 4.6e-11 relative apart (limit 2e-10). */
#define TOL_FIGURE 2e-10
/* The terms over w_up t / 2 (t: the last sample's time): 1.16 measured
 * (the Bessel coefficients past it die out over some (w_up t)^(1/3) more). */
#define TERMS_OVER_THEORY_MAX 1.2

static char dir[64];
static struct irdm_image dense, krylov;
static size_t krylov_runs, krylov_lines, krylov_terms, krylov_samples;
static double krylov_w_up, krylov_tail;

static const char *const keys[] = { "resolution", "4,4,8", "touch", "z>=0.2", "display", "z>=0.2",
				    "dt", "0.002", "precision", "f64", "representation", "modal:101",
				    "exact_head", "64", "max_error", "none" };
#define N_KEYS (sizeof(keys) / sizeof(keys[0]))

/* The precompute's line "krylov head: N Chebyshev runs of T terms over S
 * samples, the spectrum bounded by w = W rad/s; the terms cut leave X of
 * ..." */
static void progress(void *ctx, const char *stage, double fraction)
{
	(void)ctx;
	if (fraction < 0 && !strncmp(stage, "krylov head: ", 13)) {
		if (sscanf(stage, "krylov head: %zu Chebyshev runs of %zu terms over %zu samples, the spectrum bounded by w = %lf rad/s; the terms cut leave %lf",
			   &krylov_runs, &krylov_terms, &krylov_samples, &krylov_w_up, &krylov_tail) != 5)
			krylov_runs = 0;
		krylov_lines++;
	}
}

static void build_threads(struct irdm_image *img, const char *method, const char *threads,
			  struct irdm_precompute_report *rep)
{
	struct irdm_scene sc;
	char path[128], err[512] = "";
	struct irdm_precompute_opts o = { .out_path = path, .progress = progress };

	snprintf(path, sizeof(path), "%s/%s-%s.img", dir, method, threads);
	irdm_scene_defaults(&sc);
	for (size_t i = 0; i < N_KEYS; i += 2)
		assert_int_equal(irdm_scene_set(&sc, keys[i], keys[i + 1], "test", err, sizeof(err)), 0);
	assert_int_equal(irdm_scene_set(&sc, "eigensolver", method, "test", err, sizeof(err)), 0);
	assert_int_equal(irdm_scene_set(&sc, "threads", threads, "test", err, sizeof(err)), 0);
	if (irdm_precompute(&sc, &o, rep, err, sizeof(err)))
		fail_msg("%s: %s", method, err);
	assert_int_equal(irdm_image_map(path, 0, img, err, sizeof(err)), 0);
}

static void build(struct irdm_image *img, const char *method, struct irdm_precompute_report *rep)
{
	build_threads(img, method, "2", rep);
}

static int setup(void **state)
{
	struct irdm_precompute_report rep;

	(void)state;
	snprintf(dir, sizeof(dir), "/tmp/irdm-krylov-XXXXXX");
	if (!mkdtemp(dir))
		return -1;
	build(&dense, "dense", &rep);
	if (krylov_lines)
		return -1; /* every mode was solved: no Krylov run */
	build(&krylov, "lanczos", &rep);
	return 0;
}

static int teardown(void **state)
{
	char cmd[128];

	(void)state;
	irdm_image_unmap(&dense);
	irdm_image_unmap(&krylov);
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", dir);
	return system(cmd) ? -1 : 0;
}

/* One run per touchable DoF (the top face is free), from the kept modes
 * alone; its terms as the Bessel coefficients of cos(w t) give them. */
static void test_krylov_path(void **state)
{
	double t = (double)(krylov_samples - 1) * 0.002, theory = krylov_w_up * t / 2;

	(void)state;
	print_message("Krylov head: %zu runs for %u columns, %zu terms over %zu samples: %.3g times w_up t / 2 = %.0f (w_up %.4g rad/s, at most %.2f); the cut leaves %.2g (at most 1e-8)\n",
		      krylov_runs, krylov.meta->n_cols, krylov_terms, krylov_samples,
		      (double)krylov_terms / theory, theory, krylov_w_up, TERMS_OVER_THEORY_MAX,
		      krylov_tail);
	assert_int_equal(krylov_lines, 1);
	assert_int_equal(krylov_samples, 128);
	assert_true((double)krylov_terms >= theory);
	assert_true((double)krylov_terms <= TERMS_OVER_THEORY_MAX * theory);
	assert_true(krylov_tail > 0 && krylov_tail <= 1e-8);
	assert_int_equal(krylov_runs, 3 * (size_t)krylov.meta->n_cols);
	assert_int_equal(krylov.meta->n_modes, 101);
	assert_int_equal(krylov.meta->head_samples, 128);
	assert_int_equal(krylov.meta->n_cols, dense.meta->n_cols);
}

/* Every kept block over 2H samples, the two images' columns in the same
 * order (the same mesh and selection). */
static void test_blocks_match(void **state)
{
	uint32_t S = krylov.meta->head_samples, checked = 0;
	double *a = malloc(S * 9 * sizeof(double)), *b = malloc(S * 9 * sizeof(double));
	double worst = 0, scale = 0;

	(void)state;
	assert_non_null(a);
	assert_non_null(b);
	assert_int_equal(krylov.corr_start[krylov.meta->n_cols], dense.corr_start[dense.meta->n_cols]);
	for (uint32_t c = 0; c < krylov.meta->n_cols; c++)
		for (uint32_t k = krylov.corr_start[c]; k < krylov.corr_start[c + 1]; k++) {
			uint32_t r = krylov.corr_rows[k];

			assert_int_equal(dense.corr_rows[k], r);
			assert_int_equal(irdm_image_response(&krylov, c, krylov.columns[r], S, a), 0);
			assert_int_equal(irdm_image_response(&dense, c, dense.columns[r], S, b), 0);
			for (size_t i = 0; i < S * 9; i++) {
				worst = fmax(worst, fabs(a[i] - b[i]));
				scale = fmax(scale, fabs(b[i]));
			}
			checked++;
		}
	print_message("%u kept blocks over %u samples: Krylov head against every mode %.2e of max |R| (limit %.0e)\n",
		      checked, S, worst / scale, TOL_R);
	assert_true(checked > krylov.meta->n_cols);
	assert_true(worst <= TOL_R * scale);
	free(a);
	free(b);
}

/* The head is the same bit for bit whichever thread builds a column and
 * in which batch: every run has the same terms, and lanes share no inner
 * product. */
static void test_threads_alike(void **state)
{
	struct irdm_precompute_report rep;
	struct irdm_image one;
	size_t n;

	(void)state;
	build_threads(&one, "lanczos", "1", &rep);
	n = (size_t)krylov.meta->head_samples * 9 *
	    (krylov.meta->flags & IRDM_META_HEAD_PAIRS ? (krylov.corr_start[krylov.meta->n_cols] + krylov.meta->n_cols) / 2 :
							 krylov.corr_start[krylov.meta->n_cols]);
	print_message("one thread against two: %zu head values compared\n", n);
	assert_int_equal(one.meta->head_samples, krylov.meta->head_samples);
	assert_int_equal(one.corr_start[one.meta->n_cols], krylov.corr_start[krylov.meta->n_cols]);
	assert_memory_equal(one.exact_head, krylov.exact_head,
			    n * irdm_elem_size(krylov.meta->precision));
	irdm_image_unmap(&one);
}

static void forces(const struct irdm_image *img, const double *u, double *F)
{
	const double top[3] = { 0.05, 0.05, 0.2 };
	struct irdm_contact_site s = { .n_nodes = 1, .weight = { 1 } };

	s.row[0] = efx_column_row_near(img, top);
	s.col[0] = (uint32_t)irdm_image_col_of(img, s.row[0]);
	efx_reference(img, &s, 1, N_TICKS, u, F);
}

static void compare(const char *what, const double *u)
{
	double *Fk = malloc(N_TICKS * 3 * sizeof(double)), *Fd = malloc(N_TICKS * 3 * sizeof(double));

	assert_non_null(Fk);
	assert_non_null(Fd);
	forces(&krylov, u, Fk);
	forces(&dense, u, Fd);
	double d = efx_rel_rms(Fk, Fd, N_TICKS * 3);
	print_message("%s: Krylov head against every mode %.2e relative RMS force (limit %.0e)\n", what,
		      d, TOL_FORCE);
	assert_true(d <= TOL_FORCE);
	free(Fk);
	free(Fd);
}

static void test_forces_certified(void **state)
{
	(void)state;
	efx_step_release(N_TICKS, RELEASE_TICK, -0.01, compare);
	for (uint32_t c = 0; c < krylov.meta->n_cols; c++)
		assert_true(krylov.stability[c].flags & IRDM_STAB_STABLE);
}

static void test_measured(void **state)
{
	struct irdm_scene sc;
	struct irdm_precompute_report rep;
	struct irdm_measure res;
	struct irdm_image img;
	char path[128], ref[136], err[512] = "";
	struct irdm_precompute_opts o = { .out_path = path };

	(void)state;
	snprintf(path, sizeof(path), "%s/measured.img", dir);
	snprintf(ref, sizeof(ref), "%s.every", path);
	irdm_scene_defaults(&sc);
	for (size_t i = 0; i < N_KEYS; i += 2)
		assert_int_equal(irdm_scene_set(&sc, keys[i], keys[i + 1], "test", err, sizeof(err)), 0);
	assert_int_equal(irdm_scene_set(&sc, "eigensolver", "lanczos", "test", err, sizeof(err)), 0);
	assert_int_equal(irdm_scene_set(&sc, "max_error", "0.1", "test", err, sizeof(err)), 0);
	if (irdm_precompute(&sc, &o, &rep, err, sizeof(err)))
		fail_msg("%s", err);
	assert_true(rep.error_measured);
	assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)), 0);
	assert_int_equal(irdm_measure_error(&sc, &img, ref, fixture_exact_by_precompute, NULL, NULL, NULL, &res, err,
					    sizeof(err)),
			 0);
	print_message("measured at %zu nodes: %.6g against Chebyshev series (worst: %s at mesh node %u), %.6g against every mode (%s at %u): %.2e apart (limit %.0e)\n",
		      rep.error_cols, rep.measured_error, rep.error_worst_run, rep.error_worst_node,
		      res.error, res.worst_run, res.worst_node,
		      fabs(rep.measured_error - res.error) / res.error, TOL_FIGURE);
	assert_string_equal(rep.error_reference, "the kept modes and Chebyshev series");
	assert_int_equal(rep.error_cols, res.n_cols);
	assert_int_equal(rep.error_worst_node, res.worst_node);
	assert_true(res.error > 1e-4); /* a figure, not rounding */
	assert_true(fabs(rep.measured_error - res.error) <= TOL_FIGURE * res.error);
	irdm_image_unmap(&img);
}

/*
 * The series at a reference's length.  Limits, measured 2026-11-29: the
 * block's largest error over the samples, relative to its largest value,
 * 4.2e-7 / 1.1e-10 / 4.1e-11 for cuts at 1e-6 / 1e-8 / 1e-10 (a cut
 * bounds the error relative to the largest dropped response: limit 1.2
 * tol), terms 1.07 to 1.10 times w_up t / 2.
 */
#define REF_SAMPLES 1000
#define REF_KEPT 101
#define REF_TERMS_MAX 1.15

static void series_block(const struct irdm_model *m, const int64_t *dof, double tol, double *head,
			 struct irdm_krylov_head_stats *st)
{
	uint32_t index[3] = { 0, 1, 0 };
	struct irdm_corr_sparse corr = { .n_cols = 1, .n_blocks = 1, .start = index, .rows = &index[2] };
	struct irdm_modes kept = m->modes;
	struct irdm_krylov_head_opts o = { tol, IRDM_KRYLOV_HEAD_MAX_TERMS, 1, REF_SAMPLES };
	double target[9] = { 0 };
	char err[256];

	kept.n_modes = REF_KEPT;
	if (irdm_krylov_head(&m->fem, &kept, &m->damping, 0.001, dof, &corr, target, REF_SAMPLES, &o,
			     NULL, NULL, head, st, err, sizeof(err)))
		fail_msg("%s", err);
}

static void test_reference_length(void **state)
{
	static const double tols[] = { 1e-6, 1e-8, 1e-10 };
	struct irdm_model m;
	struct irdm_mode *zoh;
	struct irdm_modes dropped;
	const double top[3] = { 0.05, 0.05, 0.2 };
	size_t n, terms_before = 0;
	int64_t dof[3], *all;
	double *ex = malloc(REF_SAMPLES * 9 * sizeof(double));
	double *head = malloc(2 * REF_SAMPLES * 9 * sizeof(double)), peak = 0;
	char err[256];

	(void)state;
	assert_non_null(ex);
	assert_non_null(head);
	fixture_model(&m, 0.1, 0.1, 0.2, 4, 4, 8, 5, 0.45, false, 0, IRDM_EIG_DENSE, 0.001);
	n = m.modes.n;
	assert_int_equal(m.modes.n_modes, m.modes.n_elastic_total);
	all = malloc(n * sizeof(*all));
	zoh = malloc(m.modes.n_modes * sizeof(*zoh));
	assert_non_null(all);
	assert_non_null(zoh);
	for (size_t i = 0; i < n; i++)
		all[i] = (int64_t)i;
	assert_int_equal(irdm_modes_complete(&m.modes, 0, m.modes.n_modes, all, n, err, sizeof(err)), 0);
	irdm_modes_discretise(&m.modes, &m.damping, 0.001, zoh);
	for (int a = 0; a < 3; a++)
		dof[a] = fixture_free_dof(&m, fixture_nearest_node(&m.mesh, top), a);
	/* the exact head: the dropped modes' response, summed */
	dropped = m.modes;
	dropped.n_modes -= REF_KEPT;
	dropped.omega2 += REF_KEPT;
	dropped.phi += REF_KEPT * n;
	assert_int_equal(irdm_fir_from_modes(&dropped, &zoh[REF_KEPT], dof, 1, dof, 1, REF_SAMPLES,
					     NULL, ex, NULL, NULL),
			 0);
	for (size_t q = 0; q < REF_SAMPLES * 9; q++)
		peak = fmax(peak, fabs(ex[q]));
	for (size_t ti = 0; ti < sizeof(tols) / sizeof(tols[0]); ti++) {
		struct irdm_krylov_head_stats st;
		double worst = 0, theory;

		series_block(&m, dof, tols[ti], head, &st);
		theory = sqrt(st.lam_up) * (REF_SAMPLES - 1) * 0.001 / 2;
		for (size_t q = 0; q < REF_SAMPLES * 9; q++)
			worst = fmax(worst, fabs(head[q] - ex[q]));
		print_message("cut at %.0e: %zu terms, %.3f times w_up t / 2 = %.0f (at most %.2f); the top centre's block %.2e of its largest value off every mode's (at most %.1e)\n",
			      tols[ti], st.terms, (double)st.terms / theory, theory, REF_TERMS_MAX,
			      worst / peak, 1.2 * tols[ti]);
		assert_int_equal(st.samples, REF_SAMPLES);
		assert_true((double)st.terms >= theory);
		assert_true((double)st.terms <= REF_TERMS_MAX * theory);
		assert_true(st.terms > terms_before);
		assert_true(worst <= 1.2 * tols[ti] * peak);
		terms_before = st.terms;
	}
	free(all);
	free(zoh);
	free(ex);
	free(head);
	irdm_model_free(&m);
}

static void test_scene_refusals(void **state)
{
	static const char *const bad[][4] = {
		{ "eigensolver", "slepc", "floating", "no" },
		{ "eigensolver", "lanczos", "floating", "yes" },
		{ "eigensolver", "lanczos", "mass", "consistent" },
	};
	char err[512];

	(void)state;
	for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
		struct irdm_scene sc;

		irdm_scene_defaults(&sc);
		assert_int_equal(irdm_scene_set(&sc, "representation", "modal:101", "test", err, sizeof(err)), 0);
		assert_int_equal(irdm_scene_set(&sc, "exact_head", "16", "test", err, sizeof(err)), 0);
		assert_int_equal(irdm_scene_set(&sc, bad[i][0], bad[i][1], "test", err, sizeof(err)), 0);
		assert_int_equal(irdm_scene_set(&sc, bad[i][2], bad[i][3], "test", err, sizeof(err)), 0);
		err[0] = 0;
		assert_int_equal(irdm_scene_check(&sc, err, sizeof(err)), IRDM_EINVAL);
		print_message("%s = %s, %s = %s: %s\n", bad[i][0], bad[i][1], bad[i][2], bad[i][3], err);
		assert_non_null(strstr(err, "exact_head"));
		assert_non_null(strstr(err, bad[i][1]));
		if (i) /* the reason: the key that is not grounded and lumped */
			assert_non_null(strstr(err, bad[i][3]));
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_krylov_path),
		cmocka_unit_test(test_blocks_match),
		cmocka_unit_test(test_threads_alike),
		cmocka_unit_test(test_forces_certified),
		cmocka_unit_test(test_measured),
		cmocka_unit_test(test_reference_length),
		cmocka_unit_test(test_scene_refusals),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
