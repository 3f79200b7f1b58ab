/* SPDX-License-Identifier: MIT */
/*
 * representation = auto when every mode does not fit in memory
 * (precompute/lowest.h): a hybrid of the lowest modes of a Lanczos solve
 * and a head from Chebyshev series, the modes kept those ringing past the
 * head, built and measured, a miss built again with more.  On the paper's
 * cuboid at 4 x 4 x 8 hexes (600 elastic modes), 1 ms, the top face
 * touchable, every other key at its default, with max_memory_mib = 1 (the
 * every-mode solve needs 4 MiB):
 *  - where the cutoff lies: irdm_decay_cutoff() against the closed forms
 *    of Rayleigh damping, where the envelope falls with frequency (a
 *    stiffness part) and where it rises again (mass damping alone: the
 *    overdamped low modes creep);
 *  - how many modes to solve: on a spectrum whose count grows as w^3,
 *    enough to pass the cutoff, and not twice that;
 *  - the image keeps exactly the modes whose envelope after the 128-sample
 *    head is over 0.2 (the share at max_error 1e-3), counted here from
 *    every mode of a dense eigensolve with the damping recomputed from its
 *    definition (5 % at the first mode and at 100 Hz);
 *  - its measured figure is within max_error, and measured again against
 *    the exact model of every mode (a precompute of its own) it is the
 *    same figure;
 *  - at max_error 5e-4 the first build misses (measured 6.7e-4) and a
 *    second, keeping more modes, meets it: two builds, and the figure
 *    against every mode within max_error;
 *  - with mass damping alone every mode rings as long: refused, by name,
 *    no image written;
 *  - a head over max_head_mib is refused with the cap that builds it (more
 *    modes kept do not shrink it: the static correction keeps as many
 *    blocks), and that cap builds it;
 *  - two contacts at once, which only every mode measures: refused before
 *    any solve, naming what the lowest modes need.
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
#include "modal/decay.h"
#include "precompute/lowest.h"
#include "precompute/model.h"
#include "precompute/precompute.h"
#include "scene/scene.h"

/*
 * The figure against Chebyshev series and against every mode, apart by
 * (measured 2026-11-29, gcc -O2) 1.3e-14 at 6.3e-4 and 1.7e-13 at 4.0e-5:
 * the series' cut (1e-8 of the largest dropped response) and rounding,
 * not the figure's size.  Limit 1e-12, in the figure's own units.
 */
#define TOL_FIGURE 1e-12
#define HEAD_S (IRDM_LOWEST_HEAD * 1e-3)

static char dir[64];

static const char *const keys[] = { "resolution", "4,4,8", "touch", "z>=0.2", "display", "z>=0.2" };
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

/* The exact model of every mode, precomputed on its own. */
static int every_mode(void *ctx, const struct irdm_scene *rsc, const char *path, char *err,
		      size_t errlen)
{
	struct irdm_precompute_opts o = { .out_path = path };
	struct irdm_precompute_report rep;

	(void)ctx;
	return irdm_precompute(rsc, &o, &rep, err, errlen);
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

/* w_k = k^(1/3): the count below w grows as w^3 (Weyl's law in a solid). */
static void test_to_solve(void **state)
{
	double w2[64];
	struct irdm_modes m = { .n_modes = 64, .omega2 = w2 };
	size_t want;

	(void)state;
	for (size_t k = 0; k < 64; k++)
		w2[k] = pow((double)(k + 1), 2.0 / 3.0);
	want = irdm_lowest_to_solve(&m, 64, 2 * 4.0); /* w_64 = 4: 512 below 8 */
	print_message("to pass twice the top of 64 modes on a w^3 count: %zu (512 below it)\n", want);
	assert_true(want >= 512 && want <= 2 * 512);
	assert_int_equal(irdm_lowest_below(&m, 64, 3.0), 27);
}

/* The modes whose envelope after the head is over left, from every mode
 * of a dense eigensolve, the damping from its definition. */
static size_t ringing_count(double left)
{
	struct irdm_scene sc;
	struct irdm_model m;
	char err[256] = "";
	double w1, w2 = 2 * M_PI * 100, z = 0.05, a, b;
	size_t n = 0;

	scene(&sc, "none", NULL);
	assert_int_equal(irdm_scene_set(&sc, "representation", "modal:all", "test", err, sizeof(err)), 0);
	assert_int_equal(irdm_scene_set(&sc, "eigensolver", "dense", "test", err, sizeof(err)), 0);
	if (irdm_model_build(&sc, 0, NULL, NULL, &m, err, sizeof(err)))
		fail_msg("%s", err);
	w1 = sqrt(m.modes.omega2[0]);
	a = 2 * z * w1 * w2 / (w1 + w2);
	b = 2 * z / (w1 + w2);
	for (size_t k = 0; k < m.modes.n_modes; k++) /* underdamped: rate a/2 + b w^2 / 2 */
		n += exp(-(a + b * m.modes.omega2[k]) / 2 * HEAD_S) > left;
	irdm_model_free(&m);
	return n;
}

/* Build the scene at max_error from the lowest modes, then measure the
 * image again against every mode; return its report. */
static void build_and_measure(const char *max_error, struct irdm_precompute_report *rep,
			      double *every)
{
	struct irdm_scene sc, ref_sc;
	struct irdm_measure res;
	struct irdm_image img;
	char path[128], ref[136], err[512] = "";
	struct irdm_precompute_opts o = { .out_path = path };

	snprintf(path, sizeof(path), "%s/lowest-%s.img", dir, max_error);
	snprintf(ref, sizeof(ref), "%s.every", path);
	scene(&sc, max_error, "1");
	if (irdm_precompute(&sc, &o, rep, err, sizeof(err)))
		fail_msg("%s", err);
	assert_true(rep->auto_lowest);
	assert_true(rep->error_measured);
	assert_string_equal(rep->error_reference, "the kept modes and Chebyshev series");
	assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)), 0);
	scene(&ref_sc, max_error, NULL); /* every mode fits the reference */
	assert_int_equal(irdm_measure_error(&ref_sc, &img, ref, every_mode, NULL, NULL, NULL, &res,
					    err, sizeof(err)),
			 0);
	irdm_image_unmap(&img);
	assert_int_equal(rep->error_cols, res.n_cols);
	*every = res.error;
}

