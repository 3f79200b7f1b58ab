/* SPDX-License-Identifier: MIT */
/*
 * The arm's model (irdm/device.h) against independent references: poses
 * computed by hand, central finite differences of the forward kinematics
 * and of the potential energy (the test's own, written from the bodies'
 * positions), the virtual-work identity, a bisection for the saturation
 * scale, and brute force over the joint ranges for the workspace.
 * Tolerances sit a small factor above the error measured here (printed).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "irdm/device.h"
#include "irdm/engine.h"
#include "irdm/error.h"
#include "support/solve3.h"

#define PI 3.14159265358979323846

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;

/* xorshift64*: uniform in [lo, hi) */
static double uniform(double lo, double hi)
{
	rng_state ^= rng_state >> 12;
	rng_state ^= rng_state << 25;
	rng_state ^= rng_state >> 27;
	return lo + (hi - lo) * (double)((rng_state * 2685821657736338717ull) >> 11) * 0x1p-53;
}

static void random_pose(double q[3])
{
	/* wider than the joint ranges: the maths must hold everywhere */
	for (int i = 0; i < 3; i++)
		q[i] = uniform(-1.5, 1.5);
}

/* An arm with unequal links and an offset, so a swapped l1/l2 or a dropped
 * offset shows. */
static void odd_arm(struct irdm_device_config *c)
{
	irdm_device_config_default(c);
	c->l1_m = 0.1;
	c->l2_m = 0.2;
	c->base_offset_m[0] = 0.01;
	c->base_offset_m[1] = 0.02;
	c->base_offset_m[2] = 0.03;
}

static void assert_vec_near(const double a[3], const double b[3], double tol)
{
	for (int i = 0; i < 3; i++)
		assert_true(fabs(a[i] - b[i]) <= tol);
}

/* ---- forward kinematics --------------------------------------------------- */

static void test_fk_hand_poses(void **state)
{
	struct irdm_device_config c;
	const double s3 = sqrt(3.0), tol = 1e-15;
	double tip[3];
	(void)state;

	/* default: home pose (upper arm level, forearm down) is the origin */
	irdm_device_config_default(&c);
	irdm_device_fk(&c, (double[3]){ 0, 0, 0 }, tip);
	assert_vec_near(tip, (double[3]){ 0, 0, 0 }, tol);

	odd_arm(&c);
	/* home: elbow 0.1 m in front of the shoulder, tip 0.2 m below it */
	irdm_device_fk(&c, (double[3]){ 0, 0, 0 }, tip);
	assert_vec_near(tip, (double[3]){ 0.01, 0.02 - 0.2, 0.03 + 0.1 }, tol);
	/* upper arm straight up, forearm straight out: tip 0.2 ahead, 0.1 up */
	irdm_device_fk(&c, (double[3]){ 0, PI / 2, PI / 2 }, tip);
	assert_vec_near(tip, (double[3]){ 0.01, 0.02 + 0.1, 0.03 + 0.2 }, 1e-15);
	/* turned a quarter to +x, arm stretched level: reach 0.3 along +x */
	irdm_device_fk(&c, (double[3]){ PI / 2, 0, PI / 2 }, tip);
	assert_vec_near(tip, (double[3]){ 0.01 + 0.3, 0.02, 0.03 }, 1e-15);
	/* yaw 30 deg, upper arm 30 deg up, forearm 60 deg from vertical:
	 * r = 0.1 cos30 + 0.2 sin60 = 0.15 s3, h = 0.1 sin30 - 0.2 cos60 = -0.05 */
	irdm_device_fk(&c, (double[3]){ PI / 6, PI / 6, PI / 3 }, tip);
	assert_vec_near(tip, (double[3]){ 0.01 + 0.15 * s3 * 0.5, 0.02 - 0.05, 0.03 + 0.15 * s3 * s3 / 2 }, 1e-15);
}

/* ---- Jacobian and J^T ------------------------------------------------------ */

static void fd_jacobian(const struct irdm_device_config *c, const double q[3], double h,
			double j[9])
{
	for (int col = 0; col < 3; col++) {
		double qp[3] = { q[0], q[1], q[2] }, qm[3] = { q[0], q[1], q[2] };
		double pp[3], pm[3];

		qp[col] += h;
		qm[col] -= h;
		irdm_device_fk(c, qp, pp);
		irdm_device_fk(c, qm, pm);
		for (int row = 0; row < 3; row++)
			j[3 * row + col] = (pp[row] - pm[row]) / (2 * h);
	}
}

