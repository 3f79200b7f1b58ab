/* SPDX-License-Identifier: MIT */
/* The virtual user's hand on a simulated arm (irdm/sim_user_push.h). */
#include "irdm/device.h"
#include "irdm/sim/sim_user_push.h"

int irdm_sim_user_push(const struct irdm_sim_user *u, unsigned hand, const struct irdm_board *b,
		       struct irdm_sim_device *sim, double t_s)
{
	double q[3], qd[3], tip[3], vel[3], J[9], p_obj[3], v_obj[3], f_obj[3], f_dev[3];
	int rc;

	irdm_sim_device_state(sim, q, qd);
	irdm_device_fk(&sim->dev, q, tip);
	irdm_device_jacobian(&sim->dev, q, J);
	for (int r = 0; r < 3; r++)
		vel[r] = J[3 * r] * qd[0] + J[3 * r + 1] * qd[1] + J[3 * r + 2] * qd[2];
	irdm_board_device_to_object(b, tip, p_obj);
	irdm_board_vector_to_object(b, vel, v_obj);
	rc = irdm_sim_user_hand_force(u, hand, t_s, p_obj, v_obj, f_obj);
	irdm_board_vector_to_device(b, f_obj, f_dev);
	irdm_sim_device_set_hand_force(sim, f_dev);
	return rc;
}
