/* SPDX-License-Identifier: MIT */
/*
 * Rigid-body (Newton-Euler) motion of floating objects against independent
 * references: closed-form translation, a classical RK4 integration of
 * Euler's equations with 1000x smaller steps, the closed-form precession of
 * a symmetric top, conservation laws, exact momentum balance, and finite
 * differences of the one-tick compliance.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "irdm/rigid.h"

/* ---- helpers (independent of the module's own algebra) ------------------- */

static double norm3(const double v[3])
{
	return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

static void cross(const double a[3], const double b[3], double c[3])
{
	c[0] = a[1] * b[2] - a[2] * b[1];
	c[1] = a[2] * b[0] - a[0] * b[2];
	c[2] = a[0] * b[1] - a[1] * b[0];
}

static void qmul(const double a[4], const double b[4], double c[4])
{
	c[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
	c[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
	c[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
	c[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}

/* Rotation matrix of a unit quaternion (row-major). */
static void qmat(const double q[4], double r[9])
{
	double w = q[0], x = q[1], y = q[2], z = q[3];

	r[0] = 1 - 2 * (y * y + z * z);
	r[1] = 2 * (x * y - w * z);
	r[2] = 2 * (x * z + w * y);
	r[3] = 2 * (x * y + w * z);
	r[4] = 1 - 2 * (x * x + z * z);
	r[5] = 2 * (y * z - w * x);
	r[6] = 2 * (x * z - w * y);
	r[7] = 2 * (y * z + w * x);
	r[8] = 1 - 2 * (x * x + y * y);
}

/* Angle of the rotation a^-1 b, in [0, pi]. */
static double qangle(const double a[4], const double b[4])
{
	double ac[4] = { a[0], -a[1], -a[2], -a[3] }, d[4];

	qmul(ac, b, d);
	return 2 * atan2(sqrt(d[1] * d[1] + d[2] * d[2] + d[3] * d[3]), fabs(d[0]));
}

static void qaxis(double angle, double x, double y, double z, double q[4])
{
	double n = sqrt(x * x + y * y + z * z);

	q[0] = cos(angle / 2);
	q[1] = sin(angle / 2) * x / n;
	q[2] = sin(angle / 2) * y / n;
	q[3] = sin(angle / 2) * z / n;
}

/* I = R diag(d) R^T: a full (non-diagonal) inertia tensor. */
static void rotated_inertia(const double d[3], const double q[4], double in[9])
{
	double r[9];

	qmat(q, r);
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) {
			in[3 * i + j] = 0;
			for (int k = 0; k < 3; k++)
				in[3 * i + j] += r[3 * i + k] * d[k] * r[3 * j + k];
		}
}

static void diag_inertia(double a, double b, double c, double in[9])
{
	memset(in, 0, 9 * sizeof(double));
	in[0] = a;
	in[4] = b;
	in[8] = c;
}

static void init_ok(struct irdm_rigid_body *rb, const struct irdm_rigid_params *p,
		    const struct irdm_rigid_state *s)
{
	assert_int_equal(irdm_rigid_init(rb, p, s), IRDM_OK);
}

static double rel_err3(const double a[3], const double b[3])
{
	double d[3] = { a[0] - b[0], a[1] - b[1], a[2] - b[2] };

	return norm3(d) / norm3(b);
}

/* ---- 1. translation -------------------------------------------------------- */

static void test_constant_force_at_com(void **state)
{
	struct irdm_rigid_params p = { .mass_kg = 2.5 };
	struct irdm_rigid_state s0 = {
		.com_m = { 0.1, 0.2, -0.3 },
		.vel_m_s = { 0.3, -0.1, 0.05 },
	};
	const double f[3] = { 1.5, -0.7, 3.2 }, dt = 1e-3, d[3] = { 0.01, 0.02, 0.025 };
	struct irdm_rigid_body rb;
	double worst = 0;

	(void)state;
	qaxis(0.7, 1, -2, 0.5, s0.q);
	rotated_inertia(d, s0.q, p.inertia_body_kg_m2);
	init_ok(&rb, &p, &s0);
	for (int k = 1; k <= 1000; k++) {
		irdm_rigid_accumulate(&rb, f, rb.s.com_m);
		assert_int_equal(irdm_rigid_step(&rb, dt), 0);
		double t = k * dt;

		for (int i = 0; i < 3; i++) {
			double x = s0.com_m[i] + s0.vel_m_s[i] * t + f[i] * t * t / (2 * p.mass_kg);
			double v = s0.vel_m_s[i] + f[i] * t / p.mass_kg;

			worst = fmax(worst, fabs(rb.s.com_m[i] - x));
			worst = fmax(worst, fabs(rb.s.vel_m_s[i] - v));
		}
	}
	print_message("constant force at COM: worst |x - x_ref|, |v - v_ref| = %.3g after 1000 steps\n",
		      worst);
	assert_true(worst < 1e-12);
	for (int i = 0; i < 3; i++)
		assert_true(rb.s.omega_body_rad_s[i] == 0);
	assert_true(qangle(s0.q, rb.s.q) < 1e-15);
}

/* ---- 2. Dzhanibekov flip against RK4 ------------------------------------- */

struct ref_state {
	double w[3]; /* body angular velocity */
	double q[4];
};

static void ref_deriv(const double in[3], const struct ref_state *x, struct ref_state *dx)
{
	double lw[3] = { in[0] * x->w[0], in[1] * x->w[1], in[2] * x->w[2] }, g[3];
	double wq[4] = { 0, x->w[0], x->w[1], x->w[2] };

	cross(x->w, lw, g);
	for (int i = 0; i < 3; i++)
		dx->w[i] = -g[i] / in[i];
	qmul(x->q, wq, dx->q);
	for (int i = 0; i < 4; i++)
		dx->q[i] *= 0.5;
}

static void ref_axpy(const struct ref_state *x, double h, const struct ref_state *d,
		     struct ref_state *out)
{
	for (int i = 0; i < 3; i++)
		out->w[i] = x->w[i] + h * d->w[i];
	for (int i = 0; i < 4; i++)
		out->q[i] = x->q[i] + h * d->q[i];
}

/* Classical RK4 on (w, q), diagonal inertia. */
static void ref_rk4(const double in[3], struct ref_state *x, double h, long n)
{
	struct ref_state k1, k2, k3, k4, t;

	for (long s = 0; s < n; s++) {
		ref_deriv(in, x, &k1);
		ref_axpy(x, h / 2, &k1, &t);
		ref_deriv(in, &t, &k2);
		ref_axpy(x, h / 2, &k2, &t);
		ref_deriv(in, &t, &k3);
		ref_axpy(x, h, &k3, &t);
		ref_deriv(in, &t, &k4);
		for (int i = 0; i < 3; i++)
			x->w[i] += h / 6 * (k1.w[i] + 2 * k2.w[i] + 2 * k3.w[i] + k4.w[i]);
		for (int i = 0; i < 4; i++)
			x->q[i] += h / 6 * (k1.q[i] + 2 * k2.q[i] + 2 * k3.q[i] + k4.q[i]);
	}
	double n2 = sqrt(x->q[0] * x->q[0] + x->q[1] * x->q[1] + x->q[2] * x->q[2] +
			 x->q[3] * x->q[3]);

	for (int i = 0; i < 4; i++)
		x->q[i] /= n2;
}

static void test_dzhanibekov_vs_rk4(void **state)
{
	const double in[3] = { 1, 2, 3 }, dt = 1e-3;
	struct irdm_rigid_params p = { .mass_kg = 1 };
	struct irdm_rigid_state s0 = { .q = { 1, 0, 0, 0 }, .omega_body_rad_s = { 0.01, 10, 0.01 } };
	struct ref_state ref = { .w = { 0.01, 10, 0.01 }, .q = { 1, 0, 0, 0 } };
	struct irdm_rigid_body rb;
	double worst_angle = 0, worst_w = 0, e0, l0[3], l[3], de = 0, dl = 0, dlv = 0;
	int flips = 0, sign = 1;
	unsigned max_it = 0;

	(void)state;
	diag_inertia(in[0], in[1], in[2], p.inertia_body_kg_m2);
	init_ok(&rb, &p, &s0);
	e0 = irdm_rigid_kinetic_energy_j(&rb);
	irdm_rigid_angular_momentum_world(&rb, l0);

	for (int sec = 1; sec <= 10; sec++) {
		for (int k = 0; k < 1000; k++) {
			assert_int_equal(irdm_rigid_step(&rb, dt), 0);
			if (rb.last_newton_iters > max_it)
				max_it = rb.last_newton_iters;
			if ((rb.s.omega_body_rad_s[1] > 0 ? 1 : -1) != sign) {
				sign = -sign;
				flips++;
			}
		}
		ref_rk4(in, &ref, dt / 1000, 1000 * 1000);
		double a = qangle(ref.q, rb.s.q);
		double dw[3] = { rb.s.omega_body_rad_s[0] - ref.w[0],
				 rb.s.omega_body_rad_s[1] - ref.w[1],
				 rb.s.omega_body_rad_s[2] - ref.w[2] };

		worst_angle = fmax(worst_angle, a);
		worst_w = fmax(worst_w, norm3(dw) / norm3(ref.w));
	}
	print_message("Dzhanibekov (I = 1,2,3; w = 10 rad/s, dt = 1 ms, 10 s, %d flips): "
		      "orientation error <= %.3g rad, |dw|/|w| <= %.3g; Newton <= %u iterations\n",
		      flips, worst_angle, worst_w, max_it);
	assert_true(flips >= 3); /* the test is about the flips */
	assert_true(worst_angle < 1e-3);

	/* conservation over 1e5 steps (the 1e4 above included) */
	for (long k = 10000; k < 100000; k++) {
		assert_int_equal(irdm_rigid_step(&rb, dt), 0);
		if (k % 1000)
			continue;
		irdm_rigid_angular_momentum_world(&rb, l);
		de = fmax(de, fabs(irdm_rigid_kinetic_energy_j(&rb) - e0) / e0);
		dl = fmax(dl, fabs(norm3(l) - norm3(l0)) / norm3(l0));
		dlv = fmax(dlv, rel_err3(l, l0));
	}
	print_message("Dzhanibekov over 1e5 steps: |dE|/E <= %.3g, |d|L||/|L| <= %.3g, "
		      "|dL|/|L| (vector, world) <= %.3g\n",
		      de, dl, dlv);
	assert_true(de < 1e-9);
	assert_true(dl < 1e-9);
	assert_true(dlv < 1e-9);
}

/* ---- second order: torque-free symmetric top, closed form ---------------- */

/*
 * I = diag(a, a, c), w(0) = (w0, 0, w3): in the body the angular velocity
 * turns about z at lambda = (c - a)/a w3; in the world the body precesses
 * about the fixed L.  The orientation is R(t) = exp(t L/a) exp(-lambda t z)
 * (both about fixed axes: R' = R [w]x checks out since
 * w = R^T L/a - lambda z).
 */
static double top_error(double dt, double t_end)
{
	const double a = 0.02, c = 0.035, w0 = 3, w3 = 10;
	struct irdm_rigid_params p = { .mass_kg = 1 };
	struct irdm_rigid_state s0 = { .q = { 1, 0, 0, 0 }, .omega_body_rad_s = { w0, 0, w3 } };
	struct irdm_rigid_body rb;
	long n = lround(t_end / dt);
	double lam = (c - a) / a * w3, t = n * dt, q1[4], q2[4], qr[4];

	diag_inertia(a, a, c, p.inertia_body_kg_m2);
	init_ok(&rb, &p, &s0);
	for (long k = 0; k < n; k++)
		assert_int_equal(irdm_rigid_step(&rb, dt), 0);
	double lx = a * w0, lz = c * w3, ln = sqrt(lx * lx + lz * lz);

	qaxis(t * ln / a, lx, 0, lz, q1);
	qaxis(-lam * t, 0, 0, 1, q2);
	qmul(q1, q2, qr);
	return qangle(qr, rb.s.q);
}

static void test_symmetric_top_second_order(void **state)
{
	double e2 = top_error(2e-3, 5), e1 = top_error(1e-3, 5), e05 = top_error(5e-4, 5);

	(void)state;
	print_message("symmetric top, 5 s: orientation error %.3g (2 ms), %.3g (1 ms), %.3g (0.5 ms); "
		      "ratios %.3f, %.3f\n",
		      e2, e1, e05, e2 / e1, e1 / e05);
	assert_true(e1 < 1e-3);
	assert_true(e2 / e1 > 3.6 && e2 / e1 < 4.4);
	assert_true(e1 / e05 > 3.6 && e1 / e05 < 4.4);
}

/* Spin about a principal axis: the quaternion exponential makes it exact. */
static void test_principal_spin_exact(void **state)
{
	struct irdm_rigid_params p = { .mass_kg = 1 };
	struct irdm_rigid_state s0 = { .q = { 1, 0, 0, 0 }, .omega_body_rad_s = { 0, 0, 200 } };
	struct irdm_rigid_body rb;
	double qr[4];

	(void)state;
	diag_inertia(1, 2, 3, p.inertia_body_kg_m2);
	init_ok(&rb, &p, &s0);
	for (int k = 0; k < 1000; k++)
		assert_int_equal(irdm_rigid_step(&rb, 1e-3), 0);
	qaxis(200.0, 0, 0, 1, qr);
	print_message("principal spin 200 rad/s, 1 s: angle error %.3g rad\n", qangle(qr, rb.s.q));
	assert_true(qangle(qr, rb.s.q) < 1e-11);

	/* tiny rates take the Taylor branch: no loss of the small angle */
	s0.omega_body_rad_s[2] = 1e-9;
	init_ok(&rb, &p, &s0);
	for (int k = 0; k < 1000; k++)
		assert_int_equal(irdm_rigid_step(&rb, 1e-3), 0);
	assert_true(fabs(2 * atan2(rb.s.q[3], rb.s.q[0]) - 1e-9) < 1e-12 * 1e-9);
	s0.omega_body_rad_s[2] = 0;
	init_ok(&rb, &p, &s0);
	assert_int_equal(irdm_rigid_step(&rb, 1e-3), 0);
	assert_true(rb.s.q[0] == 1 && rb.s.q[1] == 0 && rb.s.q[2] == 0 && rb.s.q[3] == 0);
}

/* ---- 3. fast spin ------------------------------------------------------------ */

static void fast_spin(const char *what, const double w[3])
{
	/* a flat plate 20 x 10 x 0.4 cm, 0.5 kg, tilted in its body frame */
	const double m = 0.5, a = 0.2, b = 0.1, c = 0.004;
	const double d[3] = {
		m / 12 * (b * b + c * c), m / 12 * (a * a + c * c), m / 12 * (a * a + b * b)
	};
	struct irdm_rigid_params p = { .mass_kg = m };
	struct irdm_rigid_state s0 = { .q = { 1, 0, 0, 0 } };
	struct irdm_rigid_body rb;
	double qb[4], e0, l0[3], l[3], e_max = 0, de = 0, dl = 0, l_b[3];
	unsigned max_it = 0;

	qaxis(0.3, 1, 1, 0, qb);
	rotated_inertia(d, qb, p.inertia_body_kg_m2);
	/* w given in the principal frame: rotate it into the body frame */
	double r[9];

	qmat(qb, r);
	for (int i = 0; i < 3; i++)
		s0.omega_body_rad_s[i] = r[3 * i] * w[0] + r[3 * i + 1] * w[1] + r[3 * i + 2] * w[2];
	init_ok(&rb, &p, &s0);
	e0 = irdm_rigid_kinetic_energy_j(&rb);
	irdm_rigid_angular_momentum_world(&rb, l0);
	for (long k = 0; k < 60000; k++) {
		assert_int_equal(irdm_rigid_step(&rb, 1e-3), 0);
		if (rb.last_newton_iters > max_it)
			max_it = rb.last_newton_iters;
		double e = irdm_rigid_kinetic_energy_j(&rb);

		assert_true(isfinite(e));
		e_max = fmax(e_max, e);
		de = fmax(de, fabs(e - e0) / e0);
		if (k % 100 == 0) {
			irdm_rigid_angular_momentum_world(&rb, l);
			dl = fmax(dl, rel_err3(l, l0));
		}
	}
	irdm_rigid_rotate_inverse(&rb, l0, l_b);
	print_message("fast spin %s, 60 s at 1 ms: max |dE|/E %.3g, E_max/E0 - 1 = %.3g, "
		      "|dL|/|L| %.3g, Newton <= %u iterations\n",
		      what, de, e_max / e0 - 1, dl, max_it);
	assert_true(de < 1e-9);
	assert_true(dl < 1e-9);
	assert_true(fabs(rb.s.q[0] * rb.s.q[0] + rb.s.q[1] * rb.s.q[1] + rb.s.q[2] * rb.s.q[2] +
			 rb.s.q[3] * rb.s.q[3] - 1) < 1e-14);
	assert_true(max_it <= IRDM_RIGID_MAX_NEWTON);
}

static void test_fast_spin(void **state)
{
	const double w_major[3] = { 2, -1, 200 };    /* near the stable major axis */
	const double w_inter[3] = { 0.5, 200, 0.5 }; /* near the unstable intermediate axis */

	(void)state;
	fast_spin("near major axis", w_major);
	fast_spin("near intermediate axis", w_inter);
}

/*
 * Far beyond the design range (10 rad per step) Newton need not converge,
 * but |L| is still kept exactly, so the energy stays below |L|^2/(2 I_min).
 */
static void test_absurd_spin_bounded(void **state)
{
	const double d[3] = { 0.0004, 0.0017, 0.0021 };
	struct irdm_rigid_params p = { .mass_kg = 0.5 };
	struct irdm_rigid_state s0 = { .q = { 1, 0, 0, 0 }, .omega_body_rad_s = { 1e3, 1e4, 5e2 } };
	struct irdm_rigid_body rb;
	double l0[3], l[3], bound, e_max = 0;

	(void)state;
	diag_inertia(d[0], d[1], d[2], p.inertia_body_kg_m2);
	init_ok(&rb, &p, &s0);
	irdm_rigid_angular_momentum_world(&rb, l0);
	bound = norm3(l0) * norm3(l0) / (2 * d[0]);
	for (long k = 0; k < 60000; k++) {
		assert_int_equal(irdm_rigid_step(&rb, 1e-3), 0);
		e_max = fmax(e_max, irdm_rigid_kinetic_energy_j(&rb));
	}
	irdm_rigid_angular_momentum_world(&rb, l);
	print_message("absurd spin 1e4 rad/s at 1 ms, 60 s: E_max/E0 = %.3g (bound %.3g), |dL|/|L| %.3g\n",
		      e_max / (0.5 * (d[0] * 1e6 + d[1] * 1e8 + d[2] * 25e4)),
		      bound / (0.5 * (d[0] * 1e6 + d[1] * 1e8 + d[2] * 25e4)), rel_err3(l, l0));
	assert_true(e_max <= bound * (1 + 1e-12));
	assert_true(rel_err3(l, l0) < 1e-9);
}

/* ---- 4. momentum balance of an off-centre force ------------------------- */

static void test_off_centre_force(void **state)
{
	const double d[3] = { 0.01, 0.02, 0.025 }, dt = 1e-3;
	const double f[3] = { 0.3, -1, 0.5 }, r[3] = { 0.05, -0.02, 0.07 };
	struct irdm_rigid_params p = { .mass_kg = 0.7 };
	struct irdm_rigid_state s0 = { .com_m = { 1, 2, 3 } };
	struct irdm_rigid_body rb;
	double x[3], pm[3], l[3], l0[3], want_l[3], want_p[3], qi[4];

	(void)state;
	qaxis(1.1, 0.3, 1, -0.4, qi);
	rotated_inertia(d, qi, p.inertia_body_kg_m2);
	qaxis(-0.6, 1, 0.2, 0.3, s0.q);
	for (int i = 0; i < 3; i++) {
		x[i] = s0.com_m[i] + r[i];
		want_p[i] = f[i] * dt;
	}
	cross(r, f, want_l);
	for (int i = 0; i < 3; i++)
		want_l[i] *= dt;

	/* from rest */
	init_ok(&rb, &p, &s0);
	irdm_rigid_accumulate(&rb, f, x);
	assert_int_equal(irdm_rigid_step(&rb, dt), 0);
	irdm_rigid_linear_momentum_world(&rb, pm);
	irdm_rigid_angular_momentum_world(&rb, l);
	print_message("off-centre force from rest: |dp|/|p| %.3g, |dL|/|L| %.3g\n",
		      rel_err3(pm, want_p), rel_err3(l, want_l));
	assert_true(rel_err3(pm, want_p) < 1e-15);
	assert_true(rel_err3(l, want_l) < 1e-14);

	/* moving and spinning: the change is still exactly f dt and r x f dt */
	s0.vel_m_s[0] = 0.2;
	s0.vel_m_s[2] = -0.1;
	s0.omega_body_rad_s[0] = 3;
	s0.omega_body_rad_s[1] = -7;
	s0.omega_body_rad_s[2] = 5;
	init_ok(&rb, &p, &s0);
	irdm_rigid_angular_momentum_world(&rb, l0);
	irdm_rigid_accumulate(&rb, f, x);
	assert_int_equal(irdm_rigid_step(&rb, dt), 0);
	irdm_rigid_linear_momentum_world(&rb, pm);
	irdm_rigid_angular_momentum_world(&rb, l);
	for (int i = 0; i < 3; i++) {
		pm[i] -= p.mass_kg * s0.vel_m_s[i];
		l[i] -= l0[i];
	}
	print_message("off-centre force while spinning: |dp|/|p| %.3g, |dL|/|L| %.3g "
		      "(|L0|/|r x f dt| = %.3g)\n",
		      rel_err3(pm, want_p), rel_err3(l, want_l),
		      norm3(l0) / norm3(want_l));
	assert_true(rel_err3(pm, want_p) < 1e-12);
	assert_true(rel_err3(l, want_l) < 1e-10);

	/* several forces and a pure torque add up */
	const double f2[3] = { -0.3, 1, -0.5 }, tau[3] = { 0.01, 0.02, -0.03 };

	init_ok(&rb, &p, &s0);
	irdm_rigid_accumulate(&rb, f, x);
	irdm_rigid_accumulate(&rb, f2, s0.com_m); /* cancels the force, keeps r x f */
	irdm_rigid_accumulate_torque(&rb, tau);
	for (int i = 0; i < 3; i++)
		assert_true(fabs(rb.force_n[i]) < 1e-16);
	assert_true(fabs(rb.torque_n_m[0] - (want_l[0] / dt + tau[0])) < 1e-14 * norm3(want_l) / dt);
	assert_int_equal(irdm_rigid_step(&rb, dt), 0);
	for (int i = 0; i < 3; i++) {
		assert_true(rb.force_n[i] == 0 && rb.torque_n_m[i] == 0); /* consumed */
		assert_true(fabs(rb.s.vel_m_s[i] - s0.vel_m_s[i]) < 1e-16);
	}
}

/* ---- 5. compliance against finite differences ---------------------------- */

/* World position at t + dt of the material point at world r2 (from the COM). */
static void displaced(const struct irdm_rigid_body *rb0, const double r[3], const double f[3],
		      const double r2[3], double dt, double out[3])
{
	struct irdm_rigid_body rb = *rb0;
	double x[3], x2[3], xb[3];

	for (int i = 0; i < 3; i++) {
		x[i] = rb.s.com_m[i] + r[i];
		x2[i] = rb.s.com_m[i] + r2[i];
	}
	irdm_rigid_world_to_body(&rb, x2, xb);
	irdm_rigid_accumulate(&rb, f, x);
	assert_int_equal(irdm_rigid_step(&rb, dt), 0);
	irdm_rigid_body_to_world(&rb, xb, out);
}

/* Worst relative error of C against central (or one-sided) differences. */
static double fd_error(const struct irdm_rigid_body *rb, const double r[3], const double r2[3],
		       double dt, double eps, int central, const double c[9])
{
	double worst = 0, scale = 0, x0[3], xp[3], xm[3];
	const double zero[3] = { 0, 0, 0 };

	for (int i = 0; i < 9; i++)
		scale = fmax(scale, fabs(c[i]));
	displaced(rb, r, zero, r2, dt, x0);
	for (int j = 0; j < 3; j++) {
		double f[3] = { 0, 0, 0 };

		f[j] = eps;
		displaced(rb, r, f, r2, dt, xp);
		f[j] = -eps;
		displaced(rb, r, f, r2, dt, xm);
		for (int i = 0; i < 3; i++) {
			double d = central ? (xp[i] - xm[i]) / (2 * eps) : (xp[i] - x0[i]) / eps;

			worst = fmax(worst, fabs(d - c[3 * i + j]) / scale);
		}
	}
	return worst;
}

static void test_point_compliance(void **state)
{
	const double d[3] = { 0.004, 0.006, 0.009 }, dt = 1e-3;
	const double r[3] = { 0.05, -0.03, 0.08 }, r2[3] = { -0.02, 0.06, 0.01 };
	struct irdm_rigid_params p = { .mass_kg = 0.3 };
	struct irdm_rigid_state s0 = { .com_m = { 0.3, -0.2, 0.1 }, .vel_m_s = { 0.1, 0.2, -0.3 } };
	struct irdm_rigid_body rb;
	double c[9], c2[9], c21[9], qi[4], xb[3], xp[3], x0[3];
	const double zero[3] = { 0, 0, 0 };

	(void)state;
	qaxis(0.9, -0.2, 1, 0.6, qi);
	rotated_inertia(d, qi, p.inertia_body_kg_m2);
	qaxis(2.1, 0.5, -0.5, 1, s0.q);
	init_ok(&rb, &p, &s0);

	irdm_rigid_point_compliance(&rb, r, r, dt, c);
	double e_c = fd_error(&rb, r, r, dt, 1.0, 1, c);
	double e_1 = fd_error(&rb, r, r, dt, 1e-2, 0, c);

	irdm_rigid_point_compliance(&rb, r, r2, dt, c2);
	irdm_rigid_point_compliance(&rb, r2, r, dt, c21);
	double e_x = fd_error(&rb, r, r2, dt, 1.0, 1, c2);

	print_message("compliance vs finite differences (w = 0): central %.3g, one-sided %.3g, "
		      "cross point %.3g (relative)\n",
		      e_c, e_1, e_x);
	assert_true(e_c < 1e-6 && e_1 < 1e-6 && e_x < 1e-6);

	/* symmetric, positive definite, reciprocal */
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) {
			assert_true(c[3 * i + j] == c[3 * j + i]);
			assert_true(fabs(c2[3 * i + j] - c21[3 * j + i]) < 1e-15 * fabs(c[0]));
		}
	double m2 = c[0] * c[4] - c[1] * c[3];
	double det = c[0] * (c[4] * c[8] - c[5] * c[7]) - c[1] * (c[3] * c[8] - c[5] * c[6]) +
		     c[2] * (c[3] * c[7] - c[4] * c[6]);

	assert_true(c[0] > 0 && m2 > 0 && det > 0);

	/* at the COM only the translation remains: dt^2/(2m) */
	irdm_rigid_point_compliance(&rb, zero, zero, dt, c);
	for (int i = 0; i < 9; i++)
		assert_true(fabs(c[i] - (i % 4 == 0) * dt * dt / (2 * p.mass_kg)) < 1e-20);

	/* free motion: predict_point is exactly what the step does */
	s0.omega_body_rad_s[0] = 0.5;
	s0.omega_body_rad_s[1] = -1;
	s0.omega_body_rad_s[2] = 2;
	init_ok(&rb, &p, &s0);
	for (int i = 0; i < 3; i++)
		xp[i] = s0.com_m[i] + r2[i];
	irdm_rigid_world_to_body(&rb, xp, xb);
	irdm_rigid_predict_point(&rb, xb, dt, xp);
	displaced(&rb, r, zero, r2, dt, x0);
	for (int i = 0; i < 3; i++)
		assert_true(xp[i] == x0[i]);

	/* spinning: the gyroscopic coupling left out is O(|w| dt) */
	irdm_rigid_point_compliance(&rb, r, r, dt, c);
	double e_w = fd_error(&rb, r, r, dt, 1.0, 1, c);
	double wdt = sqrt(5.25) * dt;

	print_message("compliance while spinning at |w| = %.3g rad/s: %.3g relative (|w| dt = %.3g)\n",
		      sqrt(5.25), e_w, wdt);
	assert_true(e_w < 2 * wdt);
}

/* ---- 6. bad parameters ---------------------------------------------------- */

static void test_bad_params(void **state)
{
	struct irdm_rigid_params good = { .mass_kg = 1 }, p;
	struct irdm_rigid_state s0 = { .q = { 1, 0, 0, 0 } }, s;
	struct irdm_rigid_body rb, before;

	(void)state;
	diag_inertia(1, 2, 3, good.inertia_body_kg_m2);
	memset(&rb, 0x5a, sizeof(rb));
	before = rb;

#define REJECT(pp, ss) \
	do { \
		assert_int_equal(irdm_rigid_init(&rb, pp, ss), IRDM_EINVAL); \
		assert_memory_equal(&rb, &before, sizeof(rb)); \
	} while (0)

	p = good;
	p.mass_kg = 0;
	REJECT(&p, &s0);
	p = good;
	p.mass_kg = -1;
	REJECT(&p, &s0);
	p = good;
	p.mass_kg = NAN;
	REJECT(&p, &s0);
	p = good;
	p.mass_kg = INFINITY;
	REJECT(&p, &s0);
	p = good;
	p.inertia_body_kg_m2[4] = NAN;
	REJECT(&p, &s0);
	p = good;
	p.inertia_body_kg_m2[1] = INFINITY;
	REJECT(&p, &s0);
	p = good;
	p.inertia_body_kg_m2[1] = 0.1;
	REJECT(&p, &s0); /* not symmetric */
	p = good;
	p.inertia_body_kg_m2[4] = -2;
	REJECT(&p, &s0); /* indefinite */
	p = good;
	p.inertia_body_kg_m2[8] = 0;
	REJECT(&p, &s0); /* singular */
	p = good;        /* symmetric, indefinite */
	p.inertia_body_kg_m2[1] = p.inertia_body_kg_m2[3] = 1.5;
	REJECT(&p, &s0);
	REJECT(NULL, &s0);
	REJECT(&good, NULL);
	s = s0;
	s.q[0] = 0;
	REJECT(&good, &s); /* zero quaternion */
	s = s0;
	s.q[0] = 1e-9;
	REJECT(&good, &s);
	s = s0;
	s.q[2] = NAN;
	REJECT(&good, &s);
	s = s0;
	s.com_m[1] = INFINITY;
	REJECT(&good, &s);
	s = s0;
	s.vel_m_s[2] = NAN;
	REJECT(&good, &s);
	s = s0;
	s.omega_body_rad_s[0] = -INFINITY;
	REJECT(&good, &s);
	assert_int_equal(irdm_rigid_init(NULL, &good, &s0), IRDM_EINVAL);
#undef REJECT

	/* accepted: a tiny rounding asymmetry, and a non-unit q (normalised) */
	p = good;
	p.inertia_body_kg_m2[1] = 1e-14;
	s = s0;
	s.q[0] = 2;
	s.q[1] = 2;
	init_ok(&rb, &p, &s);
	assert_true(fabs(rb.s.q[0] - sqrt(0.5)) < 1e-15 && fabs(rb.s.q[1] - sqrt(0.5)) < 1e-15);
	assert_true(rb.inertia_body_kg_m2[1] == rb.inertia_body_kg_m2[3]);

	/* a step that cannot be taken leaves the state as it was */
	const double nan3[3] = { NAN, 0, 0 }, big[3] = { 1e308, 0, 0 }, at[3] = { 0, 0, 0 };

	before = rb;
	assert_int_equal(irdm_rigid_step(&rb, 0), IRDM_EINVAL);
	assert_int_equal(irdm_rigid_step(&rb, -1e-3), IRDM_EINVAL);
	assert_int_equal(irdm_rigid_step(&rb, NAN), IRDM_EINVAL);
	assert_int_equal(irdm_rigid_step(&rb, INFINITY), IRDM_EINVAL);
	irdm_rigid_accumulate(&rb, nan3, at);
	assert_int_equal(irdm_rigid_step(&rb, 1e-3), IRDM_EFAULT); /* non-finite force */
	assert_memory_equal(&rb, &before, sizeof(rb));
	rb.s.vel_m_s[0] = 1e308;
	before = rb;
	irdm_rigid_accumulate(&rb, big, at);
	assert_int_equal(irdm_rigid_step(&rb, 1e3), IRDM_EFAULT); /* overflows */
	assert_memory_equal(&rb, &before, sizeof(rb));
	assert_int_equal(irdm_rigid_step(&rb, 1e-3), IRDM_OK); /* forces were consumed */
}

/* ---- 7. self-contained state --------------------------------------------- */

/*
 * The body is plain data: a copy steps exactly like the original (no hidden
 * pointers, no static state), and the image's rigid section maps onto it.
 */
static void test_plain_data(void **state)
{
	struct irdm_rigid img = { .mass_kg = 0.4, .com_m = { 0.1, 0.1, 0.1 } };
	struct irdm_rigid_params p;
	struct irdm_rigid_state s0 = { .q = { 1, 0, 0, 0 }, .omega_body_rad_s = { 1, 2, 3 } };
	struct irdm_rigid_body a, b;
	const double f[3] = { 0, 0, -3.9 }, x[3] = { 0.01, 0, 0 };
	struct irdm_pose pose;

	(void)state;
	diag_inertia(0.001, 0.002, 0.0025, img.inertia_kg_m2);
	irdm_rigid_params_from_image(&img, &p);
	init_ok(&a, &p, &s0);
	for (int k = 0; k < 100; k++) {
		irdm_rigid_accumulate(&a, f, x);
		assert_int_equal(irdm_rigid_step(&a, 1e-3), 0);
	}
	memcpy(&b, &a, sizeof(a));
	for (int k = 0; k < 100; k++) {
		irdm_rigid_accumulate(&a, f, x);
		irdm_rigid_accumulate(&b, f, x);
		assert_int_equal(irdm_rigid_step(&a, 1e-3), 0);
		assert_int_equal(irdm_rigid_step(&b, 1e-3), 0);
	}
	assert_memory_equal(&a, &b, sizeof(a));
	irdm_rigid_pose(&a, &pose);
	assert_memory_equal(pose.com_m, a.s.com_m, sizeof(pose.com_m));
	assert_memory_equal(pose.q, a.s.q, sizeof(pose.q));

	/* body <-> world round trip */
	double xb[3] = { 0.03, -0.02, 0.05 }, xw[3], back[3];

	irdm_rigid_body_to_world(&a, xb, xw);
	irdm_rigid_world_to_body(&a, xw, back);
	assert_true(rel_err3(back, xb) < 1e-15);
	irdm_rigid_rotate(&a, xb, xw);
	irdm_rigid_rotate_inverse(&a, xw, back);
	assert_true(rel_err3(back, xb) < 1e-15);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_constant_force_at_com),
		cmocka_unit_test(test_dzhanibekov_vs_rk4),
		cmocka_unit_test(test_symmetric_top_second_order),
		cmocka_unit_test(test_principal_spin_exact),
		cmocka_unit_test(test_fast_spin),
		cmocka_unit_test(test_absurd_spin_bounded),
		cmocka_unit_test(test_off_centre_force),
		cmocka_unit_test(test_point_compliance),
		cmocka_unit_test(test_bad_params),
		cmocka_unit_test(test_plain_data),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
