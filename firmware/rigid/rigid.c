/* SPDX-License-Identifier: MIT */
/*
 * Newton-Euler rigid motion of a floating object, one tick at a time.
 *
 * Translation is integrated exactly for a force held constant over the tick:
 * x += v dt + f dt^2/(2m), v += f dt/m.
 *
 * Rotation is a Strang splitting in the angular momentum, which the torque
 * changes in the *world* frame (the contact force of a tick is held at a
 * world point): half a kick L += tau dt/2, a torque-free drift, half a kick
 * with the new orientation.  The drift is the implicit midpoint rule for
 * Euler's equations written with the exact rotation that also moves the
 * orientation:
 *
 *   w       = I^-1 (L + L') / 2       (body frame, midpoint angular velocity)
 *   L'      = exp(-dt [w]x) L         (body momentum, rotated back)
 *   q'      = q (x) exp(dt w / 2)     (exact quaternion exponential)
 *
 * solved for w by Newton's method (exact Jacobian, quadratic convergence,
 * typically 3-4 iterations, never more than IRDM_RIGID_MAX_NEWTON).
 *
 * Why this and not Catto's backward Euler on the gyroscopic term: for
 * torque-free motion it conserves
 *   - the world angular momentum R L exactly, whatever Newton converged to,
 *     because the body momentum is turned back by precisely the rotation
 *     that turns the body forward;
 *   - hence |L|, and so the energy L.I^-1 L/2 can never exceed
 *     |L|^2/(2 I_min): fast-spinning bodies stay bounded, unconditionally;
 *   - the kinetic energy exactly once Newton has converged: L' - L is a
 *     rotation of L about the axis w, so (L' - L).w = 0, and
 *     E' - E = (L' - L).I^-1 (L + L')/2 = (L' - L).w = 0;
 * and it is symmetric (time reversible), hence second order, and exact for
 * a spin about a principal axis.  Backward Euler is first order and loses
 * energy by numerical damping, which a user feels as a spinning object that
 * slows down by itself.  The kicks are in the world frame, so one step from
 * rest under a force f at r gives exactly L = r x f dt.
 *
 * The step works on a copy of the state and commits it only when it is
 * finite: a fault leaves the last good pose for the safe-off path.
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "irdm/rigid.h"
#include "irdm/vec3.h"

#define SYM_TOL 1e-12    /* inertia asymmetry allowed, relative to its largest entry */
#define PIVOT_TOL 1e-12  /* smallest Cholesky pivot, relative to the trace */
#define Q_MIN_NORM 1e-6  /* a quaternion shorter than this is "zero" */
#define NEWTON_TOL 1e-13 /* relative Newton step at which w has converged */

/* ---- small matrix algebra (vectors: irdm/vec3.h) ------------------------ */

static void mat_vec(const double m[9], const double v[3], double out[3])
{
	for (int i = 0; i < 3; i++)
		out[i] = irdm_v3_dot(&m[3 * i], v);
}

static void mat_mul(const double a[9], const double b[9], double c[9])
{
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
			c[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] +
				       a[3 * i + 2] * b[6 + j];
}

static void skew(const double v[3], double s[9])
{
	s[0] = 0;
	s[1] = -v[2];
	s[2] = v[1];
	s[3] = v[2];
	s[4] = 0;
	s[5] = -v[0];
	s[6] = -v[1];
	s[7] = v[0];
	s[8] = 0;
}

static int finite_n(const double *v, int n)
{
	for (int i = 0; i < n; i++)
		if (!isfinite(v[i]))
			return 0;
	return 1;
}

/*
 * Solve a x = b (3x3, general) by Gaussian elimination with partial
 * pivoting.  Returns -1 on a zero or non-finite pivot.
 */
