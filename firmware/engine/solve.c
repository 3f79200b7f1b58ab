/* SPDX-License-Identifier: MIT */
/*
 * The contact system (W + C) F = rhs: symmetric positive semi-definite W
 * (the contact points' R[0] compliance) plus the coupling compliance C.
 * Two contacts on one node, or a contact whose vertices are all fixed, make
 * it singular: instead of dividing by (almost) zero we add a small multiple
 * of the identity (Tikhonov) and solve again, which gives the minimum-norm
 * split of the force in the limit.
 *
 * That limit exists only if the system is consistent.  Two rigid contacts
 * on one node asked for different displacements are not: the regularised
 * force is then the disagreement over the small multiple (2.9e11 N for
 * 1 mm, tests/test_stability_cases.c), so a regularised solution whose
 * residual is not small against the right-hand side is reported instead.
 */
#include <math.h>

#include "engine_priv.h"

/* Relative size of a pivot below which the system counts as singular. */
#define PIVOT_REL 1e-10
/* Largest residual of a regularised solution, relative to the right-hand
 * side, that still counts as solving it (a consistent singular system
 * leaves about eps |F|, far below this). */
#define RESIDUAL_REL 1e-6

/* In-place Cholesky of the n x n row-major a; 0 or -1 on a small pivot. */
static int cholesky(double *a, int n, double tiny)
{
	for (int j = 0; j < n; j++) {
		double d = a[j * n + j];
		for (int k = 0; k < j; k++)
			d -= a[j * n + k] * a[j * n + k];
		if (!(d > tiny))
			return -1;
		d = sqrt(d);
		a[j * n + j] = d;
		for (int i = j + 1; i < n; i++) {
			double s = a[i * n + j];
			for (int k = 0; k < j; k++)
				s -= a[i * n + k] * a[j * n + k];
			a[i * n + j] = s / d;
		}
	}
	return 0;
}

static void cholesky_solve(const double *l, int n, double *b)
{
	for (int i = 0; i < n; i++) {
		double s = b[i];
		for (int k = 0; k < i; k++)
			s -= l[i * n + k] * b[k];
		b[i] = s / l[i * n + i];
	}
	for (int i = n - 1; i >= 0; i--) {
		double s = b[i];
		for (int k = i + 1; k < n; k++)
			s -= l[k * n + i] * b[k];
		b[i] = s / l[i * n + i];
	}
}

/* max |keep x - b| <= RESIDUAL_REL max |b| */
static bool solves(const double *keep, const double *x, const double *b, int n)
{
	double res = 0, size = 0;

	for (int i = 0; i < n; i++) {
		double r = -b[i];
		for (int k = 0; k < n; k++)
			r += keep[i * n + k] * x[k];
		res = fmax(res, fabs(r));
		size = fmax(size, fabs(b[i]));
	}
	return res <= RESIDUAL_REL * size;
}

int irdm_solve_spd(double *a, double *rhs, int n)
{
	double keep[MAX_SOLVE * MAX_SOLVE], b[MAX_SOLVE], scale = 0;
	int regularised = 0;

	for (int i = 0; i < n * n; i++)
		keep[i] = a[i];
	for (int i = 0; i < n; i++)
		b[i] = rhs[i];
	for (int i = 0; i < n; i++)
		scale = fmax(scale, fabs(a[i * n + i]));
	if (scale == 0)
		scale = 1;
	for (double eps = 0;; eps = eps ? eps * 100 : PIVOT_REL * scale) {
		for (int i = 0; i < n * n; i++)
			a[i] = keep[i];
		for (int i = 0; i < n; i++)
			a[i * n + i] += eps;
		if (!cholesky(a, n, PIVOT_REL * scale * 1e-3))
			break;
		regularised = 1;
		if (eps > scale) { /* hopeless (non-finite input): no force */
			for (int i = 0; i < n; i++)
				rhs[i] = 0;
			return 1;
		}
	}
	cholesky_solve(a, n, rhs);
	if (regularised && !solves(keep, rhs, b, n))
		return -1;
	return regularised;
}
