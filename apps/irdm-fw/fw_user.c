/* SPDX-License-Identifier: MIT */
/*
 * The virtual user (--user, irdm/sim_user.h): its script, read and met
 * with the board before any device opens, then handed to the simulated
 * back-end of each device it holds, whose reads push the arm
 * (irdm_hal_sim_attach_user()): the loop only reads the HAL.  Built with a
 * simulated back-end (CONFIG_IRDM_HAL_SIM or CONFIG_IRDM_HAL_CANEMU);
 * fw_user_none.c otherwise.
 */
#include <stdio.h>
#include <stdlib.h>

#include "irdm/error.h"
#include "irdm/sim/hal_sim.h"
#include "irdm/sim/sim_user.h"

#include "fw.h"

/*
 * The script meets the board: one device per hand, and each hand's 'home'
 * is where its tip rests at the start, the calibration pose.
 */
static int meet_board(struct fw *fw)
{
	if (fw->user->hands > fw->board.devices) {
		snprintf(fw->err, sizeof(fw->err), "--user %s: the script uses %u hands, the board "
						   "has %u device%s",
			 fw->args.user, fw->user->hands, fw->board.devices,
			 fw->board.devices == 1 ? "" : "s");
		return IRDM_EINVAL;
	}
	for (unsigned h = 0; h < fw->user->hands; h++) {
		struct irdm_device_config dev;
		double tip[3], home[3];
		int rc;

		irdm_board_device(&fw->board, h, &dev);
		irdm_device_fk(&dev, fw->board.calibration_pose_rad, tip);
		irdm_board_device_to_object(&fw->board, tip, home);
		rc = irdm_sim_user_start(fw->user, h, home, fw->args.user, fw->err,
					 sizeof(fw->err));
		if (rc)
			return rc;
	}
	return IRDM_OK;
}

int fw_user_open(struct fw *fw)
{
	int rc;

	fw->user = calloc(1, sizeof(*fw->user));
	if (!fw->user) {
		snprintf(fw->err, sizeof(fw->err), "out of memory for the user script");
		return IRDM_ENOMEM;
	}
	rc = irdm_sim_user_load(fw->user, fw->args.user, fw->err, sizeof(fw->err));
	return rc ? rc : meet_board(fw);
}

double fw_user_end_s(const struct fw *fw)
{
	return fw->user->end_s;
}

int fw_user_attach(struct fw *fw, unsigned device)
{
	if (!fw->user || device >= fw->user->hands)
		return IRDM_OK;
	return irdm_hal_sim_attach_user(&fw->hal[device], fw->user, device, &fw->board);
}

void fw_user_free(struct fw *fw)
{
	free(fw->user);
	fw->user = NULL;
}
