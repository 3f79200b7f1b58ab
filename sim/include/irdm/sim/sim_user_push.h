/* SPDX-License-Identifier: MIT */
/*
 * The virtual user's hand on a simulated arm: its force from the arm's true
 * state (tip and tip velocity through the arm's kinematics, turned into the
 * object frame the script speaks), turned back into the device frame and
 * put on the arm.  Shared by the simulated HAL back-ends' reads
 * (sim/hal/hal_sim_hand.c: irdm-fw's arms) and the CAN drive emulator
 * (irdm-candrives: the arm behind its drives), so both push alike.
 * Pure arithmetic: no allocation, no system call.
 */
#ifndef IRDM_SIM_USER_PUSH_H
#define IRDM_SIM_USER_PUSH_H

#include "irdm/board.h"
#include "irdm/sim/sim_device.h"
#include "irdm/sim/sim_user.h"

/*
 * Hand `hand` of u pushes arm sim (placed by board b) at time t_s.
 * Return: as irdm_sim_user_hand_force() (the force is then zero).
 */
int irdm_sim_user_push(const struct irdm_sim_user *u, unsigned hand, const struct irdm_board *b,
		       struct irdm_sim_device *sim, double t_s);

#endif /* IRDM_SIM_USER_PUSH_H */
