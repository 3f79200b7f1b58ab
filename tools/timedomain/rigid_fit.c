/* SPDX-License-Identifier: MIT */
/*
 * Rigid-motion removal for floating objects: weighted Kabsch (finite
 * rotation, through a 3x3 SVD) and its linearisation (w-orthogonal
 * projection off the six rigid modes).  See rigid_fit.h.
 */
#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <string.h>

#include "timedomain/rigid_fit.h"

/* Bound on Jacobi sweeps; 3x3 converges quadratically in a handful. */
#define SVD3_MAX_SWEEPS 64

static double weight(const double *w, size_t i)
{
	return w ? w[i] : 1.0;
}

static void cross3(const double a[3], const double b[3], double c[3])
{
	c[0] = a[1] * b[2] - a[2] * b[1];
	c[1] = a[2] * b[0] - a[0] * b[2];
	c[2] = a[0] * b[1] - a[1] * b[0];
}

static double det3(const double m[9])
{
	return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) + m[2] * (m[3] * m[7] - m[4] * m[6]);
}

static double col_dot(const double m[9], int i, int j)
{
	return m[i] * m[j] + m[3 + i] * m[3 + j] + m[6 + i] * m[6 + j];
}

/* Columns (p, q) of m <- [m_p m_q] [c s; -s c]. */
static void col_rotate(double m[9], int p, int q, double c, double s)
{
	for (int r = 0; r < 3; r++) {
		double mp = m[3 * r + p], mq = m[3 * r + q];

		m[3 * r + p] = c * mp - s * mq;
		m[3 * r + q] = s * mp + c * mq;
	}
}

static void col_swap(double m[9], int i, int j)
{
	for (int r = 0; r < 3; r++) {
		double t = m[3 * r + i];

		m[3 * r + i] = m[3 * r + j];
		m[3 * r + j] = t;
	}
}

/* One-sided Jacobi: rotate column pairs of b (and v) until orthogonal. */
static void svd3_orthogonalise(double b[9], double v[9])
{
	for (int sweep = 0; sweep < SVD3_MAX_SWEEPS; sweep++) {
		bool rotated = false;

		for (int p = 0; p < 2; p++) {
			for (int q = p + 1; q < 3; q++) {
				double al = col_dot(b, p, p), be = col_dot(b, q, q);
				double ga = col_dot(b, p, q);

				if (ga == 0.0 || fabs(ga) <= DBL_EPSILON * sqrt(al * be))
					continue;
				double zeta = (be - al) / (2.0 * ga);
				double t = copysign(1.0, zeta) / (fabs(zeta) + hypot(1.0, zeta));
				double c = 1.0 / sqrt(1.0 + t * t);

				col_rotate(b, p, q, c, c * t);
				col_rotate(v, p, q, c, c * t);
				rotated = true;
			}
		}
		if (!rotated)
			return;
	}
}

/* Any unit vector orthogonal to unit a. */
static void orthogonal_unit(const double a[3], double o[3])
{
	double e[3] = { 0, 0, 0 }, n;
	int k = 0;

	for (int i = 1; i < 3; i++)
		if (fabs(a[i]) < fabs(a[k]))
			k = i;
	e[k] = 1.0;
	cross3(a, e, o);
	n = sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
	for (int i = 0; i < 3; i++)
		o[i] /= n;
}

/* u's columns from the orthogonalised b; tiny columns are completed so that
 * u stays orthogonal (their singular values are ~0, so any completion is an
 * SVD). */
static void svd3_left(const double b[9], const double s[3], double u[9])
{
	double col[3][3];
	const double tiny = 64 * DBL_EPSILON * s[0];

	for (int j = 0; j < 3; j++)
		for (int r = 0; r < 3; r++)
			col[j][r] = s[j] > tiny && s[j] > 0 ? b[3 * r + j] / s[j] : 0.0;
	if (!(s[0] > 0))
		col[0][0] = 1.0;
	if (!(s[1] > tiny && s[1] > 0))
		orthogonal_unit(col[0], col[1]);
	if (!(s[2] > tiny && s[2] > 0))
		cross3(col[0], col[1], col[2]);
	for (int j = 0; j < 3; j++)
		for (int r = 0; r < 3; r++)
			u[3 * r + j] = col[j][r];
}

int irdm_svd3(const double a[9], double u[9], double s[3], double v[9])
{
	double b[9];

	for (int i = 0; i < 9; i++)
		if (!isfinite(a[i]))
			return IRDM_ENUMERIC;
	memcpy(b, a, sizeof(b));
	memset(v, 0, 9 * sizeof(double));
	v[0] = v[4] = v[8] = 1.0;
	svd3_orthogonalise(b, v);
	for (int j = 0; j < 3; j++)
		s[j] = sqrt(col_dot(b, j, j));
	/* sort descending (3 elements: bubble) */
	for (int pass = 0; pass < 2; pass++) {
		for (int j = 0; j < 2; j++) {
			if (s[j] < s[j + 1]) {
				double t = s[j];

				s[j] = s[j + 1];
				s[j + 1] = t;
				col_swap(b, j, j + 1);
				col_swap(v, j, j + 1);
			}
		}
	}
	svd3_left(b, s, u);
	return 0;
}

