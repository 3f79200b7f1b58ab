/* SPDX-License-Identifier: MIT */
/* Wall-clock seconds for the tools' stage timings (offline only). */
#ifndef IRDM_TOOLS_UTIL_CLOCK_H
#define IRDM_TOOLS_UTIL_CLOCK_H

#include <time.h>

static inline double irdm_now_s(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#endif
