/* SPDX-License-Identifier: MIT */
/*
 * The simulated arm (irdm/sim_device.h) against independent references:
 * energy from the test's own body positions (finite-difference
 * velocities), the analytic exponential of a viscous joint, exact sticking
 * under Coulomb friction, floor-quantised counts computed here, and a delay
 * that must be an exact shift of the undelayed run.
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
#include "irdm/error.h"
#include "irdm/sim/sim_device.h"

#define DT 1e-3

static struct irdm_sim_device sim, sim2; /* big: keep them off the stack */

/* The free arm: these tests follow motions longer than the joints' travel,
 * so the end stops are off (test_end_stop checks them). */
static void free_arm(struct irdm_sim_params *p)
{
	irdm_sim_params_default(p);
	p->end_stops = 0;
}

static void frictionless(struct irdm_sim_params *p)
{
	free_arm(p);
	for (int i = 0; i < 3; i++)
		p->viscous_nm_s_per_rad[i] = p->coulomb_nm[i] = 0;
}

/* ---- energy, written from the bodies of irdm/device.h ---------------------- */

static void body_pos(const struct irdm_device_config *c, int k, const double q[3], double p[3])
{
	double elbow_r = c->l1_m * cos(q[1]), elbow_h = c->l1_m * sin(q[1]);
	double r, h;

	if (k == 0) { /* along the upper arm */
		r = c->com_m[0] * cos(q[1]);
		h = c->com_m[0] * sin(q[1]);
	} else if (k == 1) { /* along the forearm from the elbow */
		r = elbow_r + c->com_m[1] * sin(q[2]);
		h = elbow_h - c->com_m[1] * cos(q[2]);
	} else { /* turns with q3 about the shoulder */
		r = c->com_m[2] * sin(q[2]);
		h = -c->com_m[2] * cos(q[2]);
	}
	p[0] = r * sin(q[0]);
	p[1] = h;
	p[2] = r * cos(q[0]);
}

static double energy(const struct irdm_sim_device *s, const struct irdm_sim_params *p)
{
	const struct irdm_device_config *c = &s->dev;
	double q[3], qd[3], e = 0;
	const double eps = 1e-6;

	irdm_sim_device_state(s, q, qd);
	for (int k = 0; k < 3; k++) {
		double qp[3], qm[3], pp[3], pm[3], v2 = 0;

		for (int i = 0; i < 3; i++) {
			qp[i] = q[i] + eps * qd[i];
			qm[i] = q[i] - eps * qd[i];
		}
		body_pos(c, k, qp, pp);
		body_pos(c, k, qm, pm);
		for (int i = 0; i < 3; i++)
			v2 += pow((pp[i] - pm[i]) / (2 * eps), 2);
		body_pos(c, k, q, pp);
		e += c->mass_kg[k] * (0.5 * v2 + c->gravity_m_per_s2 * pp[1]);
	}
	for (int i = 0; i < 3; i++)
		e += 0.5 * p->joint_inertia_kg_m2[i] * qd[i] * qd[i];
	return e;
}

static void test_energy_conserved(void **state)
{
	struct irdm_device_config c;
	struct irdm_sim_params p;
	double e0, drift = 0, vmax = 0, q[3], qd[3];
	(void)state;

	irdm_device_config_default(&c);
	frictionless(&p);
	memcpy(p.q0_rad, (double[3]){ 0.1, 0.2, -0.1 }, sizeof(p.q0_rad));
	assert_int_equal(irdm_sim_device_init(&sim, &c, &p), IRDM_OK);
	/* kick all three joints, then let it swing under gravity alone */
	assert_int_equal(irdm_sim_device_set_torque(&sim, (double[3]){ 0.05, -0.1, 0.08 }), IRDM_OK);
	for (int k = 0; k < 30; k++)
		assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
	assert_int_equal(irdm_sim_device_set_torque(&sim, (double[3]){ 0, 0, 0 }), IRDM_OK);
	assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK); /* zero reaches motors */
	e0 = energy(&sim, &p);
	for (int k = 0; k < 2000; k++) {
		assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
		drift = fmax(drift, fabs(energy(&sim, &p) - e0));
		irdm_sim_device_state(&sim, q, qd);
		for (int i = 0; i < 3; i++)
			vmax = fmax(vmax, fabs(qd[i]));
	}
	printf("frictionless swing, 2 s, RK4 at 0.1 ms: |E - E0| <= %.3g J (E0 %.4g J, joint "
	       "speeds up to %.3g rad/s)\n",
	       drift, e0, vmax);
	assert_true(vmax > 1);      /* it did swing */
	assert_true(drift < 5e-11); /* 1.2e-11 measured: 4x */
}

