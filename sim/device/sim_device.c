/* SPDX-License-Identifier: MIT */
/*
 * The simulated arm (irdm/sim_device.h states the model and its choices).
 *
 * Each body is a point whose position, relative to the shoulder, is
 *   r = a cos q2 + b sin q3,  h = a sin q2 - b cos q3,  p = (r sin q1, h, r cos q1)
 * with (a, b) = (com0, 0) for the upper arm, (l1, com1) for the forearm and
 * (0, com2) for what turns with q3: one formula gives every body's Jacobian
 * and the part of its acceleration that does not depend on q'' (Coriolis
 * and centrifugal), so the equations of motion are Lagrange's for point
 * masses:  M(q) q'' = tau - sum_b m_b J_b^T (a_b + g y^).
 */
#include <math.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/sim/sim_device.h"

#define RING (IRDM_SIM_DELAY_MAX + 1)

struct body {
	double m, a, b;
};

static void bodies(const struct irdm_device_config *d, struct body b[3])
{
	b[0] = (struct body){ d->mass_kg[0], d->com_m[0], 0 };
	b[1] = (struct body){ d->mass_kg[1], d->l1_m, d->com_m[1] };
	b[2] = (struct body){ d->mass_kg[2], 0, d->com_m[2] };
}

/* Jacobian j (row-major, rows x y z) and velocity-product acceleration acc. */
static void point_kin(const struct body *bd, const double q[3], const double qd[3],
		      double j[9], double acc[3])
{
	double s1 = sin(q[0]), c1 = cos(q[0]), s2 = sin(q[1]), c2 = cos(q[1]);
	double s3 = sin(q[2]), c3 = cos(q[2]);
	double r = bd->a * c2 + bd->b * s3;
	double rd = -bd->a * s2 * qd[1] + bd->b * c3 * qd[2];
	double rdd = -bd->a * c2 * qd[1] * qd[1] - bd->b * s3 * qd[2] * qd[2];
	double hdd = -bd->a * s2 * qd[1] * qd[1] + bd->b * c3 * qd[2] * qd[2];

	j[0] = r * c1;
	j[1] = -bd->a * s2 * s1;
	j[2] = bd->b * c3 * s1;
	j[3] = 0;
	j[4] = bd->a * c2;
	j[5] = bd->b * s3;
	j[6] = -r * s1;
	j[7] = -bd->a * s2 * c1;
	j[8] = bd->b * c3 * c1;
	acc[0] = rdd * s1 + 2 * rd * c1 * qd[0] - r * s1 * qd[0] * qd[0];
	acc[1] = hdd;
	acc[2] = rdd * c1 - 2 * rd * s1 * qd[0] - r * c1 * qd[0] * qd[0];
}

/*
 * Mass matrix m, the velocity-and-gravity bias (sum m_b J_b^T (a_b + g y^))
 * and the gravity part alone (dU/dq).
 */
static void dynamics(const struct irdm_sim_device *s, const double q[3], const double qd[3],
		     double m[9], double bias[3], double grav[3])
{
	struct body b[3];
	double g = s->dev.gravity_m_per_s2;

	bodies(&s->dev, b);
	memset(m, 0, 9 * sizeof(*m));
	for (int i = 0; i < 3; i++) {
		m[4 * i] = s->p.joint_inertia_kg_m2[i];
		bias[i] = grav[i] = 0;
	}
	for (int k = 0; k < 3; k++) {
		double j[9], acc[3];

		point_kin(&b[k], q, qd, j, acc);
		acc[1] += g;
		for (int r = 0; r < 3; r++) {
			for (int c = 0; c < 3; c++)
				m[3 * r + c] += b[k].m * (j[r] * j[c] + j[3 + r] * j[3 + c] +
							  j[6 + r] * j[6 + c]);
			bias[r] += b[k].m * (j[r] * acc[0] + j[3 + r] * acc[1] + j[6 + r] * acc[2]);
			grav[r] += b[k].m * g * j[3 + r];
		}
	}
}