static void test_jacobian_fd(void **state)
{
	struct irdm_device_config c;
	double worst = 0;
	(void)state;

	odd_arm(&c);
	for (int k = 0; k < 64; k++) {
		double q[3], j[9], jfd[9];

		random_pose(q);
		irdm_device_jacobian(&c, q, j);
		fd_jacobian(&c, q, 1e-5, jfd);
		for (int i = 0; i < 9; i++)
			worst = fmax(worst, fabs(j[i] - jfd[i]));
	}
	/* central differences at h = 1e-5: truncation l h^2 / 6 ~ 5e-12 m/rad,
	 * round-off 1e-16 * 0.3 m / 1e-5 ~ 3e-12; measured below */
	printf("jacobian vs central FD (64 poses, h 1e-5): max |error| %.3g m/rad\n", worst);
	assert_true(worst < 3e-11); /* 6.5e-12 measured: 5x */
}

static void test_transpose_virtual_work(void **state)
{
	struct irdm_device_config c;
	double worst = 0;
	(void)state;

	odd_arm(&c);
	for (int k = 0; k < 64; k++) {
		double q[3], f[3], dq[3], tau[3], qp[3], qm[3], pp[3], pm[3];
		double w_joint = 0, w_tip = 0, scale = 0;

		random_pose(q);
		for (int i = 0; i < 3; i++) {
			f[i] = uniform(-8, 8);
			dq[i] = uniform(-1e-4, 1e-4);
			qp[i] = q[i] + dq[i];
			qm[i] = q[i] - dq[i];
		}
		irdm_device_force_to_torque(&c, q, f, tau);
		irdm_device_fk(&c, qp, pp);
		irdm_device_fk(&c, qm, pm);
		for (int i = 0; i < 3; i++) {
			w_joint += tau[i] * dq[i];
			w_tip += f[i] * (pp[i] - pm[i]) / 2; /* F . dx, centred */
			scale += fabs(tau[i] * dq[i]);
		}
		worst = fmax(worst, fabs(w_joint - w_tip) / scale);
	}
	/* the centred dx is exact to O(dq^3): relative ~ 1e-9 at dq 1e-4 */
	printf("virtual work tau.dq vs F.dx (64 poses): max relative error %.3g\n", worst);
	assert_true(worst < 1e-8); /* 4.5e-9 measured: 2x */
}

/* ---- saturation ------------------------------------------------------------ */

/* Largest s in [0, 1] with every |s tau_i| <= limit_i, by bisection. */
static double bisect_scale(const double lim[3], const double tau[3])
{
	double lo = 0, hi = 1;

	for (int it = 0; it < 200; it++) {
		double mid = 0.5 * (lo + hi);
		int ok = 1;

		for (int i = 0; i < 3; i++)
			ok &= fabs(mid * tau[i]) <= lim[i];
		if (ok)
			lo = mid;
		else
			hi = mid;
	}
	return lo;
}

/* Solve J^T f = tau by Cramer's rule (the test's own solve). */
static void tip_force_of(const struct irdm_device_config *c, const double q[3],
			 const double tau[3], double f[3])
{
	double j[9], jt[9];

	irdm_device_jacobian(c, q, j);
	for (int r = 0; r < 3; r++)
		for (int k = 0; k < 3; k++)
			jt[3 * r + k] = j[3 * k + r];
	ts_solve3(jt, tau, f);
}

static double angle_between(const double a[3], const double b[3])
{
	double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
	double x[3] = { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
			a[0] * b[1] - a[1] * b[0] };

	return atan2(sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), dot);
}

static void test_saturation_keeps_direction(void **state)
{
	struct irdm_device_config c;
	const double *lim;
	double worst_angle = 0;
	int saturated = 0;
	(void)state;

	irdm_device_config_default(&c);
	lim = c.torque_limit_nm;
	for (int k = 0; k < 200; k++) {
		double q[3] = { uniform(-0.4, 0.4), uniform(-0.4, 0.4), uniform(-0.3, 0.4) };
		double f[3], tau[3], out[3], fo[3], s;

		for (int i = 0; i < 3; i++)
			f[i] = uniform(-12, 12); /* up to 1.5x the device's force */
		irdm_device_force_to_torque(&c, q, f, tau);
		assert_int_equal(irdm_device_torque_saturate(&c, tau, out, &s), IRDM_OK);
		assert_true(fabs(s - bisect_scale(lim, tau)) <= 1e-12);
		for (int i = 0; i < 3; i++) {
			assert_true(fabs(out[i]) <= lim[i] * (1 + 1e-15));
			assert_true(fabs(out[i] - s * tau[i]) <= 1e-15);
		}
		if (s < 1)
			saturated++;
		/* the force the saturated torques put on the tip points the same way */
		tip_force_of(&c, q, out, fo);
		worst_angle = fmax(worst_angle, angle_between(f, fo));
	}
	printf("saturation: %d of 200 saturated, worst force turn %.3g rad\n", saturated,
	       worst_angle);
	assert_true(saturated > 20 && saturated < 180); /* both cases */
	assert_true(worst_angle < 1e-14);               /* 3e-16 measured: round-off of the test's solve */
}