/*
 * Rotation maximising tr(rot h) for h = sum w r t^T (r rest, t deformed):
 * h = U S V^T gives rot = V D U^T, D = diag(1, 1, sign det(V U^T)) so that
 * a reflection is never returned (the guard flips the weakest direction).
 */
static int kabsch_rotation(const double h[9], double rot[9])
{
	double u[9], s[3], v[9], d;

	if (irdm_svd3(h, u, s, v))
		return IRDM_ENUMERIC;
	/* rank < 2: the points are collinear, rotation about them is free */
	if (!(s[1] > 1e-12 * s[0]))
		return IRDM_ENUMERIC;
	d = det3(u) * det3(v) < 0 ? -1.0 : 1.0;
	for (int a = 0; a < 3; a++)
		for (int b = 0; b < 3; b++)
			rot[3 * a + b] = v[3 * a + 0] * u[3 * b + 0] + v[3 * a + 1] * u[3 * b + 1] + d * v[3 * a + 2] * u[3 * b + 2];
	return 0;
}

/* Weighted centroid of x; returns the total weight (not positive: bad). */
static double centroid(size_t n, const double *x, const double *w, double c[3])
{
	double tw = 0, acc[3] = { 0, 0, 0 };

	for (size_t i = 0; i < n; i++) {
		double wi = weight(w, i);

		tw += wi;
		for (int k = 0; k < 3; k++)
			acc[k] += wi * x[3 * i + k];
	}
	for (int k = 0; k < 3; k++)
		c[k] = acc[k] / tw;
	return tw;
}

int irdm_rigid_fit_kabsch(size_t n, const double *p, const double *q, const double *w,
			  struct irdm_rigid_fit *fit)
{
	double h[9] = { 0 };

	if (!(centroid(n, p, w, fit->c_rest) > 0) || !(centroid(n, q, w, fit->c_def) > 0))
		return IRDM_ENUMERIC;
	for (size_t i = 0; i < n; i++) {
		double wi = weight(w, i), r[3], t[3];

		for (int k = 0; k < 3; k++) {
			r[k] = p[3 * i + k] - fit->c_rest[k];
			t[k] = q[3 * i + k] - fit->c_def[k];
		}
		for (int a = 0; a < 3; a++)
			for (int b = 0; b < 3; b++)
				h[3 * a + b] += wi * r[a] * t[b];
	}
	return kabsch_rotation(h, fit->rot);
}

/* y = rot^T x */
static void rot_t_apply(const double rot[9], const double x[3], double y[3])
{
	for (int a = 0; a < 3; a++)
		y[a] = rot[a] * x[0] + rot[3 + a] * x[1] + rot[6 + a] * x[2];
}

void irdm_rigid_fit_residual(const struct irdm_rigid_fit *fit, size_t n, const double *p,
			     const double *q, double *d)
{
	for (size_t i = 0; i < n; i++) {
		double t[3], y[3];

		for (int k = 0; k < 3; k++)
			t[k] = q[3 * i + k] - fit->c_def[k];
		rot_t_apply(fit->rot, t, y);
		for (int k = 0; k < 3; k++)
			d[3 * i + k] = y[k] - (p[3 * i + k] - fit->c_rest[k]);
	}
}

/* Bounding-box diagonal of p and max_i |u_i - t|. */
static void extents(size_t n, const double *p, const double *u, const double t[3],
		    double *diag, double *umax)
{
	double lo[3] = { INFINITY, INFINITY, INFINITY };
	double hi[3] = { -INFINITY, -INFINITY, -INFINITY };
	double m2 = 0;

	for (size_t i = 0; i < n; i++) {
		double a2 = 0;

		for (int k = 0; k < 3; k++) {
			double x = p[3 * i + k], du = u[3 * i + k] - t[k];

			lo[k] = fmin(lo[k], x);
			hi[k] = fmax(hi[k], x);
			a2 += du * du;
		}
		if (!(a2 <= m2)) /* also propagates NaN */
			m2 = a2;
	}
	*diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
	*umax = sqrt(m2);
}

/* q_i = p_i + eps (u_i - t): the scaled field the finite fit sees. */
static void scaled_point(const double *p, const double *u, size_t i, const double t[3],
			 double eps, double q[3])
{
	for (int k = 0; k < 3; k++)
		q[k] = p[3 * i + k] + eps * (u[3 * i + k] - t[k]);
}

