/* SPDX-License-Identifier: MIT */
/* The force loop's clock: real (absolute sleeps) or virtual (irdm/posix/clock.h). */
#include <string.h>

#include "irdm/posix/clock.h"
#include "irdm/error.h"
#include "irdm/posix/rt.h"

int irdm_clock_start(struct irdm_clock *c, enum irdm_clock_mode mode, uint32_t period_us)
{
	if ((mode != IRDM_CLOCK_REAL && mode != IRDM_CLOCK_VIRTUAL) || period_us == 0 ||
	    period_us > 1000000)
		return IRDM_EINVAL;
	memset(c, 0, sizeof(*c));
	c->mode = mode;
	c->period_ns = period_us * 1000u;
	if (mode == IRDM_CLOCK_REAL) {
		clock_gettime(CLOCK_MONOTONIC, &c->next);
		irdm_rt_timespec_add(&c->next, &(struct timespec){ 0, c->period_ns });
	}
	return IRDM_OK;
}

int64_t irdm_clock_wait(struct irdm_clock *c)
{
	int64_t late_ns;

	c->tick++;
	if (c->mode == IRDM_CLOCK_VIRTUAL)
		return 0;
	irdm_rt_sleep_until(&c->next);
	clock_gettime(CLOCK_MONOTONIC, &c->wake);
	late_ns = irdm_rt_timespec_diff_ns(&c->next, &c->wake);
	irdm_rt_timespec_add(&c->next, &(struct timespec){ 0, c->period_ns });
	return late_ns;
}

int64_t irdm_clock_elapsed_ns(const struct irdm_clock *c)
{
	struct timespec now;

	if (c->mode == IRDM_CLOCK_VIRTUAL)
		return 0;
	clock_gettime(CLOCK_MONOTONIC, &now);
	return irdm_rt_timespec_diff_ns(&c->wake, &now);
}

double irdm_clock_time_s(const struct irdm_clock *c)
{
	return c->tick ? (double)(c->tick - 1) * c->period_ns * 1e-9 : 0.0;
}