/* ---- a single viscous joint ------------------------------------------------ */

static void test_viscous_exponential(void **state)
{
	struct irdm_device_config c;
	struct irdm_sim_params p;
	const double tau = 0.01, b = 2e-3, in = 2e-4; /* time constant in / b = 0.1 s */
	double worst = 0, q[3], qd[3], v1 = 0;
	(void)state;

	/* massless links: the joint sees its own inertia only */
	irdm_device_config_default(&c);
	memset(c.mass_kg, 0, sizeof(c.mass_kg));
	free_arm(&p);
	memset(p.coulomb_nm, 0, sizeof(p.coulomb_nm));
	assert_int_equal(irdm_sim_device_init(&sim, &c, &p), IRDM_OK);
	assert_int_equal(irdm_sim_device_set_torque(&sim, (double[3]){ 0, tau, 0 }), IRDM_OK);
	/* spin up: v(t) = tau / b (1 - exp(-b t / I)) */
	for (int k = 1; k <= 300; k++) {
		assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
		irdm_sim_device_state(&sim, q, qd);
		worst = fmax(worst, fabs(qd[1] - tau / b * (1 - exp(-b * k * DT / in))));
		assert_true(qd[0] == 0 && qd[2] == 0 && q[0] == 0 && q[2] == 0);
	}
	v1 = qd[1];
	/* coast: v(t) = v1 exp(-b t / I) */
	assert_int_equal(irdm_sim_device_set_torque(&sim, (double[3]){ 0, 0, 0 }), IRDM_OK);
	for (int k = 1; k <= 500; k++) {
		assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
		irdm_sim_device_state(&sim, q, qd);
		worst = fmax(worst, fabs(qd[1] - v1 * exp(-b * k * DT / in)));
	}
	printf("viscous joint vs analytic exponential: max |error| %.3g rad/s (peak %.3g rad/s)\n",
	       worst, v1);
	assert_true(worst < 1e-13); /* 2.1e-14 measured: 5x */
}

/* ---- Coulomb friction ------------------------------------------------------ */

static void test_coulomb_holds(void **state)
{
	struct irdm_device_config c;
	struct irdm_sim_params p;
	const double q0[3] = { 0.1, 0.2, -0.1 };
	double g[3], tau[3], q[3], qd[3];
	(void)state;

	irdm_device_config_default(&c);
	irdm_sim_params_default(&p);
	memcpy(p.q0_rad, q0, sizeof(q0));
	irdm_device_gravity_torque(&c, q0, g);

	/* gravity compensated, 90 % of the breakaway torque on every joint: still */
	assert_int_equal(irdm_sim_device_init(&sim, &c, &p), IRDM_OK);
	for (int i = 0; i < 3; i++)
		tau[i] = g[i] + 0.9 * p.coulomb_nm[i] * (i == 1 ? -1 : 1);
	assert_int_equal(irdm_sim_device_set_torque(&sim, tau), IRDM_OK);
	for (int k = 0; k < 500; k++)
		assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
	irdm_sim_device_state(&sim, q, qd);
	assert_memory_equal(q, q0, sizeof(q));
	assert_true(qd[0] == 0 && qd[1] == 0 && qd[2] == 0);

	/* 110 % on the yaw: it breaks away that way; the others stay put */
	tau[0] = g[0] + 1.1 * p.coulomb_nm[0];
	assert_int_equal(irdm_sim_device_set_torque(&sim, tau), IRDM_OK);
	for (int k = 0; k < 100; k++)
		assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
	irdm_sim_device_state(&sim, q, qd);
	printf("coulomb: 110 %% breakaway on yaw moved it %.3g rad in 0.1 s\n", q[0] - q0[0]);
	assert_true(q[0] - q0[0] > 1e-4 && qd[0] > 0);
	assert_true(q[1] == q0[1] && q[2] == q0[2]);

	/* no compensation: gravity (0.08 N m) beats friction (5e-3): it falls */
	assert_int_equal(irdm_sim_device_init(&sim, &c, &p), IRDM_OK);
	for (int k = 0; k < 100; k++)
		assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
	irdm_sim_device_state(&sim, q, qd);
	assert_true(q[1] < q0[1] - 1e-3);
}