static void test_saturation_edges(void **state)
{
	struct irdm_device_config c;
	double out[3] = { 1, 1, 1 }, s = -1;
	const double inside[3] = { 1.0, -0.5, 0.2 };
	(void)state;

	irdm_device_config_default(&c);
	/* within the limits: untouched */
	assert_int_equal(irdm_device_torque_saturate(&c, inside, out, &s), IRDM_OK);
	assert_true(s == 1.0);
	assert_memory_equal(out, inside, sizeof(out));
	/* one joint at twice its limit: everything halves (clipping would not) */
	assert_int_equal(irdm_device_torque_saturate(&c, (double[3]){ 0.5, 2 * 1.07, -0.2 }, out,
						     &s),
			 IRDM_OK);
	assert_true(fabs(s - 0.5) < 1e-15);
	assert_true(fabs(out[0] - 0.25) < 1e-15 && fabs(out[2] + 0.1) < 1e-15);
	/* non-finite: zero torque and EFAULT */
	assert_int_equal(irdm_device_torque_saturate(&c, (double[3]){ 0.1, NAN, 0 }, out, &s),
			 IRDM_EFAULT);
	assert_true(out[0] == 0 && out[1] == 0 && out[2] == 0 && s == 0);
	assert_int_equal(irdm_device_torque_saturate(&c, (double[3]){ INFINITY, 0, 0 }, out, NULL),
			 IRDM_EFAULT);
}

/* ---- gravity --------------------------------------------------------------- */

/* Potential energy from the bodies' heights, written out independently of
 * the module's closed form (the bodies as irdm/device.h describes them). */
static double potential(const struct irdm_device_config *c, const double q[3])
{
	double elbow_y = c->l1_m * sin(q[1]);
	double y0 = c->com_m[0] * sin(q[1]);           /* along the upper arm */
	double y1 = elbow_y - c->com_m[1] * cos(q[2]); /* along the forearm */
	double y2 = -c->com_m[2] * cos(q[2]);          /* with theta3, from the shoulder */

	return c->gravity_m_per_s2 * (c->mass_kg[0] * y0 + c->mass_kg[1] * y1 + c->mass_kg[2] * y2);
}

static void test_gravity_fd(void **state)
{
	struct irdm_device_config c;
	const double h = 1e-5;
	double worst = 0, biggest = 0;
	(void)state;

	odd_arm(&c);
	for (int k = 0; k < 64; k++) {
		double q[3], tau[3];

		random_pose(q);
		irdm_device_gravity_torque(&c, q, tau);
		for (int i = 0; i < 3; i++) {
			double qp[3] = { q[0], q[1], q[2] }, qm[3] = { q[0], q[1], q[2] };

			qp[i] += h;
			qm[i] -= h;
			worst = fmax(worst, fabs(tau[i] - (potential(&c, qp) - potential(&c, qm)) / (2 * h)));
			biggest = fmax(biggest, fabs(tau[i]));
		}
	}
	printf("gravity torque vs dU/dq (64 poses): max |error| %.3g N m (torques up to %.3g)\n",
	       worst, biggest);
	assert_true(biggest > 0.05);
	assert_true(worst < 1e-11); /* 1.9e-12 measured: 5x */
}

/* ---- encoders -------------------------------------------------------------- */

static void test_encoder_values(void **state)
{
	struct irdm_device_config c;
	double q[3];
	const double res = 2 * PI / (4000 * 11.6);
	(void)state;

	irdm_device_config_default(&c);
	c.angle_offset_rad[1] = 0.25;
	/* by hand: angle = offset + sign (count + 1/2) 2 pi / (4000 * 11.6) */
	assert_int_equal(irdm_device_angles_from_counts(&c, (int32_t[3]){ 100, -7, 2000 }, q),
			 IRDM_OK);
	assert_true(fabs(q[0] - 100.5 * res) < 1e-15);
	assert_true(fabs(q[1] - (0.25 - 6.5 * res)) < 1e-15);
	assert_true(fabs(q[2] + 2000.5 * res) < 1e-15);
	assert_true(fabs(irdm_device_rad_per_count(&c, 2) - res) < 1e-18);
}

