/* SPDX-License-Identifier: MIT */
/*
 * First-order adaptive windowing (irdm/device.h says what and why).  Times
 * count in samples back from the newest (0, -1, -2, ...) and positions are
 * taken relative to the newest sample, so the fit's sums stay small and a
 * large absolute position loses no precision.
 */
#include <math.h>

#include "irdm/device.h"
#include "irdm/error.h"

int irdm_velocity_init(struct irdm_velocity *v, double period_s, double band, unsigned window)
{
	if (!(isfinite(period_s) && period_s > 0) || !(isfinite(band) && band > 0))
		return IRDM_EINVAL;
	if (window < 2 || window > IRDM_VELOCITY_WINDOW_MAX)
		return IRDM_EINVAL;
	v->period_s = period_s;
	v->band = band;
	v->window = window;
	irdm_velocity_reset(v);
	return IRDM_OK;
}

void irdm_velocity_reset(struct irdm_velocity *v)
{
	v->count = 0;
	v->head = 0;
	v->last_window = 0;
}

/* Sample `age` steps before the newest, relative to the newest. */
static double rel(const struct irdm_velocity *v, unsigned age)
{
	unsigned i = (v->head + IRDM_VELOCITY_WINDOW_MAX - age) % IRDM_VELOCITY_WINDOW_MAX;

	return v->y[i] - v->y[v->head];
}

/* Does the line a + b t stay within the band of the n newest samples? */
static int within_band(const struct irdm_velocity *v, unsigned n, double a, double b)
{
	for (unsigned age = 0; age < n; age++)
		if (fabs(rel(v, age) - (a - b * age)) > v->band)
			return 0;
	return 1;
}

/* Slope (per sample) of the longest window that stays within the band. */
static double adaptive_slope(struct irdm_velocity *v)
{
	double st = 0, stt = 0, sy = 0, sty = 0, slope = 0;
	unsigned n;

	for (n = 1; n <= v->count; n++) {
		double t = -(double)(n - 1), y = rel(v, n - 1), den, b, a;

		st += t;
		stt += t * t;
		sy += y;
		sty += t * y;
		if (n < 2)
			continue;
		den = n * stt - st * st;
		b = (n * sty - st * sy) / den;
		a = (sy - b * st) / n;
		/* two samples always fit: the window is at least a difference */
		if (n > 2 && !within_band(v, n, a, b))
			break;
		slope = b;
	}
	v->last_window = n - 1;
	return slope;
}

int irdm_velocity_update(struct irdm_velocity *v, double position, double *vel)
{
	*vel = 0;
	if (!isfinite(position))
		return IRDM_EFAULT;
	v->head = (v->head + 1) % IRDM_VELOCITY_WINDOW_MAX;
	v->y[v->head] = position;
	if (v->count < v->window)
		v->count++;
	*vel = adaptive_slope(v) / v->period_s;
	return IRDM_OK;
}
