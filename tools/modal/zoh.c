/* SPDX-License-Identifier: MIT */
/*
 * Exact zero-order-hold discretisation of one damped mode.
 *
 * Van Loan: exp([[Ac, bc], [0, 0]] dt) = [[A, b], [0, 1]] with
 * Ac = [[0, 1], [-w^2, -2 z w]], bc = (0, 1).  The 3x3 exponential is taken
 * by scaling and squaring of a Taylor series, which is accurate to double
 * rounding for any w dt because the scaled matrix has norm <= 1/2 and the
 * series is summed to 20 terms (error < 2^-20 / 20! relative).
 */
#include <math.h>
#include <string.h>

#include "modal/modal.h"

static void mat3_mul(const double a[9], const double b[9], double c[9])
{
	double t[9];

	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
			t[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
	memcpy(c, t, sizeof(t));
}

static void expm3(const double m[9], double e[9])
{
	double norm = 0, s[9], term[9];
	int squarings = 0;

	for (int i = 0; i < 9; i++)
		norm = fmax(norm, fabs(m[i]));
	norm *= 3;
	while (norm > 0.5 && squarings < 1000) {
		norm /= 2;
		squarings++;
	}
	for (int i = 0; i < 9; i++)
		s[i] = ldexp(m[i], -squarings);
	/* Taylor: e = I + s + s^2/2! + ... */
	memset(e, 0, 9 * sizeof(double));
	memset(term, 0, sizeof(term));
	for (int i = 0; i < 3; i++)
		e[4 * i] = term[4 * i] = 1.0;
	for (int k = 1; k <= 20; k++) {
		mat3_mul(term, s, term);
		for (int i = 0; i < 9; i++) {
			term[i] /= k;
			e[i] += term[i];
		}
	}
	for (int k = 0; k < squarings; k++)
		mat3_mul(e, e, e);
}

void irdm_zoh_mode(double w, double z, double dt, struct irdm_mode *out)
{
	double m[9] = {
		0,
		dt,
		0,
		-w * w * dt,
		-2 * z * w * dt,
		dt,
		0,
		0,
		0,
	};
	double e[9];

	expm3(m, e);
	out->omega_rad_s = w;
	out->zeta = z;
	out->a[0] = e[0];
	out->a[1] = e[1];
	out->a[2] = e[3];
	out->a[3] = e[4];
	out->b[0] = e[2];
	out->b[1] = e[5];
}

void irdm_zoh_response(const struct irdm_mode *m, size_t n, double *h)
{
	double x0 = m->b[0], x1 = m->b[1];

	for (size_t s = 0; s < n; s++) {
		h[s] = x0;
		double y0 = m->a[0] * x0 + m->a[1] * x1;
		double y1 = m->a[2] * x0 + m->a[3] * x1;
		x0 = y0;
		x1 = y1;
	}
}
