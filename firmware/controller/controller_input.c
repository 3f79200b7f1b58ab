/* SPDX-License-Identifier: MIT */
/*
 * Step 3 of the tick: raw encoder counts -> calibrated counts -> joint
 * angles -> tip (FK) -> tip velocity (adaptive windowing per joint, then
 * J q').  Velocity is estimated in joint space because that is where the
 * quantisation is: one count is the band of each joint's estimator.
 */
#include <math.h>
#include <string.h>

#include "controller_priv.h"
#include "irdm/vec3.h"

int ctrl_calibrate(struct irdm_ctrl *c, unsigned i, const int32_t raw[3])
{
	const struct irdm_ctrl_device_config *dc = &c->cfg.device[i];
	int32_t want[3];

	for (unsigned j = 0; j < 3; j++)
		if (raw[j] == IRDM_CTRL_COUNT_NAN)
			return IRDM_EFAULT;
	/* the pose is in range (irdm_ctrl_config_check), so this succeeds */
	if (irdm_device_counts_from_angles(&dc->dev, dc->calib_q_rad, want))
		return IRDM_EFAULT;
	for (unsigned j = 0; j < 3; j++) {
		c->dev[i].count_offset[j] = (int32_t)((int64_t)want[j] - raw[j]);
		irdm_velocity_reset(&c->dev[i].vel[j]);
	}
	return IRDM_OK;
}

/* Calibrated counts, in int64 so that no offset can overflow them. */
static uint32_t calibrated(const struct irdm_ctrl *c, unsigned i, const int32_t raw[3],
			   int32_t counts[3])
{
	const struct irdm_device_config *dev = &c->cfg.device[i].dev;

	for (unsigned j = 0; j < 3; j++) {
		int64_t v = (int64_t)raw[j] + c->dev[i].count_offset[j];

		if (raw[j] == IRDM_CTRL_COUNT_NAN)
			return IRDM_FAULT_ENCODER_NAN;
		if (v < dev->count_min[j] || v > dev->count_max[j])
			return IRDM_FAULT_ENCODER_RANGE;
		counts[j] = (int32_t)v;
	}
	return 0;
}

static uint32_t velocity(struct irdm_ctrl *c, unsigned i, struct irdm_ctrl_device_output *o)
{
	const struct irdm_device_config *dev = &c->cfg.device[i].dev;
	double qd[3], j[9];

	for (unsigned k = 0; k < 3; k++)
		if (irdm_velocity_update(&c->dev[i].vel[k], o->q_rad[k], &qd[k]))
			return IRDM_FAULT_ENCODER_NAN;
	irdm_device_jacobian(dev, o->q_rad, j);
	for (unsigned r = 0; r < 3; r++)
		o->vel_m_per_s[r] = j[3 * r] * qd[0] + j[3 * r + 1] * qd[1] + j[3 * r + 2] * qd[2];
	o->speed_m_per_s = irdm_v3_norm(o->vel_m_per_s);
	return isfinite(o->speed_m_per_s) ? 0 : IRDM_FAULT_ENCODER_NAN;
}

uint32_t ctrl_input(struct irdm_ctrl *c, unsigned i, const int32_t raw[3],
		    struct irdm_ctrl_device_output *o)
{
	const struct irdm_device_config *dev = &c->cfg.device[i].dev;
	int32_t counts[3];
	uint32_t f;

	c->dev[i].pose_ok = false;
	f = calibrated(c, i, raw, counts);
	if (f)
		return f;
	if (irdm_device_angles_from_counts(dev, counts, o->q_rad))
		return IRDM_FAULT_ENCODER_NAN;
	irdm_device_fk(dev, o->q_rad, o->tip_m);
	ctrl_to_object(c, i, o->tip_m, o->tip_obj_m);
	if (!irdm_v3_finite(o->tip_m) || !irdm_v3_finite(o->tip_obj_m))
		return IRDM_FAULT_ENCODER_NAN;
	f = velocity(c, i, o);
	if (f)
		return f;
	c->dev[i].pose_ok = true;
	return 0;
}
