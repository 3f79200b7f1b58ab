/* SPDX-License-Identifier: MIT */
/*
 * How long a mode rings (modal/decay.h), the rule that chooses a hybrid
 * image's kept modes:
 *  - the slowest decay rate against hand-computed values, under-,
 *    critically and overdamped, and a free mass;
 *  - on eight modes under Rayleigh damping C = 0.01 s K, where the
 *    overdamped high modes decay at about 1/b = 100 /s while two in
 *    between (z 0.9 and 1) decay faster: the rank a hybrid keeps the
 *    first of is by envelope left past the head, not by frequency, a
 *    free mass first (modal/head_split.h);
 *  - the permutation that puts them first moves omega^2 and the mode
 *    shapes together, and its inverse restores them;
 *  - auto's candidates on a model: each hybrid keeps as few of its
 *    rank's modes as its predicted error allows (accuracy/split.h).
 */
#include <math.h>
#include <stdbool.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

#include "modal/decay.h"
#include "accuracy/split.h"
#include "modal/head_split.h"
#include "modal/response.h"
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
 * 1000 -> 1000 (5 - sqrt 24) = 101.02, 1e5 -> 100.0001.
 */
static const double w_rad[8] = { 10, 100, 150, 180, 200, 300, 1000, 1e5 };
static const struct irdm_rayleigh b_only = { .a_per_s = 0.0, .b_s = 0.01 };
static const int64_t col_dofs[3] = { 0, 1, 2 };
static const struct irdm_rayleigh *probe_damp;

static void modes_of(struct irdm_modes *m, double *w2, double *phi, size_t n)
{
	for (size_t k = 0; k < 8; k++) {
		w2[k] = w_rad[k] * w_rad[k];
		for (size_t i = 0; i < n; i++)
			phi[k * n + i] = (double)(10 * k + i); /* column k tells its mode */
	}
	*m = (struct irdm_modes){ .n = n, .n_modes = 8, .n_elastic_total = 8, .omega2 = w2, .phi = phi };
}

/*
 * Over 0.05314 s the envelope left is exp(-rate 0.05314): the most left
 * first is w 10, 100, then the overdamped 1e5 (100.0001 /s) and 1000
 * (101.02), then 150 (112.5), 300 (114.59), 180 (162), 200 (200): not
 * frequency order.  A free mass (w = 0) keeps all of it: first.
 */
#define HORIZON_S 0.05314

static void test_rank_by_envelope_left(void **state)
{
	static const size_t want[8] = { 0, 1, 7, 6, 2, 5, 3, 4 };
	static const size_t kept3[8] = { 0, 1, 7, 2, 3, 4, 5, 6 };
	struct irdm_modes m;
	double w2[8], phi[8 * 3];
	size_t rank[8], order[8];
	bool dropped[8];

	(void)state;
	modes_of(&m, w2, phi, 3);
	assert_int_equal(irdm_head_split_rank(&m, &b_only, HORIZON_S, rank), 0);
	for (size_t k = 0; k < 8; k++)
		assert_int_equal(rank[k], want[k]);
	/* keeping three: w 10, 100, 1e5 first, each group ascending */
	irdm_head_split_order(rank, 8, 3, order, dropped);
	for (size_t k = 0; k < 8; k++) {
		assert_int_equal(order[k], kept3[k]);
		assert_int_equal(dropped[k], !(k == 0 || k == 1 || k == 7));
	}
	w2[4] = 0;
	assert_int_equal(irdm_head_split_rank(&m, &b_only, HORIZON_S, rank), 0);
	assert_int_equal(rank[0], 4);
	assert_int_equal(rank[1], 0);
}

static void test_permute_and_back(void **state)
{
	struct irdm_modes m;
	double w2[8], phi[8 * 3];
	size_t order[8], inv[8];

	(void)state;
	modes_of(&m, w2, phi, 3);
	for (size_t k = 0; k < 8; k++)
		order[k] = (size_t[8]){ 0, 1, 7, 2, 3, 4, 5, 6 }[k];
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
 * 400 modes at 1 .. 400 Hz under 5 % at 1 Hz and at 100 Hz, 1 ms, one
 * column every mode moves as much (along directions that vary): each hybrid keeps the first modes of
 * its head's rank, as few as the prediction allows: predicted within
 * half of 1e-3 with them, over it with one fewer (tried here on the
 * probe from scratch); a head keeps fewer than all; every mode, and the
 * truncated 300 when predicted within the target, are the candidates
 * without a head; the list is ordered by estimated tick cost.
 */
static double predicted(struct irdm_split_probe *p, const struct irdm_modes *m, unsigned head,
			size_t k)
{
	size_t rank[400];

	for (size_t i = 0; i < 400; i++)
		rank[i] = i; /* no head: the lowest k kept */
	if (head)
		assert_int_equal(irdm_head_split_rank(m, probe_damp, head * 1e-3, rank), 0);
	irdm_split_begin(p);
	return irdm_split_try(p, &rank[k], 400 - k, head);
}

static void test_candidates(void **state)
{
	struct irdm_auto_candidate c[IRDM_AUTO_MAX_CANDIDATES];
	struct irdm_rayleigh d;
	static double w2[400], phi[3 * 400];
	static struct irdm_mode zoh[400];
	struct irdm_modes m = { .n = 3, .n_modes = 400, .n_elastic_total = 400, .omega2 = w2, .phi = phi };
	struct irdm_split_probe p;
	double w1 = 2 * M_PI, w100 = 2 * M_PI * 100;
	size_t n, heads = 0, truncated = 0;

	(void)state;
	/* z(w) = a / 2w + b w / 2 with z = 0.05 at w1 and w100 */
	d.b_s = 2 * 0.05 / (w1 + w100);
	d.a_per_s = d.b_s * w1 * w100;
	probe_damp = &d;
	for (size_t k = 0; k < 400; k++) {
		w2[k] = pow(2 * M_PI * (double)(k + 1), 2);
		phi[3 * k] = 1; /* directions that vary: R[0] is not singular */
		phi[3 * k + 1] = sin((double)k);
		phi[3 * k + 2] = cos((double)k);
	}
	irdm_modes_discretise(&m, &d, 1e-3, zoh);
	assert_int_equal(irdm_split_probe_init(&p, &m, zoh, col_dofs, 1, 1000), 0);
	n = irdm_auto_candidates(&m, &d, 1e-3, 1e-3, true, &p, c);
	assert_true(n >= 3);
	for (size_t i = 0; i < n; i++) {
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
		assert_true(c[i].modes < 400);
		assert_float_equal(predicted(&p, &m, c[i].head, c[i].modes), c[i].predicted, 1e-12);
		assert_true(c[i].predicted <= 5e-4);
		assert_true(predicted(&p, &m, c[i].head, c[i].modes - 1) > 5e-4);
	}
	/* the truncated one only when predicted within the target */
	assert_int_equal(truncated, predicted(&p, &m, 0, IRDM_AUTO_TRUNCATED) <= 1e-3);
	irdm_split_probe_free(&p);
	assert_int_equal(heads, n - 1 - truncated);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_rates),
		cmocka_unit_test(test_rank_by_envelope_left),
		cmocka_unit_test(test_permute_and_back),
		cmocka_unit_test(test_candidates),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