static void test_encoder_round_trips(void **state)
{
	struct irdm_device_config c;
	double worst = 0;
	(void)state;

	irdm_device_config_default(&c);
	c.angle_offset_rad[0] = -0.1;
	for (int k = 0; k < 10000; k++) {
		int32_t n[3], back[3];
		double q[3], q2[3];

		for (int i = 0; i < 3; i++)
			n[i] = c.count_min[i] + (int32_t)uniform(0, c.count_max[i] - c.count_min[i] + 1);
		/* counts -> angles -> counts: exact */
		assert_int_equal(irdm_device_angles_from_counts(&c, n, q), IRDM_OK);
		assert_int_equal(irdm_device_counts_from_angles(&c, q, back), IRDM_OK);
		assert_memory_equal(n, back, sizeof(n));
		/* angle -> counts -> angle: within half a count */
		for (int i = 0; i < 3; i++)
			q[i] += uniform(-0.49, 0.49) * irdm_device_rad_per_count(&c, i);
		assert_int_equal(irdm_device_counts_from_angles(&c, q, back), IRDM_OK);
		assert_int_equal(irdm_device_angles_from_counts(&c, back, q2), IRDM_OK);
		for (int i = 0; i < 3; i++)
			worst = fmax(worst, fabs(q2[i] - q[i]) / irdm_device_rad_per_count(&c, i));
	}
	printf("encoder angle -> counts -> angle: max error %.4f count\n", worst);
	assert_true(worst <= 0.5 + 1e-9);
}

static void test_encoder_rejects(void **state)
{
	struct irdm_device_config c;
	double q[3] = { 7, 7, 7 };
	int32_t n[3] = { 7, 7, 7 };
	(void)state;

	irdm_device_config_default(&c);
	for (int i = 0; i < 3; i++) {
		int32_t bad[3] = { 0, 0, 0 };
		double qb[3] = { 0, 0, 0 };

		bad[i] = c.count_max[i] + 1;
		assert_int_equal(irdm_device_angles_from_counts(&c, bad, q), IRDM_EFAULT);
		bad[i] = c.count_min[i] - 1;
		assert_int_equal(irdm_device_angles_from_counts(&c, bad, q), IRDM_EFAULT);
		bad[i] = INT32_MIN;
		assert_int_equal(irdm_device_angles_from_counts(&c, bad, q), IRDM_EFAULT);
		bad[i] = c.count_max[i];
		assert_int_equal(irdm_device_angles_from_counts(&c, bad, q), IRDM_OK);

		qb[i] = NAN;
		assert_int_equal(irdm_device_counts_from_angles(&c, qb, n), IRDM_EFAULT);
		qb[i] = -INFINITY;
		assert_int_equal(irdm_device_counts_from_angles(&c, qb, n), IRDM_EFAULT);
		qb[i] = 1e300; /* past any int32 count */
		assert_int_equal(irdm_device_counts_from_angles(&c, qb, n), IRDM_EFAULT);
		qb[i] = 1.0; /* past the joint's range */
		assert_int_equal(irdm_device_counts_from_angles(&c, qb, n), IRDM_EFAULT);
	}
	/* a failed call leaves its output alone */
	n[0] = 7;
	assert_int_equal(irdm_device_counts_from_angles(&c, (double[3]){ 0, 0, NAN }, n),
			 IRDM_EFAULT);
	assert_int_equal(n[0], 7);
	/* a configuration that makes a non-finite angle */
	c.angle_offset_rad[1] = INFINITY;
	memcpy(q, (double[3]){ 7, 7, 7 }, sizeof(q));
	assert_int_equal(irdm_device_angles_from_counts(&c, (int32_t[3]){ 0, 0, 0 }, q),
			 IRDM_EFAULT);
	assert_true(q[0] == 7);
}

/* ---- defaults ------------------------------------------------------------- */

/*
 * The default count range is written as numbers (irdm/device.h); it is the
 * counts whose cells hold the joint ranges -0.42..0.42, -0.40..0.40 and
 * -0.35..0.45 rad, derived here as the encoder formula floors an angle.
 */