int irdm_rigid_remove_kabsch(size_t n, const double *p, const double *w, const double *u,
			     double rel_eps, double *d)
{
	struct irdm_rigid_fit fit;
	double t[3], diag, umax, eps, tw = 0, acc[3] = { 0, 0, 0 }, h[9] = { 0 };

	/* The translation is linear in u: remove it exactly, before scaling. */
	if (!(centroid(n, u, w, t) > 0) || !(centroid(n, p, w, fit.c_rest) > 0))
		return IRDM_ENUMERIC;
	extents(n, p, u, t, &diag, &umax);
	if (!isfinite(umax) || !(diag > 0) || !(rel_eps > 0))
		return IRDM_ENUMERIC;
	if (umax == 0.0) {
		memset(d, 0, 3 * n * sizeof(*d));
		return 0;
	}
	eps = rel_eps * diag / umax;
	for (size_t i = 0; i < n; i++) {
		double q[3], wi = weight(w, i);

		scaled_point(p, u, i, t, eps, q);
		tw += wi;
		for (int k = 0; k < 3; k++)
			acc[k] += wi * q[k];
	}
	for (int k = 0; k < 3; k++)
		fit.c_def[k] = acc[k] / tw;
	for (size_t i = 0; i < n; i++) {
		double q[3], wi = weight(w, i);

		scaled_point(p, u, i, t, eps, q);
		for (int a = 0; a < 3; a++)
			for (int b = 0; b < 3; b++)
				h[3 * a + b] += wi * (p[3 * i + a] - fit.c_rest[a]) * (q[b] - fit.c_def[b]);
	}
	if (kabsch_rotation(h, fit.rot))
		return IRDM_ENUMERIC;
	for (size_t i = 0; i < n; i++) {
		double q[3];

		scaled_point(p, u, i, t, eps, q);
		irdm_rigid_fit_residual(&fit, 1, &p[3 * i], q, &d[3 * i]);
		for (int k = 0; k < 3; k++)
			d[3 * i + k] /= eps;
	}
	return 0;
}

/* Solve the SPD 3x3 system a x = b by Cholesky; -1 if not (numerically) SPD. */
static int spd_solve3(const double a[9], const double b[3], double x[3])
{
	double l[9] = { 0 }, y[3];
	double scale = a[0] + a[4] + a[8];

	for (int j = 0; j < 3; j++) {
		double s = a[3 * j + j];

		for (int k = 0; k < j; k++)
			s -= l[3 * j + k] * l[3 * j + k];
		if (!(s > 1e-14 * scale))
			return IRDM_ENUMERIC;
		l[3 * j + j] = sqrt(s);
		for (int i = j + 1; i < 3; i++) {
			double t = a[3 * i + j];

			for (int k = 0; k < j; k++)
				t -= l[3 * i + k] * l[3 * j + k];
			l[3 * i + j] = t / l[3 * j + j];
		}
	}
	for (int i = 0; i < 3; i++) {
		y[i] = b[i];
		for (int k = 0; k < i; k++)
			y[i] -= l[3 * i + k] * y[k];
		y[i] /= l[3 * i + i];
	}
	for (int i = 2; i >= 0; i--) {
		x[i] = y[i];
		for (int k = i + 1; k < 3; k++)
			x[i] -= l[3 * k + i] * x[k];
		x[i] /= l[3 * i + i];
	}
	return 0;
}

int irdm_rigid_project_linear(size_t n, const double *p, const double *w, const double *u,
			      double *d)
{
	double c[3], t[3], mom[3] = { 0, 0, 0 }, inertia[9] = { 0 }, theta[3];

	if (!(centroid(n, p, w, c) > 0) || !(centroid(n, u, w, t) > 0))
		return IRDM_ENUMERIC;
	for (size_t i = 0; i < n; i++) {
		double wi = weight(w, i), r[3], du[3], rxu[3], r2;

		for (int k = 0; k < 3; k++) {
			r[k] = p[3 * i + k] - c[k];
			du[k] = u[3 * i + k] - t[k];
		}
		cross3(r, du, rxu);
		r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
		for (int a = 0; a < 3; a++) {
			mom[a] += wi * rxu[a];
			for (int b = 0; b < 3; b++)
				inertia[3 * a + b] += wi * ((a == b ? r2 : 0.0) - r[a] * r[b]);
		}
	}
	if (spd_solve3(inertia, mom, theta))
		return IRDM_ENUMERIC;
	for (size_t i = 0; i < n; i++) {
		double r[3], txr[3];

		for (int k = 0; k < 3; k++)
			r[k] = p[3 * i + k] - c[k];
		cross3(theta, r, txr);
		for (int k = 0; k < 3; k++)
			d[3 * i + k] = u[3 * i + k] - t[k] - txr[k];
	}
	return 0;
}
