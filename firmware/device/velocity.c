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

/* The newest sample is y[head + MAX], older ones below it: each sample is
 * stored twice (slots i and i + MAX) so any window is contiguous. */
static const double *newest(const struct irdm_velocity *v)
{
	return &v->y[v->head + IRDM_VELOCITY_WINDOW_MAX];
}

/* Does the line a + b t stay within the band of the n newest samples? */
static int within_band(const struct irdm_velocity *v, unsigned n, double a, double b)
{
	const double *y = newest(v), y0 = y[0];

	for (unsigned age = 0; age < n; age++)
		if (fabs(y[-(int)age] - y0 - (a - b * age)) > v->band)
			return 0;
	return 1;
}

/*
 * Least-squares slope (per sample) of the n >= 2 newest samples; returns
 * whether that line stays within the band of all of them.  Times run 0,
 * -1, ... back from the newest sample.
 */
static int fit(const struct irdm_velocity *v, unsigned n, double *slope)
{
	const double *y = newest(v), y0 = y[0];
	double st = 0, stt = 0, sy = 0, sty = 0, a;

	for (unsigned age = 0; age < n; age++) {
		double t = -(double)age, d = y[-(int)age] - y0;

		st += t;
		stt += t * t;
		sy += d;
		sty += t * d;
	}
	*slope = (n * sty - st * sy) / (n * stt - st * st);
	a = (sy - *slope * st) / n;
	return within_band(v, n, a, *slope);
}

/*
 * The longest window that fits, searched from last sample's length: grow
 * while the next longer one fits, else shrink until one fits (two samples
 * always do).  Windows change slowly from sample to sample, so this takes
 * a few O(n) fits where growing from two every sample would take O(n^2).
 */
static double adaptive_slope(struct irdm_velocity *v)
{
	double slope = 0, longer;
	unsigned n = v->last_window + 1;

	if (v->count < 2) {
		v->last_window = v->count;
		return 0;
	}
	n = n < 2 ? 2 : n > v->count ? v->count :
				       n;
	if (fit(v, n, &slope) || n == 2) {
		while (n < v->count && fit(v, n + 1, &longer)) {
			n++;
			slope = longer;
		}
	} else {
		while (--n > 2 && !fit(v, n, &slope))
			;
		if (n == 2)
			fit(v, 2, &slope);
	}
	v->last_window = n;
	return slope;
}

int irdm_velocity_update(struct irdm_velocity *v, double position, double *vel)
{
	*vel = 0;
	if (!isfinite(position))
		return IRDM_EFAULT;
	v->head = (v->head + 1) % IRDM_VELOCITY_WINDOW_MAX;
	v->y[v->head] = position;
	v->y[v->head + IRDM_VELOCITY_WINDOW_MAX] = position;
	if (v->count < v->window)
		v->count++;
	*vel = adaptive_slope(v) / v->period_s;
	return IRDM_OK;
}
