/* SPDX-License-Identifier: MIT */
/*
 * representation = auto when every mode does not fit in memory
 * (precompute/lowest.h): a hybrid of the lowest modes of a Lanczos solve
 * and a head from Chebyshev series, the modes kept those ringing past the
 * head, built and measured, a miss built again with more.  On the paper's
 * cuboid at 4 x 4 x 8 hexes (600 elastic modes), 2 ms, 10 % damping at
 * the first mode and at 100 Hz, the top face touchable, every other key
 * at its default, with max_memory_mib = 3 (every mode needs 4.1 MiB, the
 * Lanczos solves 0.4 to 2.8):
 *  - where the cutoff lies: irdm_decay_cutoff() against the closed forms
 *    of Rayleigh damping, where the envelope falls with frequency (a
 *    stiffness part) and where it rises again (mass damping alone: the
 *    overdamped low modes creep);
 *  - how many modes lie below it: the inertia of K - sigma M against the
 *    count of a dense eigensolve, at frequencies through the spectrum;
 *  - each build keeps exactly the modes whose envelope after the
 *    128-sample head is over its share, counted here from every mode of a
 *    dense eigensolve with the damping recomputed from its definition: at
 *    max_error 9e-4 the first share (0.18) measures 9.5e-4, over it, and
 *    the second, lowered by twice the miss, keeps more (solved again) and
 *    meets it;
 *  - the kept image's figure, measured again against the exact model of
 *    every mode (a precompute of its own), is the same figure;
 *  - refused, by name, with nothing written: a Lanczos solve over
 *    max_memory_mib (with the last build's figure), mass damping alone
 *    (every mode rings as long), a head over max_head_mib (with the cap
 *    that builds it, and that cap then builds it: more modes kept do not
 *    shrink it), a material so stiff that measuring without every mode
 *    needs too long a series; before any solve, two contacts at once and
 *    error_columns = every (measured on every mode only) and a clustered
 *    static correction (the head needs the blocks).
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
#include "irdm/error.h"
#include "irdm/posix/image_map.h"
#include "fem/inertia.h"
#include "modal/decay.h"
#include "precompute/lowest.h"
#include "precompute/model.h"
#include "precompute/precompute.h"
#include "scene/scene.h"
#include "support/model_fixture.h"

/*
 * The figure against Chebyshev series and against every mode, apart by
 * (measured 2026-11-29, gcc -O2) 1.3e-14 to 6.9e-13 on figures of 4e-5 to
 * 6.3e-4 here and on the default material: the series' cut (1e-8 of the
 * largest dropped response) and rounding, not the figure's size.  Limit
 * 2e-12, in the figure's own units.
 */
#define TOL_FIGURE 2e-12
#define DT 0.002
#define ZETA 0.1
#define HEAD_S (IRDM_LOWEST_HEAD * DT)

static char dir[64];

static const char *const keys[] = { "resolution", "4,4,8", "touch", "z>=0.2", "display", "z>=0.2",
				    "dt", "0.002", "damping", "0.1@mode1,0.1@100" };
#define N_KEYS (sizeof(keys) / sizeof(keys[0]))

static void scene(struct irdm_scene *sc, const char *max_error, const char *memory)
{
	char err[256] = "";

	irdm_scene_defaults(sc);
	for (size_t i = 0; i < N_KEYS; i += 2)
		assert_int_equal(irdm_scene_set(sc, keys[i], keys[i + 1], "test", err, sizeof(err)), 0);
	assert_int_equal(irdm_scene_set(sc, "max_error", max_error, "test", err, sizeof(err)), 0);
	if (memory)
		assert_int_equal(irdm_scene_set(sc, "max_memory_mib", memory, "test", err, sizeof(err)), 0);
}

static int setup(void **state)
{
	(void)state;
	snprintf(dir, sizeof(dir), "/tmp/irdm-lowest-XXXXXX");
	return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
	char cmd[128];

	(void)state;
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", dir);
	return system(cmd) ? -1 : 0;
}

/*
 * Stiffness and mass damping, underdamped: the envelope exp(-(a + b w^2)
 * t / 2) crosses `left` at w = sqrt((2 ln(1/left) / t - a) / b).  Mass
 * damping alone: over w >= a/2 the rate is a/2 whatever w (here its
 * envelope is under `left`); below, overdamped, the slow root's rate
 * a/2 - sqrt(a^2/4 - w^2) crosses r = ln(1/left) / t at
 * w = sqrt(a^2/4 - (a/2 - r)^2), and every mode under it creeps longer.
 */