static void test_default_count_range(void **state)
{
	static const double lo_rad[3] = { -0.42, -0.40, -0.35 };
	static const double hi_rad[3] = { 0.42, 0.40, 0.45 };
	struct irdm_device_config c;
	(void)state;

	irdm_device_config_default(&c);
	for (int i = 0; i < 3; i++) {
		double per = 2 * M_PI / (c.counts_per_rev[i] * c.gear_ratio[i]);
		double a = floor(c.sign[i] * (lo_rad[i] - c.angle_offset_rad[i]) / per);
		double b = floor(c.sign[i] * (hi_rad[i] - c.angle_offset_rad[i]) / per);

		assert_int_equal(c.count_min[i], (int32_t)fmin(a, b));
		assert_int_equal(c.count_max[i], (int32_t)fmax(a, b));
	}
}

static void test_defaults_desktop_like(void **state)
{
	struct irdm_device_config c;
	struct irdm_engine_config ec;
	double lo[3] = { 1, 1, 1 }, hi[3] = { -1, -1, -1 }, q[3], tip[3];
	const int n = 24;
	(void)state;

	irdm_device_config_default(&c);
	assert_int_equal(irdm_device_config_check(&c), IRDM_OK);
	/* workspace: brute force over the encoders' ranges */
	for (int a = 0; a <= n; a++)
		for (int b = 0; b <= n; b++)
			for (int d = 0; d <= n; d++) {
				int32_t cnt[3];
				const int k[3] = { a, b, d };

				for (int i = 0; i < 3; i++)
					cnt[i] = c.count_min[i] +
						 (int32_t)((int64_t)(c.count_max[i] - c.count_min[i]) * k[i] / n);
				assert_int_equal(irdm_device_angles_from_counts(&c, cnt, q), IRDM_OK);
				irdm_device_fk(&c, q, tip);
				for (int i = 0; i < 3; i++) {
					lo[i] = fmin(lo[i], tip[i]);
					hi[i] = fmax(hi[i], tip[i]);
				}
			}
	printf("default workspace %.1f x %.1f x %.1f cm (x, y, z)\n", 100 * (hi[0] - lo[0]),
	       100 * (hi[1] - lo[1]), 100 * (hi[2] - lo[2]));
	assert_true(fabs(hi[0] - lo[0] - 0.16) < 0.01);
	assert_true(fabs(hi[1] - lo[1] - 0.12) < 0.01);
	assert_true(fabs(hi[2] - lo[2] - 0.12) < 0.01);

	/* the engine's haptic coupling from these figures: 1000 N/m, 7.9 N at 1 kHz */
	irdm_engine_config_haptic(&ec, 1e-3, c.k_max_n_per_m, c.b_device_ns_per_m, c.max_force_n);
	assert_true(ec.coupling_k_n_per_m == 1000.0);
	assert_true(ec.max_force_n == 7.9);
	/* and the motors give 7.9 N along each axis at the home pose unsaturated */
	for (int i = 0; i < 3; i++) {
		double f[3] = { 0, 0, 0 }, tau[3], out[3], s;

		f[i] = c.max_force_n;
		irdm_device_force_to_torque(&c, (double[3]){ 0, 0, 0 }, f, tau);
		assert_int_equal(irdm_device_torque_saturate(&c, tau, out, &s), IRDM_OK);
		assert_true(s == 1.0);
	}
}

static void test_config_check_rejects(void **state)
{
	struct irdm_device_config c;
	(void)state;

#define REJECT(field, value) \
	do { \
		irdm_device_config_default(&c); \
		c.field = (value); \
		assert_int_equal(irdm_device_config_check(&c), IRDM_EINVAL); \
	} while (0)
	REJECT(l1_m, 0);
	REJECT(l2_m, NAN);
	REJECT(counts_per_rev[1], -4000);
	REJECT(gear_ratio[2], 0);
	REJECT(sign[0], 0);
	REJECT(count_max[1], c.count_min[1] - 1);
	REJECT(torque_limit_nm[2], INFINITY);
	REJECT(mass_kg[0], -0.1);
	REJECT(gravity_m_per_s2, -9.81);
	REJECT(max_force_n, 0);
	REJECT(b_device_ns_per_m, NAN);
#undef REJECT
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_fk_hand_poses),
		cmocka_unit_test(test_jacobian_fd),
		cmocka_unit_test(test_transpose_virtual_work),
		cmocka_unit_test(test_saturation_keeps_direction),
		cmocka_unit_test(test_saturation_edges),
		cmocka_unit_test(test_gravity_fd),
		cmocka_unit_test(test_encoder_values),
		cmocka_unit_test(test_encoder_round_trips),
		cmocka_unit_test(test_encoder_rejects),
		cmocka_unit_test(test_default_count_range),
		cmocka_unit_test(test_defaults_desktop_like),
		cmocka_unit_test(test_config_check_rejects),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
