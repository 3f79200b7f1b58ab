/* SPDX-License-Identifier: MIT */
/*
 * The loop's clock: virtual time advances exactly one period per wait and
 * reports no latency; real time paces absolute periods (N waits take N
 * periods, measured by an independent clock read) and reports the lateness
 * of each wake-up.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <time.h>

#include <cmocka.h>

#include "irdm/posix/clock.h"
#include "irdm/error.h"

static double now_s(void)
{
	struct timespec t;

	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void test_rejects_bad_periods(void **state)
{
	struct irdm_clock c;

	(void)state;
	assert_int_equal(irdm_clock_start(&c, IRDM_CLOCK_REAL, 0), IRDM_EINVAL);
	assert_int_equal(irdm_clock_start(&c, IRDM_CLOCK_REAL, 1000001), IRDM_EINVAL);
	assert_int_equal(irdm_clock_start(&c, (enum irdm_clock_mode)7, 1000), IRDM_EINVAL);
	assert_int_equal(irdm_clock_start(&c, IRDM_CLOCK_VIRTUAL, 1000000), IRDM_OK);
}

static void test_virtual_time_is_exact_and_instant(void **state)
{
	struct irdm_clock c;
	double t0 = now_s();

	(void)state;
	assert_int_equal(irdm_clock_start(&c, IRDM_CLOCK_VIRTUAL, 1000), IRDM_OK);
	for (int i = 0; i < 60000; i++) {
		assert_int_equal(irdm_clock_wait(&c), 0);
		assert_true(fabs(irdm_clock_time_s(&c) - (double)i * 1e-3) <= 1e-15 * i);
		assert_int_equal(irdm_clock_elapsed_ns(&c), 0);
	}
	/* a minute of virtual time in well under a second of real time */
	assert_true(now_s() - t0 < 1.0);
}

static void test_real_time_paces_absolute_periods(void **state)
{
	enum { N = 100, PERIOD_US = 1000 };
	struct irdm_clock c;
	int64_t late, worst = 0;
	double t0, t1;

	(void)state;
	assert_int_equal(irdm_clock_start(&c, IRDM_CLOCK_REAL, PERIOD_US), IRDM_OK);
	t0 = now_s();
	for (int i = 0; i < N; i++) {
		late = irdm_clock_wait(&c);
		assert_true(late >= 0);
		worst = late > worst ? late : worst;
		assert_true(irdm_clock_elapsed_ns(&c) >= 0);
	}
	t1 = now_s();
	/* N waits end N periods after the start, give or take one period
	 * for where in its period the clock started and a wake-up's lateness */
	print_message("100 real periods of 1 ms took %.3f ms, worst wake-up %.1f us late\n",
		      (t1 - t0) * 1e3, (double)worst * 1e-3);
	assert_true(t1 - t0 >= (N - 1) * PERIOD_US * 1e-6);
	assert_true(t1 - t0 <= (N + 1) * PERIOD_US * 1e-6 + (double)worst * 1e-9 + 0.05);
	assert_true(fabs(irdm_clock_time_s(&c) - (double)(N - 1) * 1e-3) <= 1e-15 * N);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_rejects_bad_periods),
		cmocka_unit_test(test_virtual_time_is_exact_and_instant),
		cmocka_unit_test(test_real_time_paces_absolute_periods),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