static void test_cutoff_closed_form(void **state)
{
	struct irdm_rayleigh rb = { .a_per_s = 0.98, .b_s = 1.57e-4 }, ra = { .a_per_s = 200, .b_s = 0 };
	double t = 0.128, left = 0.2, r = log(1 / left) / t;
	double want_b = sqrt((2 * r - rb.a_per_s) / rb.b_s);
	double want_a = sqrt(ra.a_per_s * ra.a_per_s / 4 - pow(ra.a_per_s / 2 - r, 2));
	double got_b = irdm_decay_cutoff(&rb, t, left, 1e4);
	double got_a = irdm_decay_cutoff(&ra, t, left, 1e4);

	(void)state;
	print_message("cutoff: Rayleigh %.9g rad/s (closed form %.9g), mass alone %.9g (%.9g)\n",
		      got_b, want_b, got_a, want_a);
	assert_true(fabs(got_b - want_b) <= 1e-9 * want_b);
	assert_true(fabs(got_a - want_a) <= 1e-9 * want_a);
	/* nothing rings that long below the bound, or everything does */
	assert_true(irdm_decay_cutoff(&rb, t, 0.999999, 1e4) < 2);
	assert_true(irdm_decay_cutoff(&rb, t, left, want_b / 2) == want_b / 2);
}

/* Every mode of the test's model, from a dense eigensolve. */
static void every_mode_model(struct irdm_model *m)
{
	struct irdm_scene sc;
	char err[256] = "";

	scene(&sc, "none", NULL);
	assert_int_equal(irdm_scene_set(&sc, "representation", "modal:all", "test", err, sizeof(err)), 0);
	assert_int_equal(irdm_scene_set(&sc, "eigensolver", "dense", "test", err, sizeof(err)), 0);
	if (irdm_model_build(&sc, 0, NULL, NULL, m, err, sizeof(err)))
		fail_msg("%s", err);
}

static void test_inertia_count(void **state)
{
	struct irdm_model m;
	char err[256] = "";

	(void)state;
	every_mode_model(&m);
	for (double f = 5; f < 600; f *= 1.6) {
		double w2 = pow(2 * M_PI * f, 2);
		size_t got, want = 0;

		for (size_t k = 0; k < m.modes.n_modes; k++)
			want += m.modes.omega2[k] < w2;
		assert_int_equal(irdm_fem_count_below(&m.fem, w2, &got, err, sizeof(err)), 0);
		print_message("below %6.1f Hz: %zu by inertia, %zu by a dense eigensolve\n", f, got, want);
		assert_int_equal(got, want);
		assert_int_equal(irdm_lowest_below(&m.modes, m.modes.n_modes, sqrt(w2)), want);
	}
	irdm_model_free(&m);
}

/* The modes whose envelope after the head is over left, from every mode
 * of a dense eigensolve, the damping from its definition. */
static size_t ringing_count(double left)
{
	struct irdm_model m;
	double w1, w2 = 2 * M_PI * 100, a, b;
	size_t n = 0;

	every_mode_model(&m);
	w1 = sqrt(m.modes.omega2[0]);
	a = 2 * ZETA * w1 * w2 / (w1 + w2);
	b = 2 * ZETA / (w1 + w2);
	for (size_t k = 0; k < m.modes.n_modes; k++) /* underdamped: rate a/2 + b w^2 / 2 */
		n += exp(-(a + b * m.modes.omega2[k]) / 2 * HEAD_S) > left;
	irdm_model_free(&m);
	return n;
}

/* The builds' lines: "auto: modal:K (the modes to F Hz, over L of their
 * envelope after the head) ... measured error E: ..."; and the solves. */
#define MAX_BUILDS 4
static size_t n_builds, n_solves, n_lanczos, built_k[MAX_BUILDS];
static double built_left[MAX_BUILDS], built_error[MAX_BUILDS];