/* Solve m x = rhs on the joints not in `stuck` (x = 0 on those). */
static void solve_free(const double m[9], const double rhs[3], unsigned stuck, double x[3])
{
	double a[3][4];
	int idx[3], n = 0;

	for (int i = 0; i < 3; i++) {
		x[i] = 0;
		if (!(stuck & (1u << i)))
			idx[n++] = i;
	}
	for (int r = 0; r < n; r++) {
		for (int c = 0; c < n; c++)
			a[r][c] = m[3 * idx[r] + idx[c]];
		a[r][n] = rhs[idx[r]];
	}
	/* M is symmetric positive definite (joint inertia > 0): no pivoting */
	for (int p = 0; p < n; p++)
		for (int r = p + 1; r < n; r++) {
			double f = a[r][p] / a[p][p];

			for (int c = p; c <= n; c++)
				a[r][c] -= f * a[p][c];
		}
	for (int r = n - 1; r >= 0; r--) {
		double v = a[r][n];

		for (int c = r + 1; c < n; c++)
			v -= a[r][c] * x[idx[c]];
		x[idx[r]] = v / a[r][r];
	}
}

/* The end stops' torque on joint i (zero off the stops). */
static double stop_torque(const struct irdm_sim_device *s, int i, double q, double qd)
{
	double k = s->p.stop_stiffness_nm_per_rad, b = s->p.stop_damping_nm_s_per_rad;

	if (q < s->stop_lo_rad[i])
		return k * (s->stop_lo_rad[i] - q) - b * qd;
	if (q > s->stop_hi_rad[i])
		return -k * (q - s->stop_hi_rad[i]) - b * qd;
	return 0;
}

/* Torques at (q, q'): motors and the hand (J^T f at q) held over the
 * sub-step, and the end stops. */
static void applied(const struct irdm_sim_device *s, const double q[3], const double qd[3],
		    double tau[3])
{
	double th[3];

	irdm_device_force_to_torque(&s->dev, q, s->hand_n, th);
	for (int i = 0; i < 3; i++)
		tau[i] = s->motor_nm[i] + th[i] + stop_torque(s, i, q[i], qd[i]);
}

/* x = (q, q'); friction fixed over the sub-step; stuck joints do not move. */
static void deriv(const struct irdm_sim_device *s, const double x[6], const double fric[3],
		  unsigned stuck, double dx[6])
{
	double m[9], bias[3], grav[3], tau[3], rhs[3];

	dynamics(s, x, x + 3, m, bias, grav);
	applied(s, x, x + 3, tau);
	for (int i = 0; i < 3; i++) {
		rhs[i] = tau[i] - bias[i] - s->p.viscous_nm_s_per_rad[i] * x[3 + i] + fric[i];
		dx[i] = x[3 + i];
	}
	solve_free(m, rhs, stuck, dx + 3);
}

/* Karnopp: which joints stick this sub-step, and the others' friction. */
static unsigned classify(struct irdm_sim_device *s, double fric[3])
{
	double m[9], bias[3], grav[3], tau[3];
	unsigned stuck = 0;

	dynamics(s, s->q_rad, s->qd_rad_per_s, m, bias, grav);
	applied(s, s->q_rad, s->qd_rad_per_s, tau);
	for (int i = 0; i < 3; i++) {
		double c = s->p.coulomb_nm[i], v = s->qd_rad_per_s[i];
		double hold = tau[i] - grav[i]; /* what friction must resist */

		fric[i] = 0;
		if (c <= 0)
			continue;
		if (fabs(v) > s->p.stick_velocity_rad_per_s) {
			fric[i] = -copysign(c, v);
		} else if (fabs(hold) <= c) {
			stuck |= 1u << i;
			s->qd_rad_per_s[i] = 0;
		} else {
			fric[i] = -copysign(c, hold); /* breaking away */
		}
	}
	return stuck;
}