static void test_keeps_the_ringing_modes(void **state)
{
	struct irdm_precompute_report rep;
	size_t want = ringing_count(irdm_lowest_left_first(1e-3));
	double every;

	(void)state;
	build_and_measure("1e-3", &rep, &every);
	print_message("max_error 1e-3: %zu modes kept (%zu ring past the head to 0.2), %zu build(s); measured %.6g against Chebyshev series, %.6g against every mode: %.2e apart (limit %.0e)\n",
		      rep.modes, want, rep.auto_tries, rep.measured_error, every,
		      fabs(rep.measured_error - every), TOL_FIGURE);
	assert_int_equal(rep.modes, want);
	assert_int_equal(rep.auto_tries, 1);
	assert_true(every > 1e-5 && every <= 1e-3); /* a figure, not rounding */
	assert_true(fabs(rep.measured_error - every) <= TOL_FIGURE);
}

static void test_miss_builds_again(void **state)
{
	struct irdm_precompute_report rep;
	size_t first = ringing_count(irdm_lowest_left_first(5e-4));
	double every;

	(void)state;
	build_and_measure("5e-4", &rep, &every);
	print_message("max_error 5e-4: %zu build(s), %zu modes kept (the first build's share: %zu); measured %.6g against Chebyshev series, %.6g against every mode: %.2e apart\n",
		      rep.auto_tries, rep.modes, first, rep.measured_error, every, fabs(rep.measured_error - every));
	assert_int_equal(rep.auto_tries, 2);
	assert_true(rep.modes > first);
	assert_true(every <= 5e-4);
	assert_true(fabs(rep.measured_error - every) <= TOL_FIGURE);
}

static void test_mass_damping_refused(void **state)
{
	struct irdm_scene sc;
	struct irdm_precompute_report rep;
	char path[128], err[512] = "";
	struct irdm_precompute_opts o = { .out_path = path };

	(void)state;
	snprintf(path, sizeof(path), "%s/mass.img", dir);
	scene(&sc, "1e-3", "1");
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
	struct irdm_precompute_opts o = { .out_path = path };

	snprintf(path, sizeof(path), "%s/%s.img", dir, key);
	scene(&sc, "1e-3", "1");
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

static void test_two_contacts_refused(void **state)
{
	struct irdm_precompute_report rep;
	char err[512] = "";

	(void)state;
	assert_int_equal(build_with("contacts", "2", &rep, err, sizeof(err)), IRDM_ENOMEM);
	print_message("%s\n", err);
	assert_non_null(strstr(err, "more than the 0.000977 GiB of max_memory_mib"));
	assert_non_null(strstr(err, "from the lowest modes of a Lanczos solve instead on a grounded object with lumped mass, contacts = 1"));
	assert_int_equal(rep.modes, 0); /* not a mode solved */
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_cutoff_closed_form),
		cmocka_unit_test(test_to_solve),
		cmocka_unit_test(test_keeps_the_ringing_modes),
		cmocka_unit_test(test_miss_builds_again),
		cmocka_unit_test(test_mass_damping_refused),
		cmocka_unit_test(test_head_cap),
		cmocka_unit_test(test_two_contacts_refused),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
