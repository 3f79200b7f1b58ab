/* SPDX-License-Identifier: MIT */
/*
 * The PHANToM-like arm's model (irdm/device.h holds the model, its frame
 * and its conventions).  Pure arithmetic: it runs in the force tick.
 */
#include <math.h>
#include <stddef.h>

#include "irdm/device.h"
#include "irdm/error.h"

#define TWO_PI 6.283185307179586

/* Joint angle ranges of the default arm: a 15.8 x 11.9 x 12.2 cm box. */
static const double default_lo_rad[3] = { -0.42, -0.40, -0.35 };
static const double default_hi_rad[3] = { 0.42, 0.40, 0.45 };

double irdm_device_rad_per_count(const struct irdm_device_config *cfg, unsigned i)
{
	return TWO_PI / (cfg->counts_per_rev[i] * cfg->gear_ratio[i]);
}

/* The (unclamped) count whose cell holds angle q of joint i. */
static double count_of(const struct irdm_device_config *cfg, unsigned i, double q)
{
	return floor(cfg->sign[i] * (q - cfg->angle_offset_rad[i]) /
		     irdm_device_rad_per_count(cfg, i));
}

static void default_count_range(struct irdm_device_config *cfg, unsigned i)
{
	double a = count_of(cfg, i, default_lo_rad[i]);
	double b = count_of(cfg, i, default_hi_rad[i]);

	cfg->count_min[i] = (int32_t)fmin(a, b);
	cfg->count_max[i] = (int32_t)fmax(a, b);
}

void irdm_device_config_default(struct irdm_device_config *cfg)
{
	/* 4000 counts per motor turn (1000 lines, quadrature) through 11.6:1:
	 * 1.35e-4 rad, 18 um at the tip per count. */
	static const struct irdm_device_config def = {
		.l1_m = 0.135,
		.l2_m = 0.135,
		.base_offset_m = { 0.0, 0.135, -0.135 },        /* home pose tip at 0 */
		.counts_per_rev = { 4000, 4000, 4000 },
		.gear_ratio = { 11.6, 11.6, 11.6 },
		.angle_offset_rad = { 0, 0, 0 },
		.sign = { 1, 1, -1 },   /* the third motor turns against its joint */
		/* 7.9 N along any axis at the home pose: 7.9 N * 0.135 m */
		.torque_limit_nm = { 1.07, 1.07, 1.07 },
		.mass_kg = { 0.060, 0.045, 0.090 },
		.com_m = { 0.065, 0.080, -0.030 },
		.gravity_m_per_s2 = 9.81,
		.max_force_n = 7.9,
		.k_max_n_per_m = 1000.0,
		.b_device_ns_per_m = 5.0,
	};

	*cfg = def;
	for (unsigned i = 0; i < 3; i++)
		default_count_range(cfg, i);
}

static int positive(double v)
{
	return isfinite(v) && v > 0;
}

static int joint_ok(const struct irdm_device_config *cfg, unsigned i)
{
	return positive(cfg->counts_per_rev[i]) && positive(cfg->gear_ratio[i]) &&
	       isfinite(cfg->angle_offset_rad[i]) && (cfg->sign[i] == 1 || cfg->sign[i] == -1) &&
	       cfg->count_min[i] <= cfg->count_max[i] && positive(cfg->torque_limit_nm[i]) &&
	       isfinite(cfg->mass_kg[i]) && cfg->mass_kg[i] >= 0 && isfinite(cfg->com_m[i]) &&
	       isfinite(cfg->base_offset_m[i]);
}

int irdm_device_config_check(const struct irdm_device_config *cfg)
{
	if (!positive(cfg->l1_m) || !positive(cfg->l2_m))
		return IRDM_EINVAL;
	for (unsigned i = 0; i < 3; i++)
		if (!joint_ok(cfg, i))
			return IRDM_EINVAL;
	if (!isfinite(cfg->gravity_m_per_s2) || cfg->gravity_m_per_s2 < 0)
		return IRDM_EINVAL;
	if (!positive(cfg->max_force_n) || !positive(cfg->k_max_n_per_m) ||
	    !positive(cfg->b_device_ns_per_m))
		return IRDM_EINVAL;
	return IRDM_OK;
}