static int solve3(const double a_in[9], const double b_in[3], double x[3])
{
	double a[9], b[3];

	for (int i = 0; i < 9; i++)
		a[i] = a_in[i];
	for (int i = 0; i < 3; i++)
		b[i] = b_in[i];
	for (int k = 0; k < 3; k++) {
		int p = k;

		for (int i = k + 1; i < 3; i++)
			if (fabs(a[3 * i + k]) > fabs(a[3 * p + k]))
				p = i;
		if (!(fabs(a[3 * p + k]) > 0) || !isfinite(a[3 * p + k]))
			return -1;
		if (p != k) {
			for (int j = 0; j < 3; j++) {
				double t = a[3 * k + j];

				a[3 * k + j] = a[3 * p + j];
				a[3 * p + j] = t;
			}
			double t = b[k];

			b[k] = b[p];
			b[p] = t;
		}
		for (int i = k + 1; i < 3; i++) {
			double l = a[3 * i + k] / a[3 * k + k];

			for (int j = k; j < 3; j++)
				a[3 * i + j] -= l * a[3 * k + j];
			b[i] -= l * b[k];
		}
	}
	for (int i = 2; i >= 0; i--) {
		double s = b[i];

		for (int j = i + 1; j < 3; j++)
			s -= a[3 * i + j] * x[j];
		x[i] = s / a[3 * i + i];
	}
	return 0;
}

/* ---- rotations ----------------------------------------------------------- */

/* sin(x)/x, with its Taylor series where the quotient would lose digits. */
static double sinc(double x)
{
	if (fabs(x) < 1e-4)
		return 1 - x * x / 6;
	return sin(x) / x;
}

/* (x - sin x)/x^3: cancels badly for small x, so a series there. */
static double x_minus_sin_over_x3(double x)
{
	double x2 = x * x;

	if (fabs(x) < 0.1)
		return 1.0 / 6 - x2 / 120 + x2 * x2 / 5040 - x2 * x2 * x2 / 362880;
	return (x - sin(x)) / (x2 * x);
}

/* out = exp([phi]x) v (Rodrigues); 1 - cos t is written 2 sin^2(t/2). */
static void rotvec_apply(const double phi[3], const double v[3], double out[3])
{
	double th = irdm_v3_norm(phi);
	double s = sinc(0.5 * th);
	double a = sinc(th), b = 0.5 * s * s;
	double pv[3], ppv[3];

	irdm_v3_cross(pv, phi, v);
	irdm_v3_cross(ppv, phi, pv);
	for (int i = 0; i < 3; i++)
		out[i] = v[i] + a * pv[i] + b * ppv[i];
}

/* Left Jacobian of SO(3): exp(phi + d) = exp(J_l(phi) d) exp(phi) + O(d^2). */
static void left_jacobian(const double phi[3], double j[9])
{
	double th = irdm_v3_norm(phi);
	double s = sinc(0.5 * th);
	double b = 0.5 * s * s, c = x_minus_sin_over_x3(th);
	double k[9], k2[9];

	skew(phi, k);
	mat_mul(k, k, k2);
	for (int i = 0; i < 9; i++)
		j[i] = b * k[i] + c * k2[i];
	j[0] += 1;
	j[4] += 1;
	j[8] += 1;
}

/* The unit quaternion exp(phi/2) of the rotation vector phi. */
static void quat_exp(const double phi[3], double q[4])
{
	double h = 0.5 * irdm_v3_norm(phi);
	double s = 0.5 * sinc(h); /* sin(h) / |phi| */

	q[0] = cos(h);
	q[1] = s * phi[0];
	q[2] = s * phi[1];
	q[3] = s * phi[2];
}

static void quat_mul(const double a[4], const double b[4], double c[4])
{
	double w = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
	double x = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
	double y = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
	double z = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];

	c[0] = w;
	c[1] = x;
	c[2] = y;
	c[3] = z;
}

static void quat_normalise(double q[4])
{
	double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);

	for (int i = 0; i < 4; i++)
		q[i] /= n;
}

/* out = R(q) v, or R(q)^T v when inverse; out may alias v. */
static void quat_rotate(const double q[4], int inverse, const double v[3], double out[3])
{
	double w = q[0];
	double u[3] = { q[1], q[2], q[3] };
	double t[3], ut[3];

	if (inverse)
		w = -w; /* conj(q) and -conj(q) are the same rotation */
	irdm_v3_cross(t, u, v);
	irdm_v3_scale(t, 2, t);
	irdm_v3_cross(ut, u, t);
	for (int i = 0; i < 3; i++)
		out[i] = v[i] + w * t[i] + ut[i];
}

/* ---- set-up -------------------------------------------------------------- */

