/* SPDX-License-Identifier: MIT */
/*
 * The virtual user's hand on the arm of a simulated back-end ("sim",
 * "canemu"), private to sim/hal: the back-end pushes the arm at the start
 * of each read, so the loop above the HAL never sees the simulator.
 *
 * Time: the HAL's contract reads each device once a tick from the loop's
 * first tick on, so the n-th read since the hand took the arm (n from 0)
 * is tick n, at n x period of the loop's clock (irdm_clock_time_s(): the
 * same product, so the hand is where it was when the loop pushed it).
 */
#ifndef IRDM_SIM_HAL_SIM_HAND_H
#define IRDM_SIM_HAL_SIM_HAND_H

#include <stdint.h>

#include "irdm/board.h"
#include "irdm/hal/hal.h"
#include "irdm/sim/sim_device.h"
#include "irdm/sim/sim_user.h"

struct sim_hand {
	const struct irdm_sim_user *user; /* NULL: nobody holds the arm */
	const struct irdm_board *board;   /* its frames and period */
	unsigned hand;                    /* the script's hand, 0-based */
	uint64_t reads;                   /* reads since the hand took the arm */
};

void sim_hand_attach(struct sim_hand *h, const struct irdm_sim_user *u, unsigned hand,
		     const struct irdm_board *b);

/* A read's turn: the hand's force on the arm at this read's tick. */
void sim_hand_push(struct sim_hand *h, struct irdm_sim_device *arm);

/* The hand of an open canemu instance, or NULL (hal_canemu.c). */
struct sim_hand *irdm_hal_canemu_hand(struct irdm_hal_dev *dev);

#endif /* IRDM_SIM_HAL_SIM_HAND_H */
