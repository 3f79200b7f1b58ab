/* SPDX-License-Identifier: MIT */
/*
 * The loop's clock: virtual time advances exactly one period per wait,
 * reports no latency and never sleeps (a minute of it runs in seccomp
 * strict mode, where a sleep would be a killing system call; the real
 * clock there is the control); real time paces absolute periods (N waits
 * take at least N - 1 periods, measured by an independent clock read) and
 * reports the lateness of each wake-up.  How late is printed, not asserted:
 * a unit test on a shared machine cannot hold a time (make jitter measures
 * it).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <math.h>
#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/wait.h>
#include <time.h>

#include <cmocka.h>

#include "irdm/posix/clock.h"
#include "irdm/error.h"
#include "support/strict_mode.h"

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

static void test_virtual_time_is_exact(void **state)
{
	struct irdm_clock c;

	(void)state;
	assert_int_equal(irdm_clock_start(&c, IRDM_CLOCK_VIRTUAL, 1000), IRDM_OK);
	for (int i = 0; i < 60000; i++) {
		assert_int_equal(irdm_clock_wait(&c), 0);
		assert_true(fabs(irdm_clock_time_s(&c) - (double)i * 1e-3) <= 1e-15 * i);
		assert_int_equal(irdm_clock_elapsed_ns(&c), 0);
	}
}

struct wait_result {
	int prctl_errno;
	int64_t late_sum;
};

/* A minute of 1 ms waits on the clock given, in strict mode. */
static void waits_child(void *arg, int fd)
{
	struct irdm_clock *c = arg;
	struct wait_result res = { 0 };

	res.prctl_errno = strict_enter();
	if (res.prctl_errno)
		strict_exit(fd, &res, sizeof(res), STRICT_UNAVAILABLE);
	for (int i = 0; i < 60000; i++)
		res.late_sum += irdm_clock_wait(c);
	strict_exit(fd, &res, sizeof(res), 0);
}

static int strict_waits(enum irdm_clock_mode mode, struct wait_result *res)
{
	struct irdm_clock c;
	size_t got;
	int status;

	assert_int_equal(irdm_clock_start(&c, mode, 1000), IRDM_OK);
	status = strict_run(waits_child, &c, res, sizeof(*res), &got);
	if (WIFEXITED(status) && WEXITSTATUS(status) == STRICT_UNAVAILABLE) {
		print_message("  seccomp strict mode not available (errno %d): skipped\n",
			      res->prctl_errno);
		skip();
	}
	return status;
}

/* Virtual time never sleeps nor reads a clock: a minute of it makes no
 * system call.  The control: the real clock's first wait sleeps, a system
 * call that strict mode kills. */
static void test_virtual_time_makes_no_system_call(void **state)
{
	struct wait_result res;
	int status;

	(void)state;
	status = strict_waits(IRDM_CLOCK_VIRTUAL, &res);
	assert_true(WIFEXITED(status));
	assert_int_equal(WEXITSTATUS(status), 0);
	assert_int_equal(res.late_sum, 0);
	status = strict_waits(IRDM_CLOCK_REAL, &res);
	assert_true(WIFSIGNALED(status));
	assert_int_equal(WTERMSIG(status), SIGKILL);
}

static void test_real_time_paces_absolute_periods(void **state)
{
	enum { N = 100,
	       PERIOD_US = 1000 };
	struct irdm_clock c;
	int64_t late, worst = 0;
	double t0, t1;

	(void)state;
	t0 = now_s(); /* before the start: load only adds to t1 - t0 */
	assert_int_equal(irdm_clock_start(&c, IRDM_CLOCK_REAL, PERIOD_US), IRDM_OK);
	for (int i = 0; i < N; i++) {
		late = irdm_clock_wait(&c);
		assert_true(late >= 0);
		worst = late > worst ? late : worst;
		assert_true(irdm_clock_elapsed_ns(&c) >= 0);
	}
	t1 = now_s();
	/* N waits end no sooner than N periods after the start, give or take
	 * one period for where in its period the clock started */
	print_message("100 real periods of 1 ms took %.3f ms, worst wake-up %.1f us late\n",
		      (t1 - t0) * 1e3, (double)worst * 1e-3);
	assert_true(t1 - t0 >= (N - 1) * PERIOD_US * 1e-6);
	assert_true(fabs(irdm_clock_time_s(&c) - (double)(N - 1) * 1e-3) <= 1e-15 * N);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_rejects_bad_periods),
		cmocka_unit_test(test_virtual_time_is_exact),
		cmocka_unit_test(test_virtual_time_makes_no_system_call),
		cmocka_unit_test(test_real_time_paces_absolute_periods),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