void irdm_rigid_params_from_image(const struct irdm_rigid *img, struct irdm_rigid_params *p)
{
	p->mass_kg = img->mass_kg;
	for (int i = 0; i < 9; i++)
		p->inertia_body_kg_m2[i] = img->inertia_kg_m2[i];
}

/*
 * Symmetrise a (checking that it was symmetric) and invert it through
 * L D L^T, whose pivots prove it positive definite.
 */
static int inertia_inverse(const double a_in[9], double a[9], double inv[9])
{
	double scale = 0, d[3], l[9] = { 0 };

	for (int i = 0; i < 9; i++) {
		if (!isfinite(a_in[i]))
			return -1;
		scale = fmax(scale, fabs(a_in[i]));
	}
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) {
			if (fabs(a_in[3 * i + j] - a_in[3 * j + i]) > SYM_TOL * scale)
				return -1;
			a[3 * i + j] = 0.5 * (a_in[3 * i + j] + a_in[3 * j + i]);
		}
	double min_pivot = PIVOT_TOL * (a[0] + a[4] + a[8]);

	for (int j = 0; j < 3; j++) {
		d[j] = a[3 * j + j];
		for (int k = 0; k < j; k++)
			d[j] -= l[3 * j + k] * l[3 * j + k] * d[k];
		if (!(d[j] > min_pivot))
			return -1;
		l[3 * j + j] = 1;
		for (int i = j + 1; i < 3; i++) {
			double s = a[3 * i + j];

			for (int k = 0; k < j; k++)
				s -= l[3 * i + k] * l[3 * j + k] * d[k];
			l[3 * i + j] = s / d[j];
		}
	}
	for (int c = 0; c < 3; c++) {
		double y[3];

		for (int i = 0; i < 3; i++) { /* L y = e_c, then D, then L^T */
			y[i] = i == c;
			for (int k = 0; k < i; k++)
				y[i] -= l[3 * i + k] * y[k];
		}
		for (int i = 0; i < 3; i++)
			y[i] /= d[i];
		for (int i = 2; i >= 0; i--)
			for (int k = i + 1; k < 3; k++)
				y[i] -= l[3 * k + i] * y[k];
		for (int i = 0; i < 3; i++)
			inv[3 * i + c] = y[i];
	}
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < i; j++)
			inv[3 * i + j] = inv[3 * j + i] = 0.5 * (inv[3 * i + j] + inv[3 * j + i]);
	return 0;
}

int irdm_rigid_init(struct irdm_rigid_body *rb, const struct irdm_rigid_params *p,
		    const struct irdm_rigid_state *s0)
{
	struct irdm_rigid_body b = { 0 };

	if (!rb || !p || !s0)
		return IRDM_EINVAL;
	if (!isfinite(p->mass_kg) || !(p->mass_kg > 0))
		return IRDM_EINVAL;
	if (inertia_inverse(p->inertia_body_kg_m2, b.inertia_body_kg_m2,
			    b.inv_inertia_body_per_kg_m2))
		return IRDM_EINVAL;
	b.s = *s0;
	if (!irdm_v3_finite(b.s.com_m) || !irdm_v3_finite(b.s.vel_m_s) || !finite_n(b.s.q, 4) ||
	    !irdm_v3_finite(b.s.omega_body_rad_s))
		return IRDM_EINVAL;
	if (!(sqrt(irdm_v3_dot(b.s.q + 1, b.s.q + 1) + b.s.q[0] * b.s.q[0]) >= Q_MIN_NORM))
		return IRDM_EINVAL;
	quat_normalise(b.s.q);
	b.mass_kg = p->mass_kg;
	*rb = b;
	return IRDM_OK;
}

/* ---- forces -------------------------------------------------------------- */

void irdm_rigid_clear(struct irdm_rigid_body *rb)
{
	irdm_v3_zero(rb->force_n);
	irdm_v3_zero(rb->torque_n_m);
}

void irdm_rigid_accumulate(struct irdm_rigid_body *rb, const double f_world_n[3],
			   const double x_world_m[3])
{
	double r[3], tau[3];

	irdm_v3_sub(r, x_world_m, rb->s.com_m);
	irdm_v3_cross(tau, r, f_world_n);
	irdm_v3_add(rb->force_n, rb->force_n, f_world_n);
	irdm_v3_add(rb->torque_n_m, rb->torque_n_m, tau);
}