/* ---- encoders -------------------------------------------------------------- */

static int32_t floor_count(const struct irdm_device_config *c, int i, double q)
{
	double per_rad = c->counts_per_rev[i] * c->gear_ratio[i] / (2 * 3.14159265358979323846);

	return (int32_t)floor(c->sign[i] * (q - c->angle_offset_rad[i]) * per_rad);
}

static void test_quantisation_floor(void **state)
{
	struct irdm_device_config c;
	struct irdm_sim_params p;
	int32_t n[3];
	double q[3], qd[3];
	int checked = 0;
	(void)state;

	irdm_device_config_default(&c);
	c.angle_offset_rad[2] = 0.013;
	free_arm(&p);
	memcpy(p.q0_rad, (double[3]){ -0.2, 0.3, 0.2 }, sizeof(p.q0_rad));
	assert_int_equal(irdm_sim_device_init(&sim, &c, &p), IRDM_OK);
	/* the arm falls through many counts; every sample is the floor */
	for (int k = 0; k < 300; k++) {
		assert_int_equal(irdm_sim_device_set_torque(&sim, (double[3]){ 0.02, 0, 0 }), IRDM_OK);
		assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
		irdm_sim_device_state(&sim, q, qd);
		if (irdm_sim_device_read_counts(&sim, n) != IRDM_OK)
			break; /* left the range: checked below */
		for (int i = 0; i < 3; i++)
			assert_int_equal(n[i], floor_count(&c, i, q[i]));
		checked++;
	}
	printf("quantisation: %d ticks of floor-exact counts\n", checked);
	assert_true(checked > 100);
	/* outside the range the controller accepts the encoder still counts:
	 * the controller's check, not the read, reports it */
	memcpy(p.q0_rad, (double[3]){ 0, 1.2, 0 }, sizeof(p.q0_rad));
	assert_int_equal(irdm_sim_device_init(&sim, &c, &p), IRDM_OK);
	assert_int_equal(irdm_sim_device_read_counts(&sim, n), IRDM_OK);
	assert_int_equal(n[1], floor_count(&c, 1, 1.2));
	assert_true(n[1] > c.count_max[1] || n[1] < c.count_min[1]);
}

/* ---- delays ---------------------------------------------------------------- */

