/* SPDX-License-Identifier: MIT */
/*
 * Absolute sleep on CLOCK_MONOTONIC and the timespec arithmetic of every
 * periodic loop: one copy for the project.
 */
#include <errno.h>

#include "irdm/posix/rt.h"

#define NSEC_PER_SEC 1000000000L

int irdm_rt_sleep_until(const struct timespec *t)
{
	int rc;

	/* absolute: a signal does not stretch the period, just retry */
	do
		rc = clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, t, NULL);
	while (rc == EINTR);
	return rc ? IRDM_EINVAL : IRDM_OK;
}

void irdm_rt_timespec_add(struct timespec *t, const struct timespec *dt)
{
	/* both normalised: the nanoseconds sum to less than 2 s, one carry at most */
	t->tv_sec += dt->tv_sec;
	t->tv_nsec += dt->tv_nsec;
	if (t->tv_nsec >= NSEC_PER_SEC) {
		t->tv_nsec -= NSEC_PER_SEC;
		t->tv_sec++;
	}
}

int64_t irdm_rt_timespec_diff_ns(const struct timespec *a, const struct timespec *b)
{
	return ((int64_t)b->tv_sec - (int64_t)a->tv_sec) * NSEC_PER_SEC +
	       ((int64_t)b->tv_nsec - (int64_t)a->tv_nsec);
}

int irdm_rt_timespec_cmp(const struct timespec *a, const struct timespec *b)
{
	if (a->tv_sec != b->tv_sec)
		return a->tv_sec < b->tv_sec ? -1 : 1;
	return (a->tv_nsec > b->tv_nsec) - (a->tv_nsec < b->tv_nsec);
}
