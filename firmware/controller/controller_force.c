/* SPDX-License-Identifier: MIT */
/*
 * Step 7 of the tick: the engine's force on the object -> the force on the
 * tip (its negative, in the device frame) -> clamped to max_force_n keeping
 * its direction -> joint torques by J^T -> plus the arm's gravity torque ->
 * saturated by scaling (irdm_device_torque_saturate(): the direction of the
 * whole torque is kept, so the arm is never pushed sideways by a clip).
 */
#include <math.h>

#include "controller_priv.h"
#include "irdm/vec3.h"

uint32_t ctrl_force(struct irdm_ctrl *c, unsigned i, struct irdm_ctrl_device_output *o)
{
	const struct irdm_device_config *dev = &c->cfg.device[i].dev;
	double f, s_force = 1, s_torque = 1, tau[3], g[3];
	uint32_t flags = 0;

	ctrl_force_to_device(c, i, o->force_obj_n, o->force_n);
	f = irdm_v3_norm(o->force_n);
	if (f > c->cfg.limits.max_force_n) {
		s_force = c->cfg.limits.max_force_n / f;
		irdm_v3_scale(o->force_n, s_force, o->force_n);
		flags |= IRDM_FAULT_CLAMP;
	}
	irdm_device_force_to_torque(dev, o->q_rad, o->force_n, tau);
	irdm_device_gravity_torque(dev, o->q_rad, g);
	irdm_v3_add(tau, tau, g);
	/* a non-finite torque comes back zero; the engine faults first on a
	 * non-finite force, so this is a last guard */
	if (irdm_device_torque_saturate(dev, tau, o->torque_nm, &s_torque))
		return IRDM_FAULT_ENGINE;
	if (s_torque < 1)
		flags |= IRDM_FAULT_CLAMP;
	o->scale = s_force * s_torque;
	return flags;
}