void irdm_device_fk(const struct irdm_device_config *cfg, const double q[3], double tip[3])
{
	double r = cfg->l1_m * cos(q[1]) + cfg->l2_m * sin(q[2]);
	double h = cfg->l1_m * sin(q[1]) - cfg->l2_m * cos(q[2]);

	tip[0] = cfg->base_offset_m[0] + r * sin(q[0]);
	tip[1] = cfg->base_offset_m[1] + h;
	tip[2] = cfg->base_offset_m[2] + r * cos(q[0]);
}

void irdm_device_jacobian(const struct irdm_device_config *cfg, const double q[3], double j[9])
{
	double s1 = sin(q[0]), c1 = cos(q[0]);
	double dr2 = -cfg->l1_m * sin(q[1]), dr3 = cfg->l2_m * cos(q[2]);     /* dr/dq2, dr/dq3 */
	double r = cfg->l1_m * cos(q[1]) + cfg->l2_m * sin(q[2]);

	j[0] = r * c1;  j[1] = dr2 * s1;                j[2] = dr3 * s1;
	j[3] = 0;       j[4] = cfg->l1_m * cos(q[1]);   j[5] = cfg->l2_m * sin(q[2]);
	j[6] = -r * s1; j[7] = dr2 * c1;                j[8] = dr3 * c1;
}

void irdm_device_force_to_torque(const struct irdm_device_config *cfg, const double q[3],
				 const double f[3], double tau[3])
{
	double j[9];

	irdm_device_jacobian(cfg, q, j);
	for (unsigned c = 0; c < 3; c++)
		tau[c] = j[c] * f[0] + j[3 + c] * f[1] + j[6 + c] * f[2];
}

void irdm_device_gravity_torque(const struct irdm_device_config *cfg, const double q[3],
				double tau[3])
{
	/* U = g (m0 c0 sin q2 + m1 (l1 sin q2 - c1 cos q3) - m2 c2 cos q3) */
	double g = cfg->gravity_m_per_s2;
	const double *m = cfg->mass_kg, *c = cfg->com_m;

	tau[0] = 0;
	tau[1] = g * cos(q[1]) * (m[0] * c[0] + m[1] * cfg->l1_m);
	tau[2] = g * sin(q[2]) * (m[1] * c[1] + m[2] * c[2]);
}

int irdm_device_torque_saturate(const struct irdm_device_config *cfg, const double in[3],
				double out[3], double *scale)
{
	double s = 1.0;

	for (unsigned i = 0; i < 3; i++) {
		if (!isfinite(in[i]))
			goto fault;
		if (fabs(in[i]) > cfg->torque_limit_nm[i])
			s = fmin(s, cfg->torque_limit_nm[i] / fabs(in[i]));
	}
	for (unsigned i = 0; i < 3; i++)
		out[i] = s * in[i];
	if (scale)
		*scale = s;
	return IRDM_OK;

fault:
	for (unsigned i = 0; i < 3; i++)
		out[i] = 0;
	if (scale)
		*scale = 0;
	return IRDM_EFAULT;
}

int irdm_device_angles_from_counts(const struct irdm_device_config *cfg, const int32_t counts[3],
				   double q[3])
{
	double a[3];

	for (unsigned i = 0; i < 3; i++) {
		if (counts[i] < cfg->count_min[i] || counts[i] > cfg->count_max[i])
			return IRDM_EFAULT;
		a[i] = cfg->angle_offset_rad[i] +
		       cfg->sign[i] * ((double)counts[i] + 0.5) * irdm_device_rad_per_count(cfg, i);
		if (!isfinite(a[i]))
			return IRDM_EFAULT;
	}
	for (unsigned i = 0; i < 3; i++)
		q[i] = a[i];
	return IRDM_OK;
}

int irdm_device_counts_from_angles(const struct irdm_device_config *cfg, const double q[3],
				   int32_t counts[3])
{
	double c[3];

	for (unsigned i = 0; i < 3; i++) {
		c[i] = count_of(cfg, i, q[i]);
		/* compared as doubles, so a huge angle cannot overflow the cast,
		 * and written so that a NaN or infinite angle fails too */
		if (!(c[i] >= cfg->count_min[i] && c[i] <= cfg->count_max[i]))
			return IRDM_EFAULT;
	}
	for (unsigned i = 0; i < 3; i++)
		counts[i] = (int32_t)c[i];
	return IRDM_OK;
}