static void delayed_pair(unsigned write_k, unsigned read_k)
{
	struct irdm_device_config c;
	struct irdm_sim_params p;
	enum { N = 40 };
	static double qa[N + 1][3], qb[N + 1][3];
	static int32_t na[N + 1][3], nb[N + 1][3];
	double qd[3];

	irdm_device_config_default(&c);
	c.gravity_m_per_s2 = 0; /* at rest until the torque arrives */
	frictionless(&p);
	assert_int_equal(irdm_sim_device_init(&sim, &c, &p), IRDM_OK);
	p.write_delay_ticks = write_k;
	p.read_delay_ticks = read_k;
	assert_int_equal(irdm_sim_device_init(&sim2, &c, &p), IRDM_OK);
	for (int k = 0; k <= N; k++) {
		double tau[3] = { 0.2, -0.3, 0.25 };

		if (k > 0) {
			assert_int_equal(irdm_sim_device_set_torque(&sim, tau), IRDM_OK);
			assert_int_equal(irdm_sim_device_set_torque(&sim2, tau), IRDM_OK);
			assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
			assert_int_equal(irdm_sim_device_step(&sim2, DT), IRDM_OK);
		}
		irdm_sim_device_state(&sim, qa[k], qd);
		irdm_sim_device_state(&sim2, qb[k], qd);
		assert_int_equal(irdm_sim_device_read_counts(&sim, na[k]), IRDM_OK);
		assert_int_equal(irdm_sim_device_read_counts(&sim2, nb[k]), IRDM_OK);
	}
	/* the delayed arm is the undelayed one shifted by exactly write_k ticks,
	 * and its reader sees that a further read_k ticks late */
	for (int k = 0; k <= N; k++) {
		int kw = k - (int)write_k, kr = k - (int)read_k;

		assert_memory_equal(qb[k], qa[kw > 0 ? kw : 0], sizeof(qb[k]));
		kr = kr > 0 ? kr : 0;
		kw = kr - (int)write_k;
		assert_memory_equal(nb[k], na[kw > 0 ? kw : 0], sizeof(nb[k]));
	}
	assert_true(memcmp(qa[N], qa[0], sizeof(qa[0])) != 0); /* it moved */
	assert_true(memcmp(na[N], na[0], sizeof(na[0])) != 0);
}

static void test_delay_exact(void **state)
{
	(void)state;
	delayed_pair(0, 0);
	delayed_pair(3, 0);
	delayed_pair(0, 4);
	delayed_pair(2, 5);
	delayed_pair(IRDM_SIM_DELAY_MAX, IRDM_SIM_DELAY_MAX);
}

/* ---- the hand, limits, rejects ---------------------------------------------- */

static void test_hand_force_work(void **state)
{
	struct irdm_device_config c;
	struct irdm_sim_params p;
	const double f[3] = { 0.5, -0.3, 0.8 };
	double tip0[3], tip[3], q[3], qd[3], worst = 0, ke = 0;
	(void)state;

	/* no gravity, no friction: the kinetic energy is the hand's work,
	 * F . (tip - tip0) for a constant force */
	irdm_device_config_default(&c);
	c.gravity_m_per_s2 = 0;
	frictionless(&p);
	assert_int_equal(irdm_sim_device_init(&sim, &c, &p), IRDM_OK);
	irdm_device_fk(&c, p.q0_rad, tip0);
	assert_int_equal(irdm_sim_device_set_hand_force(&sim, f), IRDM_OK);
	for (int k = 0; k < 200; k++) {
		double w = 0;

		assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
		irdm_sim_device_state(&sim, q, qd);
		irdm_device_fk(&c, q, tip);
		for (int i = 0; i < 3; i++)
			w += f[i] * (tip[i] - tip0[i]);
		ke = energy(&sim, &p);
		worst = fmax(worst, fabs(ke - w));
	}
	printf("hand force: kinetic energy vs work F.dx: max |error| %.3g J (KE %.3g J)\n", worst,
	       ke);
	assert_true(ke > 1e-3);
	assert_true(worst < 1e-9 * ke); /* 2.5e-10 KE measured: 4x */
	assert_int_equal(irdm_sim_device_set_hand_force(&sim, (double[3]){ NAN, 0, 0 }),
			 IRDM_EFAULT);
	assert_true(sim.hand_n[0] == 0 && sim.hand_n[1] == 0 && sim.hand_n[2] == 0);
}