static void progress(void *ctx, const char *line, double fraction)
{
	const char *at;
	double hz;

	(void)ctx;
	n_lanczos += fraction == 0 && !strcmp(line, "Lanczos eigensolve");
	if (fraction >= 0)
		return;
	n_solves += strstr(line, "(inertia), ringing past the head") != NULL;
	if (strncmp(line, "auto: modal:", 12) || n_builds == MAX_BUILDS)
		return;
	at = strstr(line, "measured error ");
	if (!at)
		return; /* refused before its measurement */
	if (sscanf(line, "auto: modal:%zu (the modes to %lf Hz, over %lf", &built_k[n_builds], &hz,
		   &built_left[n_builds]) != 3 ||
	    sscanf(at, "measured error %lf", &built_error[n_builds]) != 1)
		fail_msg("unread: %s", line);
	n_builds++;
}

/* The modes over a share printed to 3 digits: between its rounding's ends. */
static void assert_ringing(size_t k, double left)
{
	size_t lo = ringing_count(left * (1 + 5e-3)), hi = ringing_count(left * (1 - 5e-3));

	print_message("kept %zu; %zu to %zu ring past the head to %.3g (every mode)\n", k, lo, hi,
		      left);
	assert_true(k >= lo && k <= hi);
}

static void test_rounds(void **state)
{
	struct irdm_scene sc, ref_sc;
	struct irdm_precompute_report rep;
	struct irdm_measure res;
	struct irdm_image img;
	char path[128], ref[136], err[512] = "";
	struct irdm_precompute_opts o = { .out_path = path, .progress = progress };

	(void)state;
	snprintf(path, sizeof(path), "%s/rounds.img", dir);
	snprintf(ref, sizeof(ref), "%s.every", path);
	scene(&sc, "9e-4", "3");
	n_builds = n_solves = 0;
	if (irdm_precompute(&sc, &o, &rep, err, sizeof(err)))
		fail_msg("%s", err);
	assert_true(rep.auto_lowest && rep.error_measured);
	assert_string_equal(rep.error_reference, "the kept modes and Chebyshev series");
	assert_int_equal(n_builds, 2);
	assert_int_equal(rep.auto_tries, 2);
	/* the first share exactly, then lowered by twice the first miss */
	assert_int_equal(built_k[0], ringing_count(irdm_lowest_left_first(9e-4)));
	assert_true(built_error[0] > 9e-4);
	assert_true(fabs(built_left[1] - irdm_lowest_left_next(irdm_lowest_left_first(9e-4), 9e-4,
							       built_error[0])) <=
		    5e-3 * built_left[1]);
	assert_ringing(built_k[1], built_left[1]);
	assert_int_equal(rep.modes, built_k[1]);
	assert_true(built_k[1] > built_k[0]);
	assert_int_equal(n_solves, 2); /* the second build solved more */
	/* its figure against every mode */
	assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)), 0);
	scene(&ref_sc, "9e-4", NULL); /* every mode fits the reference */
	assert_int_equal(irdm_measure_error(&ref_sc, &img, ref, fixture_exact_by_precompute, NULL,
					    NULL, NULL, &res, err, sizeof(err)),
			 0);
	irdm_image_unmap(&img);
	print_message("builds: %zu modes measured %.6g, %zu modes measured %.6g against Chebyshev series, %.6g against every mode: %.2e apart (limit %.0e)\n",
		      built_k[0], built_error[0], built_k[1], rep.measured_error, res.error,
		      fabs(rep.measured_error - res.error), TOL_FIGURE);
	assert_int_equal(rep.error_cols, res.n_cols);
	assert_true(fabs(rep.measured_error - res.error) <= TOL_FIGURE);
	assert_true(res.error > 1e-5 && res.error <= 9e-4); /* a figure, not rounding */
}

static void test_mass_damping_refused(void **state)
{
	struct irdm_scene sc;
	struct irdm_precompute_report rep;
	char path[128], err[512] = "";
	struct irdm_precompute_opts o = { .out_path = path };

	(void)state;
	snprintf(path, sizeof(path), "%s/mass.img", dir);
	scene(&sc, "1e-3", "3");
	assert_int_equal(irdm_scene_set(&sc, "damping", "rayleigh:2,0", "test", err, sizeof(err)), 0);
	assert_int_equal(irdm_precompute(&sc, &o, &rep, err, sizeof(err)), IRDM_ENUMERIC);
	print_message("%s\n", err);
	assert_non_null(strstr(err, "every mode up to the top of the spectrum"));
	assert_non_null(strstr(err, "rings past a head of 128 samples"));
	assert_int_equal(access(path, F_OK), -1);
}

