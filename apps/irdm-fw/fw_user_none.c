/* SPDX-License-Identifier: MIT */
/*
 * irdm-fw without a simulated back-end (neither CONFIG_IRDM_HAL_SIM nor
 * CONFIG_IRDM_HAL_CANEMU): no virtual user, and no simulator linked.  A
 * board whose back-end could carry one is refused before (fw_backends.c).
 */
#include <stdio.h>

#include "irdm/error.h"

#include "fw.h"

int fw_user_open(struct fw *fw)
{
	snprintf(fw->err, sizeof(fw->err), "--user %s: this irdm-fw has no simulated back-end "
					   "(CONFIG_IRDM_HAL_SIM, CONFIG_IRDM_HAL_CANEMU)",
		 fw->args.user);
	return IRDM_ENOTSUP;
}

double fw_user_end_s(const struct fw *fw)
{
	(void)fw;
	return 0.0;
}

int fw_user_attach(struct fw *fw, unsigned device)
{
	(void)fw;
	(void)device;
	return IRDM_OK;
}

void fw_user_free(struct fw *fw)
{
	(void)fw;
}