static void substep(struct irdm_sim_device *s, double h)
{
	double x[6], k1[6], k2[6], k3[6], k4[6], t[6], fric[3], v0[3];
	unsigned stuck = classify(s, fric);

	memcpy(x, s->q_rad, sizeof(s->q_rad));
	memcpy(x + 3, s->qd_rad_per_s, sizeof(s->qd_rad_per_s));
	memcpy(v0, s->qd_rad_per_s, sizeof(v0));
	deriv(s, x, fric, stuck, k1);
	for (int i = 0; i < 6; i++)
		t[i] = x[i] + 0.5 * h * k1[i];
	deriv(s, t, fric, stuck, k2);
	for (int i = 0; i < 6; i++)
		t[i] = x[i] + 0.5 * h * k2[i];
	deriv(s, t, fric, stuck, k3);
	for (int i = 0; i < 6; i++)
		t[i] = x[i] + h * k3[i];
	deriv(s, t, fric, stuck, k4);
	for (int i = 0; i < 6; i++)
		x[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
	for (int i = 0; i < 3; i++) {
		s->q_rad[i] = x[i];
		s->qd_rad_per_s[i] = x[3 + i];
		/* Coulomb friction stops a joint; it does not reverse it */
		if (fric[i] != 0 && v0[i] * x[3 + i] < 0)
			s->qd_rad_per_s[i] = 0;
	}
}

void irdm_sim_params_default(struct irdm_sim_params *p)
{
	static const struct irdm_sim_params def = {
		.joint_inertia_kg_m2 = { 2e-4, 2e-4, 2e-4 },
		.viscous_nm_s_per_rad = { 2e-3, 2e-3, 2e-3 },
		.coulomb_nm = { 5e-3, 5e-3, 5e-3 },
		.stick_velocity_rad_per_s = 1e-3,
		.substeps = IRDM_SIM_DEFAULT_SUBSTEPS,
		.write_delay_ticks = IRDM_SIM_DEFAULT_DELAY_TICKS,
		.read_delay_ticks = IRDM_SIM_DEFAULT_DELAY_TICKS,
		.end_stops = IRDM_SIM_DEFAULT_END_STOPS,
		.stop_inset_rad = 0.02,
		.stop_stiffness_nm_per_rad = 500,
		.stop_damping_nm_s_per_rad = 0.6,
	};

	*p = def;
}

static int params_ok(const struct irdm_sim_params *p)
{
	for (int i = 0; i < 3; i++) {
		if (!(isfinite(p->joint_inertia_kg_m2[i]) && p->joint_inertia_kg_m2[i] > 0))
			return 0;
		if (!(isfinite(p->viscous_nm_s_per_rad[i]) && p->viscous_nm_s_per_rad[i] >= 0))
			return 0;
		if (!(isfinite(p->coulomb_nm[i]) && p->coulomb_nm[i] >= 0) || !isfinite(p->q0_rad[i]))
			return 0;
	}
	if (p->end_stops &&
	    !(isfinite(p->stop_inset_rad) && p->stop_inset_rad >= 0 &&
	      isfinite(p->stop_stiffness_nm_per_rad) && p->stop_stiffness_nm_per_rad > 0 &&
	      isfinite(p->stop_damping_nm_s_per_rad) && p->stop_damping_nm_s_per_rad >= 0))
		return 0;
	return isfinite(p->stick_velocity_rad_per_s) && p->stick_velocity_rad_per_s > 0 &&
	       p->substeps >= 1 && p->substeps <= IRDM_SIM_SUBSTEPS_MAX &&
	       p->write_delay_ticks <= IRDM_SIM_DELAY_MAX && p->read_delay_ticks <= IRDM_SIM_DELAY_MAX;
}

/* Sample the encoders into the read ring's slot for the current tick. */
/*
 * An incremental encoder counts on past the range the controller accepts
 * (count_min..count_max is the controller's check, which reports it as
 * its own cause): the sample is the count wherever it lies; only an angle
 * with no int32 count (not finite, or beyond 2^31 counts) has none.
 */
static void sample(struct irdm_sim_device *s)
{
	unsigned slot = (unsigned)(s->ticks % RING);
	struct irdm_device_config enc = s->dev;

	for (unsigned i = 0; i < 3; i++) {
		enc.count_min[i] = INT32_MIN;
		enc.count_max[i] = INT32_MAX;
	}
	s->count_status[slot] = irdm_device_counts_from_angles(&enc, s->q_rad, s->count_ring[slot]);
}

/*
 * The stops: stop_inset_rad inside the angles the encoders can read, from
 * the start of count_min's cell to the end of count_max's (either way
 * round: a joint may count against its angle).
 * Return: 0, or -1 if a range is not wider than twice the inset or the
 * initial pose is not between the stops.
 */
static int place_stops(struct irdm_sim_device *s)
{
	for (unsigned i = 0; i < 3; i++) {
		double c = irdm_device_rad_per_count(&s->dev, i) * s->dev.sign[i];
		double a = s->dev.angle_offset_rad[i] + c * s->dev.count_min[i];
		double b = s->dev.angle_offset_rad[i] + c * (s->dev.count_max[i] + 1.0);

		s->stop_lo_rad[i] = -INFINITY;
		s->stop_hi_rad[i] = INFINITY;
		if (!s->p.end_stops)
			continue;
		s->stop_lo_rad[i] = fmin(a, b) + s->p.stop_inset_rad;
		s->stop_hi_rad[i] = fmax(a, b) - s->p.stop_inset_rad;
		if (!(s->stop_lo_rad[i] < s->stop_hi_rad[i]) ||
		    !(s->q_rad[i] >= s->stop_lo_rad[i] && s->q_rad[i] <= s->stop_hi_rad[i]))
			return -1;
	}
	return 0;
}

int irdm_sim_device_init(struct irdm_sim_device *s, const struct irdm_device_config *dev,
			 const struct irdm_sim_params *p)
{
	if (irdm_device_config_check(dev) != IRDM_OK || !params_ok(p))
		return IRDM_EINVAL;
	memset(s, 0, sizeof(*s));
	s->dev = *dev;
	s->p = *p;
	memcpy(s->q_rad, p->q0_rad, sizeof(s->q_rad));
	if (place_stops(s)) {
		memset(s, 0, sizeof(*s));
		return IRDM_EINVAL;
	}
	/* readers see the initial pose until the first delayed sample arrives */
	sample(s);
	for (unsigned i = 1; i < RING; i++) {
		memcpy(s->count_ring[i], s->count_ring[0], sizeof(s->count_ring[0]));
		s->count_status[i] = s->count_status[0];
	}
	return IRDM_OK;
}

int irdm_sim_device_set_torque(struct irdm_sim_device *s, const double tau[3])
{
	for (int i = 0; i < 3; i++)
		if (!isfinite(tau[i])) {
			memset(s->cmd_nm, 0, sizeof(s->cmd_nm));
			return IRDM_EFAULT;
		}
	for (int i = 0; i < 3; i++) {
		double lim = s->dev.torque_limit_nm[i];

		s->cmd_nm[i] = fmin(lim, fmax(-lim, tau[i]));
	}
	return IRDM_OK;
}

void irdm_sim_device_torque_off(struct irdm_sim_device *s)
{
	memset(s->cmd_nm, 0, sizeof(s->cmd_nm));
	memset(s->cmd_ring, 0, sizeof(s->cmd_ring));
	memset(s->motor_nm, 0, sizeof(s->motor_nm));
}

int irdm_sim_device_set_hand_force(struct irdm_sim_device *s, const double f[3])
{
	for (int i = 0; i < 3; i++)
		if (!isfinite(f[i])) {
			memset(s->hand_n, 0, sizeof(s->hand_n));
			return IRDM_EFAULT;
		}
	memcpy(s->hand_n, f, sizeof(s->hand_n));
	return IRDM_OK;
}

int irdm_sim_device_step(struct irdm_sim_device *s, double dt_s)
{
	double q0[3], qd0[3];
	unsigned now = (unsigned)(s->ticks % RING);
	unsigned late = (unsigned)((s->ticks + RING - s->p.write_delay_ticks) % RING);

	if (!(isfinite(dt_s) && dt_s > 0))
		return IRDM_EINVAL;
	/* the command joins the bus; the one sent write_delay ticks ago lands
	 * (zero before any has had time to arrive: the ring starts zeroed) */
	memcpy(s->cmd_ring[now], s->cmd_nm, sizeof(s->cmd_nm));
	memcpy(s->motor_nm, s->cmd_ring[late], sizeof(s->motor_nm));
	memcpy(q0, s->q_rad, sizeof(q0));
	memcpy(qd0, s->qd_rad_per_s, sizeof(qd0));
	for (unsigned k = 0; k < s->p.substeps; k++)
		substep(s, dt_s / s->p.substeps);
	for (int i = 0; i < 3; i++)
		if (!isfinite(s->q_rad[i]) || !isfinite(s->qd_rad_per_s[i]))
			goto fault;
	s->ticks++;
	sample(s);
	return IRDM_OK;

fault:
	memcpy(s->q_rad, q0, sizeof(q0));
	memcpy(s->qd_rad_per_s, qd0, sizeof(qd0));
	return IRDM_EFAULT;
}

int irdm_sim_device_read_counts(const struct irdm_sim_device *s, int32_t counts[3])
{
	unsigned slot = (unsigned)((s->ticks + RING - s->p.read_delay_ticks) % RING);

	if (s->count_status[slot] != IRDM_OK)
		return IRDM_EFAULT;
	memcpy(counts, s->count_ring[slot], sizeof(s->count_ring[slot]));
	return IRDM_OK;
}

void irdm_sim_device_state(const struct irdm_sim_device *s, double q[3], double qd[3])
{
	memcpy(q, s->q_rad, sizeof(s->q_rad));
	memcpy(qd, s->qd_rad_per_s, sizeof(s->qd_rad_per_s));
}

void irdm_sim_device_motor_torque(const struct irdm_sim_device *s, double tau[3])
{
	memcpy(tau, s->motor_nm, sizeof(s->motor_nm));
}