static int build_with(const char *key, const char *value, struct irdm_precompute_report *rep,
		      char *err, size_t errlen)
{
	struct irdm_scene sc;
	char path[128];
	struct irdm_precompute_opts o = { .out_path = path, .progress = progress };

	snprintf(path, sizeof(path), "%s/%s.img", dir, key);
	scene(&sc, "1e-3", "3");
	n_builds = n_solves = n_lanczos = 0;
	assert_int_equal(irdm_scene_set(&sc, key, value, "test", err, errlen), 0);
	return irdm_precompute(&sc, &o, rep, err, errlen);
}

static void test_head_cap(void **state)
{
	struct irdm_precompute_report rep;
	char err[512] = "", cap[32];
	const char *at;
	unsigned mib = 0;

	(void)state;
	assert_int_equal(build_with("max_head_mib", "1", &rep, err, sizeof(err)), IRDM_ENUMERIC);
	print_message("%s\n", err);
	at = strstr(err, "more than max_head_mib = 1: max_head_mib = ");
	assert_non_null(at);
	assert_int_equal(sscanf(at, "more than max_head_mib = 1: max_head_mib = %u or more builds it", &mib), 1);
	assert_true(mib > 1);
	snprintf(cap, sizeof(cap), "%u", mib);
	if (build_with("max_head_mib", cap, &rep, err, sizeof(err)))
		fail_msg("max_head_mib = %s: %s", cap, err);
	assert_true(rep.auto_lowest && rep.measured_error <= 1e-3);
}

static void test_lanczos_over_budget(void **state)
{
	struct irdm_precompute_report rep;
	char err[512] = "";

	(void)state;
	assert_int_equal(build_with("max_error", "5e-4", &rep, err, sizeof(err)), IRDM_ENOMEM);
	print_message("%s\n", err);
	assert_non_null(strstr(err, "modes: the Lanczos solve of "));
	assert_non_null(strstr(err, "GiB, more than the 0.00293 GiB of max_memory_mib; the last build measured "));
}

static void test_stiff_refused(void **state)
{
	struct irdm_precompute_report rep;
	char err[512] = "";

	(void)state;
	assert_int_equal(build_with("young", "2e9", &rep, err, sizeof(err)), IRDM_ENUMERIC);
	print_message("%s\n", err);
	assert_non_null(strstr(err, "the error measurement over 0.998 s needs Chebyshev series of about "));
	assert_non_null(strstr(err, "a stiff object needs every mode"));
	assert_int_equal(n_lanczos, 1); /* the first modes only, for the damping */
	assert_int_equal(n_builds, 0);
}

/* What only every mode measures, or a head cannot be built on. */
static void test_every_mode_only_refused(void **state)
{
	static const char *const kv[][2] = { { "contacts", "2" },
					     { "error_columns", "every" },
					     { "static_correction_cluster", "16" } };
	struct irdm_precompute_report rep;
	char err[1024] = "";

	(void)state;
	for (size_t i = 0; i < sizeof(kv) / sizeof(kv[0]); i++) {
		assert_int_equal(build_with(kv[i][0], kv[i][1], &rep, err, sizeof(err)), IRDM_ENOMEM);
		print_message("%s = %s: %s\n", kv[i][0], kv[i][1], err);
		assert_non_null(strstr(err, "more than the 0.00293 GiB of max_memory_mib"));
		assert_non_null(strstr(err, "from the lowest modes of a Lanczos solve instead on a grounded object with lumped mass, contacts = 1, eigensolver = auto, error_columns not every and no static_correction_cluster"));
		assert_int_equal(n_lanczos, 0); /* not a mode solved */
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_cutoff_closed_form),
		cmocka_unit_test(test_inertia_count),
		cmocka_unit_test(test_rounds),
		cmocka_unit_test(test_lanczos_over_budget),
		cmocka_unit_test(test_stiff_refused),
		cmocka_unit_test(test_mass_damping_refused),
		cmocka_unit_test(test_head_cap),
		cmocka_unit_test(test_every_mode_only_refused),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
