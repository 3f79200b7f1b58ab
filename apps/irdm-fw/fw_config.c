/* SPDX-License-Identifier: MIT */
/*
 * The board, as the controller's configuration.  Each arm comes from the
 * board with its shoulder already placed in the shared device frame
 * (irdm_board_device()), so the controller's mount offset stays zero and
 * "each device's own frame" and the shared frame coincide.
 */
#include <string.h>

#include "irdm/contact.h"
#include "irdm/error.h"

#include "fw.h"

int fw_config_from_board(struct irdm_ctrl_config *c, const struct irdm_board *b)
{
	struct irdm_ctrl_limits *lim = &c->limits;
	int rc;

	irdm_ctrl_config_default(c);
	c->n_devices = b->devices;
	for (unsigned i = 0; i < b->devices; i++) {
		rc = irdm_board_device(b, i, &c->device[i].dev);
		if (rc)
			return rc;
		memset(c->device[i].mount_offset_m, 0, sizeof(c->device[i].mount_offset_m));
		memcpy(c->device[i].calib_q_rad, b->calibration_pose_rad,
		       sizeof(c->device[i].calib_q_rad));
	}
	/* the board places the object in the device frame (p_dev = R p_obj + o);
	 * the controller maps the other way: p_obj = R^T p_dev - R^T o */
	for (int r = 0; r < 3; r++)
		for (int k = 0; k < 3; k++)
			c->obj_rot[3 * r + k] = b->object_rotation[3 * k + r];
	irdm_board_device_to_object(b, (const double[3]){ 0, 0, 0 }, c->obj_offset_m);
	lim->max_force_n = b->device.max_force_n;
	memcpy(lim->workspace_min_m, b->workspace_min_m, sizeof(lim->workspace_min_m));
	memcpy(lim->workspace_max_m, b->workspace_max_m, sizeof(lim->workspace_max_m));
	lim->max_tip_speed_m_per_s = b->max_tip_speed_m_per_s;
	lim->overrun_fault_count = b->overrun_fault_count;
	lim->watchdog_us = b->watchdog_us;
	c->period_us = b->period_us;
	c->proxy.mu_s = b->friction_mu[0];
	c->proxy.mu_d = b->friction_mu[1];
	irdm_board_engine_config(b, &c->engine);
	c->engine.max_contacts = b->devices > c->engine.max_contacts ? b->devices : c->engine.max_contacts;
	c->engine.max_force_n = IRDM_CTRL_ENGINE_FORCE_GUARD * lim->max_force_n;
	return irdm_ctrl_config_check(c);
}

/*
 * irdm_ctrl_init() says only EINVAL: find which input it was.  The image
 * without a contact structure; else an encoder too fine for the velocity
 * filter (the board); else the controller's configuration (the board).
 */
const char *fw_ctrl_init_why(struct fw *fw)
{
	struct irdm_contact_mesh cm;
	struct irdm_velocity v;

	if (irdm_contact_mesh_init(&cm, fw->s->img)) {
		snprintf(fw->err, sizeof(fw->err), "%s: no contact structure (CONTACT_BVH): "
						   "precompute with --touch and --display covering it",
			 fw->args.image);
		return fw->err;
	}
	for (unsigned j = 0; j < 3; j++)
		if (irdm_velocity_init(&v, fw->board.period_us * 1e-6,
				       irdm_device_rad_per_count(&fw->board.device, j),
				       fw->ccfg.velocity_window)) {
			snprintf(fw->err, sizeof(fw->err), "%s: joint %u: counts_per_rev x "
							   "gear_ratio gives %g rad a count, which the velocity filter "
							   "cannot use",
				 fw->args.board, j + 1,
				 irdm_device_rad_per_count(&fw->board.device, j));
			return fw->err;
		}
	snprintf(fw->err, sizeof(fw->err), "%s: the controller refuses this board's arm, "
					   "limits or placement (irdm_ctrl_config_check)",
		 fw->args.board);
	return fw->err;
}