static void test_limits_and_rejects(void **state)
{
	struct irdm_device_config c;
	struct irdm_sim_params p;
	double tau[3];
	(void)state;

	irdm_device_config_default(&c);
	irdm_sim_params_default(&p);
	assert_int_equal(irdm_sim_device_init(&sim, &c, &p), IRDM_OK);
	/* the motors clip each joint */
	assert_int_equal(irdm_sim_device_set_torque(&sim, (double[3]){ 10, -10, 0.5 }), IRDM_OK);
	assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
	irdm_sim_device_motor_torque(&sim, tau);
	assert_true(tau[0] == c.torque_limit_nm[0] && tau[1] == -c.torque_limit_nm[1] &&
		    tau[2] == 0.5);
	/* non-finite: zero */
	assert_int_equal(irdm_sim_device_set_torque(&sim, (double[3]){ 0, INFINITY, 0 }),
			 IRDM_EFAULT);
	assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
	irdm_sim_device_motor_torque(&sim, tau);
	assert_true(tau[0] == 0 && tau[1] == 0 && tau[2] == 0);
	/* torque_off passes the bus delay */
	p.write_delay_ticks = 5;
	assert_int_equal(irdm_sim_device_init(&sim, &c, &p), IRDM_OK);
	for (int k = 0; k < 8; k++) {
		assert_int_equal(irdm_sim_device_set_torque(&sim, (double[3]){ 0.3, 0, 0 }), IRDM_OK);
		assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
	}
	irdm_sim_device_torque_off(&sim);
	assert_int_equal(irdm_sim_device_step(&sim, DT), IRDM_OK);
	irdm_sim_device_motor_torque(&sim, tau);
	assert_true(tau[0] == 0);

	assert_int_equal(irdm_sim_device_step(&sim, 0), IRDM_EINVAL);
	assert_int_equal(irdm_sim_device_step(&sim, NAN), IRDM_EINVAL);
#define REJECT(field, value) \
	do { \
		irdm_sim_params_default(&p); \
		p.field = (value); \
		assert_int_equal(irdm_sim_device_init(&sim, &c, &p), IRDM_EINVAL); \
	} while (0)
	REJECT(joint_inertia_kg_m2[0], 0);
	REJECT(viscous_nm_s_per_rad[1], -1);
	REJECT(coulomb_nm[2], NAN);
	REJECT(stick_velocity_rad_per_s, 0);
	REJECT(substeps, 0);
	REJECT(substeps, IRDM_SIM_SUBSTEPS_MAX + 1);
	REJECT(write_delay_ticks, IRDM_SIM_DELAY_MAX + 1);
	REJECT(read_delay_ticks, IRDM_SIM_DELAY_MAX + 1);
	REJECT(q0_rad[1], INFINITY);
	REJECT(q0_rad[1], 0.39);     /* past the shoulder's stop (0.38) */
	REJECT(stop_inset_rad, 0.5); /* no travel left between the stops */
	REJECT(stop_inset_rad, -0.01);
	REJECT(stop_stiffness_nm_per_rad, 0);
	REJECT(stop_damping_nm_s_per_rad, NAN);
#undef REJECT
	irdm_sim_params_default(&p);
	c.l1_m = -1;
	assert_int_equal(irdm_sim_device_init(&sim, &c, &p), IRDM_EINVAL);
}

/* ---- end stops -------------------------------------------------------------- */

/*
 * The yaw joint thrown at its stop.  With the shoulder and elbow held by
 * Coulomb friction far above any torque they feel (they stick: Karnopp),
 * the yaw is one degree of freedom with the constant inertia
 *   I = joint inertia + sum_b m_b r_b^2   (r_b: body b's distance from the
 * vertical axis, home pose: upper arm com0, forearm l1, crank 0),
 * no gravity torque (the axis is vertical) and, frictionless, a linear
 * spring-damper inside the stop: it leaves the stop at e times the speed
 * it came in, e = exp(-zeta pi / sqrt(1 - zeta^2)), zeta = b / (2 sqrt(k I)),
 * after half a damped period pi / (omega_n sqrt(1 - zeta^2)); and it
 * enters by at most v / omega_n (the undamped bound).
 */
