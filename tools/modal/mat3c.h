/* SPDX-License-Identifier: MIT */
/* Complex 3x3 (row-major) determinant and adjugate, for the certificates. */
#ifndef IRDM_TOOLS_MAT3C_H
#define IRDM_TOOLS_MAT3C_H

#include <complex.h>

static inline double complex irdm_det3c(const double complex a[9])
{
	return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) + a[2] * (a[3] * a[7] - a[4] * a[6]);
}

/* adj(a): a adj(a) = det(a) I */
static inline void irdm_adj3c(const double complex a[9], double complex b[9])
{
	b[0] = a[4] * a[8] - a[5] * a[7];
	b[1] = a[2] * a[7] - a[1] * a[8];
	b[2] = a[1] * a[5] - a[2] * a[4];
	b[3] = a[5] * a[6] - a[3] * a[8];
	b[4] = a[0] * a[8] - a[2] * a[6];
	b[5] = a[2] * a[3] - a[0] * a[5];
	b[6] = a[3] * a[7] - a[4] * a[6];
	b[7] = a[1] * a[6] - a[0] * a[7];
	b[8] = a[0] * a[4] - a[1] * a[3];
}

#endif
