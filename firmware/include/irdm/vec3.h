/* SPDX-License-Identifier: MIT */
/*
 * 3-vectors of doubles: the one set of small helpers the firmware modules
 * share (engine, contact, rigid).  Each helper does exactly the operations
 * its name says, in the order written here, so that code calling it gives
 * the same bits as the expression it replaces: a dot product is
 * a0 b0 + a1 b1 + a2 b2, summed left to right.  Outputs come first (like
 * memcpy) and may alias any input.
 */
#ifndef IRDM_VEC3_H
#define IRDM_VEC3_H

#include <math.h>
#include <stdbool.h>

static inline double irdm_v3_dot(const double a[3], const double b[3])
{
	return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* |a|, as sqrt(a . a). */
static inline double irdm_v3_norm(const double a[3])
{
	return sqrt(irdm_v3_dot(a, a));
}

/* r = a x b */
static inline void irdm_v3_cross(double r[3], const double a[3], const double b[3])
{
	double x = a[1] * b[2] - a[2] * b[1];
	double y = a[2] * b[0] - a[0] * b[2];
	double z = a[0] * b[1] - a[1] * b[0];

	r[0] = x;
	r[1] = y;
	r[2] = z;
}

/* r = a + b */
static inline void irdm_v3_add(double r[3], const double a[3], const double b[3])
{
	r[0] = a[0] + b[0];
	r[1] = a[1] + b[1];
	r[2] = a[2] + b[2];
}

/* r = a - b */
static inline void irdm_v3_sub(double r[3], const double a[3], const double b[3])
{
	r[0] = a[0] - b[0];
	r[1] = a[1] - b[1];
	r[2] = a[2] - b[2];
}

/* r = s a */
static inline void irdm_v3_scale(double r[3], double s, const double a[3])
{
	r[0] = s * a[0];
	r[1] = s * a[1];
	r[2] = s * a[2];
}

/* y += s x */
static inline void irdm_v3_axpy(double y[3], double s, const double x[3])
{
	y[0] += s * x[0];
	y[1] += s * x[1];
	y[2] += s * x[2];
}

/* r = w0 a + w1 b + w2 c: the point of barycentric weights w on (a, b, c). */
static inline void irdm_v3_bary(double r[3], const double w[3], const double a[3],
				const double b[3], const double c[3])
{
	for (int i = 0; i < 3; i++)
		r[i] = w[0] * a[i] + w[1] * b[i] + w[2] * c[i];
}

static inline void irdm_v3_zero(double r[3])
{
	r[0] = r[1] = r[2] = 0;
}

static inline bool irdm_v3_finite(const double a[3])
{
	return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]);
}

#endif /* IRDM_VEC3_H */
