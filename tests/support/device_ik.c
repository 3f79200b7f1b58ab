/* SPDX-License-Identifier: MIT */
#include "device_ik.h"
#include "solve3.h"

void dik_angles(const struct irdm_device_config *dev, const double p[3], double q[3])
{
	q[0] = q[1] = q[2] = 0;
	for (int it = 0; it < 50; it++) {
		double tip[3], e[3], j[9], dq[3];
		irdm_device_fk(dev, q, tip);
		for (int a = 0; a < 3; a++)
			e[a] = p[a] - tip[a];
		irdm_device_jacobian(dev, q, j);
		ts_solve3(j, e, dq);
		for (int a = 0; a < 3; a++)
			q[a] += dq[a];
	}
}
