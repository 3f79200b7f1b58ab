/* SPDX-License-Identifier: MIT */
#include "solve3.h"

#include <string.h>

static double det3(const double m[9])
{
	return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
	       m[2] * (m[3] * m[7] - m[4] * m[6]);
}

void ts_solve3(const double a[9], const double b[3], double x[3])
{
	double d = det3(a);

	for (int c = 0; c < 3; c++) {
		double m[9];

		memcpy(m, a, sizeof(m));
		for (int r = 0; r < 3; r++)
			m[3 * r + c] = b[r];
		x[c] = det3(m) / d;
	}
}
