/* SPDX-License-Identifier: MIT */
/*
 * How long a mode rings (modal/decay.h), the rule that chooses a hybrid
 * image's kept modes:
 *  - the slowest decay rate against hand-computed values, under-,
 *    critically and overdamped, and a free mass;
 *  - on eight modes under Rayleigh damping C = 0.01 s K, where the
 *    overdamped high modes decay at about 1/b = 100 /s while two in
 *    between (z 0.9 and 1) decay faster: the modes kept for a horizon
 *    are the ones ringing past it, not the lowest;
 *  - the permutation that puts them first moves omega^2 and the mode
 *    shapes together, and its inverse restores them;
 *  - auto's candidates on a model: each head's kept modes are the ones
 *    ringing past it (counted here from the same hand formulas).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

#include "modal/decay.h"
#include "precompute/candidates.h"

static void test_rates(void **state)
{
	(void)state;
	/* underdamped: z w */
	assert_float_equal(irdm_decay_rate(10.0, 0.05), 0.5, 1e-12);
	assert_float_equal(irdm_decay_rate(2 * M_PI * 2.33, 0.0038), 0.0556313, 1e-7);
	/* critically damped: w */
	assert_float_equal(irdm_decay_rate(10.0, 1.0), 10.0, 1e-12);
	/* overdamped, the slow root w (z - sqrt(z^2 - 1)):
	 * 10 (2.5 - sqrt(5.25)) = 10 (2.5 - 2.29128784747792) */
	assert_float_equal(irdm_decay_rate(10.0, 2.5), 2.0871215252208, 1e-10);
	/* 300 (1.5 - sqrt(1.25)) = 114.59 */
	assert_float_equal(irdm_decay_rate(300.0, 1.5), 114.5898033750315, 1e-9);
	/* 1e5 (500 - sqrt(249999)): 100.0001000002, kept to its digits */
	assert_float_equal(irdm_decay_rate(1e5, 500.0), 100.0001000002, 1e-8);
	/* a free mass does not decay */
	assert_float_equal(irdm_decay_rate(0.0, 0.0), 0.0, 0.0);
	assert_float_equal(irdm_decay_left(0.5, 2.0), exp(-1.0), 1e-15);
}

/*
 * C = b K, b = 0.01 s: z = b w / 2.  Rates (1/s): w 10 -> 0.5, 100 -> 50,
 * 150 -> 112.5, 180 -> 162 (z 0.9), 200 -> 200 (z 1), 300 -> 114.59 (z 1.5),
 * 1000 -> 1000 (5 - sqrt 24) = 101.02, 1e5 -> 100.0001.  Over 0.05314 s at
 * tol 1e-3 a mode rings past when its rate is under ln(1000) / 0.05314 =
 * 130.0 /s: all but w = 180 and 200.
 */
static const double w_rad[8] = { 10, 100, 150, 180, 200, 300, 1000, 1e5 };
static const struct irdm_rayleigh b_only = { .a_per_s = 0.0, .b_s = 0.01 };
#define HORIZON_S 0.05314

static void modes_of(struct irdm_modes *m, double *w2, double *phi, size_t n)
{
	for (size_t k = 0; k < 8; k++) {
		w2[k] = w_rad[k] * w_rad[k];
		for (size_t i = 0; i < n; i++)
			phi[k * n + i] = (double)(10 * k + i); /* column k tells its mode */
	}
	*m = (struct irdm_modes){ .n = n, .n_modes = 8, .n_elastic_total = 8, .omega2 = w2, .phi = phi };
}

static void test_kept_by_decay_not_frequency(void **state)
{
	static const size_t want[8] = { 0, 1, 2, 5, 6, 7, 3, 4 };
	struct irdm_modes m;
	double w2[8], phi[8 * 3];
	size_t order[8];

	(void)state;
	modes_of(&m, w2, phi, 3);
	assert_int_equal(irdm_modes_by_decay(&m, &b_only, HORIZON_S, 1e-3, order), 6);
	for (size_t k = 0; k < 8; k++)
		assert_int_equal(order[k], want[k]);
	/* a longer horizon lets the overdamped ones ring down too (rate
	 * about 100 /s: 1.8e-4 left after 0.0863 s): w 10 and 100 ring */
	assert_int_equal(irdm_modes_by_decay(&m, &b_only, 0.0863, 1e-3, order), 2);
	/* a short one: every rate is under ln 1000 / 0.01 s = 691 /s */
	assert_int_equal(irdm_modes_by_decay(&m, &b_only, 0.01, 1e-3, order), 8);
	/* the tolerance counts: at 0.5 the rates under ln 2 / 0.01 s = 69.3
	 * /s, w 10 and 100 (w 150: e^-1.125 = 0.32 left) */
	assert_int_equal(irdm_modes_by_decay(&m, &b_only, 0.01, 0.5, order), 2);
}

