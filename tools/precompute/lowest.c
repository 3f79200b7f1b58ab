/* SPDX-License-Identifier: MIT */
/* representation = auto from the lowest modes (lowest.h). */
#include <math.h>

#include "precompute/lowest.h"

double irdm_lowest_left_first(double max_error)
{
	return fmin(IRDM_LOWEST_SHARE * max_error, IRDM_LOWEST_SHARE_MAX);
}

double irdm_lowest_left_next(double left, double max_error, double measured)
{
	double f = 0.5 * max_error / measured;

	return left * fmin(fmax(f, 0.01), 0.5);
}

size_t irdm_lowest_below(const struct irdm_modes *m, size_t n, double w)
{
	size_t k = 0;

	while (k < n && m->omega2[k] <= w * w)
		k++;
	return k;
}
