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

void irdm_device_config_default(struct irdm_device_config *cfg)
{
	static const struct irdm_device_config def = {
		.l1_m = IRDM_DEVICE_DEFAULT_L1_M,
		.l2_m = IRDM_DEVICE_DEFAULT_L2_M,
		.base_offset_m = { IRDM_DEVICE_DEFAULT_BASE_OFFSET_M },
		.counts_per_rev = { IRDM_DEVICE_DEFAULT_COUNTS_PER_REV },
		.gear_ratio = { IRDM_DEVICE_DEFAULT_GEAR_RATIO },
		.angle_offset_rad = { IRDM_DEVICE_DEFAULT_ANGLE_OFFSET_RAD },
		.sign = { IRDM_DEVICE_DEFAULT_SIGN },
		.count_min = { IRDM_DEVICE_DEFAULT_COUNT_MIN },
		.count_max = { IRDM_DEVICE_DEFAULT_COUNT_MAX },
		.torque_limit_nm = { IRDM_DEVICE_DEFAULT_TORQUE_LIMIT_NM },
		.mass_kg = { IRDM_DEVICE_DEFAULT_MASS_KG },
		.com_m = { IRDM_DEVICE_DEFAULT_COM_M },
		.gravity_m_per_s2 = IRDM_DEVICE_DEFAULT_GRAVITY_M_PER_S2,
		.max_force_n = IRDM_DEVICE_DEFAULT_MAX_FORCE_N,
		.k_max_n_per_m = IRDM_DEVICE_DEFAULT_K_MAX_N_PER_M,
		.b_device_ns_per_m = IRDM_DEVICE_DEFAULT_B_DEVICE_NS_PER_M,
	};

	*cfg = def;
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
	double dr2 = -cfg->l1_m * sin(q[1]), dr3 = cfg->l2_m * cos(q[2]); /* dr/dq2, dr/dq3 */
	double r = cfg->l1_m * cos(q[1]) + cfg->l2_m * sin(q[2]);

	j[0] = r * c1;
	j[1] = dr2 * s1;
	j[2] = dr3 * s1;
	j[3] = 0;
	j[4] = cfg->l1_m * cos(q[1]);
	j[5] = cfg->l2_m * sin(q[2]);
	j[6] = -r * s1;
	j[7] = dr2 * c1;
	j[8] = dr3 * c1;
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