void irdm_rigid_accumulate_torque(struct irdm_rigid_body *rb, const double tau_world_n_m[3])
{
	irdm_v3_add(rb->torque_n_m, rb->torque_n_m, tau_world_n_m);
}

/* ---- the step ------------------------------------------------------------ */

/*
 * Torque-free drift of the body momentum l (body frame) over dt: solves for
 * the midpoint angular velocity w, then turns l back and q forward by
 * dt w.  Returns the Newton iterations used.
 */
static unsigned drift(const struct irdm_rigid_body *rb, double q[4], double l[3], double dt)
{
	const double *in = rb->inertia_body_kg_m2;
	double w[3], phi[3], lp[3], g[3], jl[9], sk[9], jac[9], d[3], qi[4];
	unsigned it = 0;

	mat_vec(rb->inv_inertia_body_per_kg_m2, l, w); /* explicit guess, O(dt) off */
	while (it < IRDM_RIGID_MAX_NEWTON) {
		it++;
		irdm_v3_scale(phi, -dt, w);
		rotvec_apply(phi, l, lp);
		mat_vec(in, w, g);
		for (int i = 0; i < 3; i++)
			g[i] -= 0.5 * (l[i] + lp[i]);
		/* d lp / d w = dt [lp]x J_l(phi) */
		left_jacobian(phi, jl);
		skew(lp, sk);
		mat_mul(sk, jl, jac);
		for (int i = 0; i < 9; i++)
			jac[i] = in[i] - 0.5 * dt * jac[i];
		if (solve3(jac, g, d))
			break;
		irdm_v3_sub(w, w, d);
		if (!(irdm_v3_dot(d, d) > NEWTON_TOL * NEWTON_TOL * irdm_v3_dot(w, w)))
			break;
	}
	irdm_v3_scale(phi, dt, w);
	quat_exp(phi, qi);
	quat_mul(q, qi, q);
	quat_normalise(q);
	for (int i = 0; i < 3; i++)
		phi[i] = -phi[i];
	rotvec_apply(phi, l, l);
	return it;
}

static void kick(const double q[4], const double tau_world[3], double h, double l[3])
{
	double tb[3];

	quat_rotate(q, 1, tau_world, tb);
	irdm_v3_axpy(l, h, tb);
}

int irdm_rigid_step(struct irdm_rigid_body *rb, double dt_s)
{
	struct irdm_rigid_state s = rb->s;
	double f[3], tau[3], l[3];
	unsigned it;

	memcpy(f, rb->force_n, sizeof(f));
	memcpy(tau, rb->torque_n_m, sizeof(tau));
	irdm_rigid_clear(rb);
	if (!isfinite(dt_s) || !(dt_s > 0))
		return IRDM_EINVAL;
	if (!irdm_v3_finite(f) || !irdm_v3_finite(tau))
		return IRDM_EFAULT;

	for (int i = 0; i < 3; i++) {
		double a = f[i] / rb->mass_kg;

		s.com_m[i] += s.vel_m_s[i] * dt_s + 0.5 * a * dt_s * dt_s;
		s.vel_m_s[i] += a * dt_s;
	}

	mat_vec(rb->inertia_body_kg_m2, s.omega_body_rad_s, l);
	kick(s.q, tau, 0.5 * dt_s, l);
	it = drift(rb, s.q, l, dt_s);
	kick(s.q, tau, 0.5 * dt_s, l);
	mat_vec(rb->inv_inertia_body_per_kg_m2, l, s.omega_body_rad_s);

	if (!irdm_v3_finite(s.com_m) || !irdm_v3_finite(s.vel_m_s) || !finite_n(s.q, 4) ||
	    !irdm_v3_finite(s.omega_body_rad_s))
		return IRDM_EFAULT;
	rb->s = s;
	rb->last_newton_iters = it;
	return IRDM_OK;
}

/* ---- queries ------------------------------------------------------------- */

void irdm_rigid_get_state(const struct irdm_rigid_body *rb, struct irdm_rigid_state *s)
{
	*s = rb->s;
}

