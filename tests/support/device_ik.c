/* SPDX-License-Identifier: MIT */
#include "device_ik.h"

#include <string.h>

/* a x = b by Cramer's rule (a row-major, well conditioned near home) */
static void solve3(const double a[9], const double b[3], double x[3])
{
	double d = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
		   a[2] * (a[3] * a[7] - a[4] * a[6]);

	for (int c = 0; c < 3; c++) {
		double m[9];
		memcpy(m, a, sizeof(m));
		for (int r = 0; r < 3; r++)
			m[3 * r + c] = b[r];
		x[c] = (m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
			m[2] * (m[3] * m[7] - m[4] * m[6])) /
		       d;
	}
}

void dik_angles(const struct irdm_device_config *dev, const double p[3], double q[3])
{
	q[0] = q[1] = q[2] = 0;
	for (int it = 0; it < 50; it++) {
		double tip[3], e[3], j[9], dq[3];
		irdm_device_fk(dev, q, tip);
		for (int a = 0; a < 3; a++)
			e[a] = p[a] - tip[a];
		irdm_device_jacobian(dev, q, j);
		solve3(j, e, dq);
		for (int a = 0; a < 3; a++)
			q[a] += dq[a];
	}
}
