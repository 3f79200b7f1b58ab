/* SPDX-License-Identifier: MIT */
/* The Hann taper and its sine bump (window.h). */
#include <math.h>

#include "modal/window.h"

/* i = 0 is the sample after the head: the taper starts just below 1 and
 * ends just above 0, so neither end of the window jumps. */
static double window_x(size_t i, size_t L)
{
	return (double)(i + 1) / (double)(L + 1);
}

double irdm_window_taper(size_t i, size_t L)
{
	return 0.5 * (1 + cos(M_PI * window_x(i, L)));
}

double irdm_window_bump(size_t i, size_t L)
{
	return sin(M_PI * window_x(i, L));
}
