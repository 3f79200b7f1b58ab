/* SPDX-License-Identifier: MIT */
/* The controller's steps, one file each (irdm/controller.h lists them). */
#ifndef IRDM_CONTROLLER_PRIV_H
#define IRDM_CONTROLLER_PRIV_H

#include "irdm/controller.h"

/* controller_input.c: counts -> angles -> tip -> velocity (and tip_obj);
 * returns the encoder fault bits of this sample. */
uint32_t ctrl_input(struct irdm_ctrl *c, unsigned i, const int32_t raw[3],
		    struct irdm_ctrl_device_output *o);
/* Offsets that make raw read as the calibration pose.
 * Return: IRDM_OK; IRDM_EFAULT if raw is not a number. */
int ctrl_calibrate(struct irdm_ctrl *c, unsigned i, const int32_t raw[3]);

/* controller_placement.c */
int ctrl_placement_check(const struct irdm_ctrl_config *cfg);
void ctrl_placement_init(struct irdm_ctrl *c);
void ctrl_to_object(const struct irdm_ctrl *c, unsigned i, const double tip_m[3],
		    double p_obj_m[3]);
void ctrl_force_to_device(const struct irdm_ctrl *c, unsigned i, const double f_obj_n[3],
			  double f_dev_n[3]);

/* controller_limits.c: fault conditions of the timing, and of device i's pose */
uint32_t ctrl_timing(struct irdm_ctrl *c, const struct irdm_ctrl_input *in,
		     struct irdm_ctrl_output *out);
uint32_t ctrl_pose_limits(const struct irdm_ctrl *c, const struct irdm_ctrl_device_output *o);

/* controller_contact.c: proxies (when `touch`) and the engine tick.
 * Return: IRDM_OK; IRDM_EFAULT if the contact step or the engine failed. */
int ctrl_contacts(struct irdm_ctrl *c, struct irdm_ctrl_output *out, bool touch);
/* End every contact and proxy (leaving ENABLED, reset). */
void ctrl_contacts_end(struct irdm_ctrl *c);

/* controller_force.c: device i's torque from its engine force; returns
 * IRDM_FAULT_CLAMP if the force or the torque was clamped. */
uint32_t ctrl_force(struct irdm_ctrl *c, unsigned i, struct irdm_ctrl_device_output *o);

#endif /* IRDM_CONTROLLER_PRIV_H */
