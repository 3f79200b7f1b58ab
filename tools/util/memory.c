/* SPDX-License-Identifier: MIT */
/* The memory a tool may plan for (memory.h). */
#include <sys/resource.h>
#include <unistd.h>

#include "util/memory.h"

/* Lower *budget to resource r's soft limit, if set and lower. */
static void limit(int r, const char *name, double *budget, const char **what)
{
	struct rlimit rl;

	if (getrlimit(r, &rl) || rl.rlim_cur == RLIM_INFINITY)
		return;
	if (*budget == 0 || (double)rl.rlim_cur < *budget) {
		*budget = (double)rl.rlim_cur;
		*what = name;
	}
}

static double cap; /* irdm_memory_cap()'s, bytes (0: none) */

void irdm_memory_cap(double bytes)
{
	cap = bytes > 0 ? bytes : 0;
}

double irdm_memory_budget(const char **what)
{
	long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
	double budget = pages > 0 && size > 0 ? (double)pages * (double)size : 0;

	*what = "physical memory";
	limit(RLIMIT_AS, "ulimit -v", &budget, what);
	limit(RLIMIT_DATA, "ulimit -d", &budget, what);
	if (cap > 0 && (budget == 0 || cap < budget)) {
		budget = cap;
		*what = "max_memory_mib";
	}
	return budget;
}
