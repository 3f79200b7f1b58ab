/* SPDX-License-Identifier: MIT */
/* The virtual user's hand inside a simulated back-end (hal_sim_hand.h). */
#include "irdm/sim/sim_user_push.h"

#include "hal_sim_hand.h"

void sim_hand_attach(struct sim_hand *h, const struct irdm_sim_user *u, unsigned hand,
		     const struct irdm_board *b)
{
	h->user = u;
	h->board = b;
	h->hand = hand;
	h->reads = 0;
}

void sim_hand_push(struct sim_hand *h, struct irdm_sim_device *arm)
{
	uint32_t period_ns;

	if (!h->user)
		return;
	/* as the loop's clock: the tick's count times its period in ns */
	period_ns = h->board->period_us * 1000u;
	irdm_sim_user_push(h->user, h->hand, h->board, arm, (double)h->reads * period_ns * 1e-9);
	h->reads++;
}