static void test_end_stop(void **state)
{
	struct irdm_device_config c;
	struct irdm_sim_params p;
	double q[3], qd[3], v_in = 0, v_out = 0, t_in = -1, t_out = -1, deepest = 0;
	double inertia, zeta, e, wn, stop;
	int32_t n[3];
	(void)state;

	irdm_device_config_default(&c);
	irdm_sim_params_default(&p);
	p.coulomb_nm[0] = p.viscous_nm_s_per_rad[0] = 0;
	p.coulomb_nm[1] = p.coulomb_nm[2] = 5; /* N m: >> gravity and inertia */
	assert_int_equal(irdm_sim_device_init(&sim, &c, &p), IRDM_OK);
	inertia = p.joint_inertia_kg_m2[0] + c.mass_kg[0] * c.com_m[0] * c.com_m[0] +
		  c.mass_kg[1] * c.l1_m * c.l1_m;
	zeta = p.stop_damping_nm_s_per_rad / (2 * sqrt(p.stop_stiffness_nm_per_rad * inertia));
	e = exp(-zeta * M_PI / sqrt(1 - zeta * zeta));
	wn = sqrt(p.stop_stiffness_nm_per_rad / inertia);
	stop = (c.count_max[0] + 1.0) * irdm_device_rad_per_count(&c, 0) - p.stop_inset_rad;
	/* 5 ms of 0.5 N m (about 2 rad/s), then coast 0.4 rad into the stop;
	 * 0.1 ms steps (10 us RK4 sub-steps) time the contact */
	for (int k = 0; k < 5000 && t_out < 0; k++) {
		double tau[3] = { k < 50 ? 0.5 : 0, 0, 0 };

		assert_int_equal(irdm_sim_device_set_torque(&sim, tau), IRDM_OK);
		assert_int_equal(irdm_sim_device_step(&sim, DT / 10), IRDM_OK);
		irdm_sim_device_state(&sim, q, qd);
		assert_int_equal(irdm_sim_device_read_counts(&sim, n), IRDM_OK);
		if (q[0] <= stop && t_in < 0)
			v_in = qd[0];
		else if (t_in < 0)
			t_in = k;
		deepest = fmax(deepest, q[0] - stop);
		if (t_in >= 0 && q[0] <= stop) {
			t_out = k;
			v_out = qd[0];
		}
		assert_true(qd[1] == 0 && qd[2] == 0); /* the others stick */
	}
	printf("end stop: in at %.4f rad/s, out at %.4f rad/s: e = %.5f (analytic %.5f), "
	       "%g s in contact (analytic %g s), %.2e rad deep (bound %.2e)\n",
	       v_in, -v_out,
	       -v_out / v_in, e, (t_out - t_in) * DT / 10, M_PI / (wn * sqrt(1 - zeta * zeta)),
	       deepest, v_in / wn);
	assert_true(v_in > 0.5);
	/* measured 1.2e-4 (the contact starts inside an RK4 sub-step) */
	assert_true(fabs(-v_out / v_in - e) < 3e-4);
	/* entry and exit are seen to one 0.1 ms step */
	assert_true(fabs((t_out - t_in) * DT / 10 - M_PI / (wn * sqrt(1 - zeta * zeta))) < 1.5e-4);
	assert_true(deepest > 0.5 * v_in / wn && deepest <= v_in / wn);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_energy_conserved),
		cmocka_unit_test(test_viscous_exponential),
		cmocka_unit_test(test_coulomb_holds),
		cmocka_unit_test(test_quantisation_floor),
		cmocka_unit_test(test_delay_exact),
		cmocka_unit_test(test_hand_force_work),
		cmocka_unit_test(test_limits_and_rejects),
		cmocka_unit_test(test_end_stop),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