void irdm_rigid_pose(const struct irdm_rigid_body *rb, struct irdm_pose *pose)
{
	for (int i = 0; i < 3; i++)
		pose->com_m[i] = rb->s.com_m[i];
	for (int i = 0; i < 4; i++)
		pose->q[i] = rb->s.q[i];
}

void irdm_rigid_body_to_world(const struct irdm_rigid_body *rb, const double x_body_m[3],
			      double x_world_m[3])
{
	quat_rotate(rb->s.q, 0, x_body_m, x_world_m);
	irdm_v3_add(x_world_m, x_world_m, rb->s.com_m);
}

void irdm_rigid_world_to_body(const struct irdm_rigid_body *rb, const double x_world_m[3],
			      double x_body_m[3])
{
	double r[3];

	irdm_v3_sub(r, x_world_m, rb->s.com_m);
	quat_rotate(rb->s.q, 1, r, x_body_m);
}

void irdm_rigid_rotate(const struct irdm_rigid_body *rb, const double v_body[3],
		       double v_world[3])
{
	quat_rotate(rb->s.q, 0, v_body, v_world);
}

void irdm_rigid_rotate_inverse(const struct irdm_rigid_body *rb, const double v_world[3],
			       double v_body[3])
{
	quat_rotate(rb->s.q, 1, v_world, v_body);
}

void irdm_rigid_point_compliance(const struct irdm_rigid_body *rb, const double r_world_m[3],
				 const double r2_world_m[3], double dt_s, double c_m_per_n[9])
{
	double h = 0.5 * dt_s * dt_s;
	int same = 1;

	for (int j = 0; j < 3; j++) {
		double e[3] = { 0, 0, 0 }, t[3], tb[3], wb[3], w[3], d[3];

		e[j] = 1;
		irdm_v3_cross(t, r_world_m, e); /* torque of a unit force along e_j */
		quat_rotate(rb->s.q, 1, t, tb);
		mat_vec(rb->inv_inertia_body_per_kg_m2, tb, wb);
		quat_rotate(rb->s.q, 0, wb, w); /* I_world^-1 (r x e_j) */
		irdm_v3_cross(d, r2_world_m, w);
		for (int i = 0; i < 3; i++)
			c_m_per_n[3 * i + j] = (i == j) * h / rb->mass_kg - h * d[i];
		same &= r_world_m[j] == r2_world_m[j];
	}
	if (!same)
		return;
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < i; j++)
			c_m_per_n[3 * i + j] = c_m_per_n[3 * j + i] =
				0.5 * (c_m_per_n[3 * i + j] + c_m_per_n[3 * j + i]);
}

void irdm_rigid_predict_point(const struct irdm_rigid_body *rb, const double x_body_m[3],
			      double dt_s, double x_world_m[3])
{
	double q[4], l[3];

	for (int i = 0; i < 4; i++)
		q[i] = rb->s.q[i];
	mat_vec(rb->inertia_body_kg_m2, rb->s.omega_body_rad_s, l);
	drift(rb, q, l, dt_s);
	quat_rotate(q, 0, x_body_m, x_world_m);
	for (int i = 0; i < 3; i++)
		x_world_m[i] += rb->s.com_m[i] + rb->s.vel_m_s[i] * dt_s;
}

double irdm_rigid_kinetic_energy_j(const struct irdm_rigid_body *rb)
{
	double l[3];

	mat_vec(rb->inertia_body_kg_m2, rb->s.omega_body_rad_s, l);
	return 0.5 * rb->mass_kg * irdm_v3_dot(rb->s.vel_m_s, rb->s.vel_m_s) +
	       0.5 * irdm_v3_dot(rb->s.omega_body_rad_s, l);
}

void irdm_rigid_linear_momentum_world(const struct irdm_rigid_body *rb, double p_kg_m_s[3])
{
	irdm_v3_scale(p_kg_m_s, rb->mass_kg, rb->s.vel_m_s);
}

void irdm_rigid_angular_momentum_world(const struct irdm_rigid_body *rb, double l_kg_m2_s[3])
{
	double l[3];

	mat_vec(rb->inertia_body_kg_m2, rb->s.omega_body_rad_s, l);
	quat_rotate(rb->s.q, 0, l, l_kg_m2_s);
}