static void test_permute_and_back(void **state)
{
	struct irdm_modes m;
	double w2[8], phi[8 * 3];
	size_t order[8], inv[8];

	(void)state;
	modes_of(&m, w2, phi, 3);
	irdm_modes_by_decay(&m, &b_only, HORIZON_S, 1e-3, order);
	assert_int_equal(irdm_modes_permute(&m, order), 0);
	for (size_t k = 0; k < 8; k++) {
		assert_float_equal(w2[k], w_rad[order[k]] * w_rad[order[k]], 0.0);
		for (size_t i = 0; i < 3; i++)
			assert_float_equal(phi[k * 3 + i], (double)(10 * order[k] + i), 0.0);
	}
	for (size_t k = 0; k < 8; k++)
		inv[order[k]] = k;
	assert_int_equal(irdm_modes_permute(&m, inv), 0);
	for (size_t k = 0; k < 8; k++) {
		assert_float_equal(w2[k], w_rad[k] * w_rad[k], 0.0);
		assert_float_equal(phi[k * 3 + 2], (double)(10 * k + 2), 0.0);
	}
}

/*
 * 400 modes at 1 .. 400 Hz under 5 % at 1 Hz and at 100 Hz, 1 ms: each
 * head tried keeps the modes whose envelope after it is above 1e-3
 * (counted here from the rates' formulas), a head keeps fewer than all,
 * every mode is the one candidate without a head, and the list is
 * ordered by estimated tick cost.
 */
static void test_candidates(void **state)
{
	struct irdm_auto_candidate c[IRDM_AUTO_MAX_CANDIDATES];
	struct irdm_rayleigh d;
	double w2[400];
	struct irdm_modes m = { .n = 0, .n_modes = 400, .n_elastic_total = 400, .omega2 = w2 };
	double w1 = 2 * M_PI, w100 = 2 * M_PI * 100;
	size_t n, heads = 0, truncated = 0;

	(void)state;
	/* z(w) = a / 2w + b w / 2 with z = 0.05 at w1 and w100 */
	d.b_s = 2 * 0.05 / (w1 + w100);
	d.a_per_s = d.b_s * w1 * w100;
	for (size_t k = 0; k < 400; k++)
		w2[k] = pow(2 * M_PI * (double)(k + 1), 2);
	n = irdm_auto_candidates(&m, &d, 1e-3, 1e-3, c);
	assert_true(n >= 2);
	for (size_t i = 0; i < n; i++) {
		size_t ring = 0;

		if (i)
			assert_true(c[i - 1].tick_us <= c[i].tick_us);
		if (!c[i].head) {
			/* every mode, or the lowest ones with the static
			 * correction: the truncated candidate */
			assert_true(c[i].modes == 400 || c[i].modes == IRDM_AUTO_TRUNCATED);
			truncated += c[i].modes == IRDM_AUTO_TRUNCATED;
			continue;
		}
		heads++;
		for (size_t k = 0; k < 400; k++) {
			double w = sqrt(w2[k]), z = d.a_per_s / (2 * w) + d.b_s * w / 2;
			double rate = z <= 1 ? z * w : w * (z - sqrt(z * z - 1));

			ring += exp(-rate * c[i].head * 1e-3) > 1e-3;
		}
		assert_int_equal(c[i].modes, ring);
		assert_true(ring < 400);
	}
	assert_int_equal(truncated, 1);
	assert_int_equal(heads, n - 2);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_rates),
		cmocka_unit_test(test_kept_by_decay_not_frequency),
		cmocka_unit_test(test_permute_and_back),
		cmocka_unit_test(test_candidates),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
