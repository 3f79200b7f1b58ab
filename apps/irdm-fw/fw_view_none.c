/* SPDX-License-Identifier: MIT */
/*
 * irdm-fw without the live view: the trimmed builds (CONFIG=...) leave the
 * web server and its library out; --view says so.
 */
#include <stdio.h>

#include "irdm/error.h"

#include "fw.h"

int fw_view_open(struct fw *fw)
{
	if (!fw->args.view)
		return IRDM_OK;
	snprintf(fw->err, sizeof(fw->err), "--view: this build has no view (the trimmed "
					   "configurations leave it out: build without CONFIG=)");
	return IRDM_ENOTSUP;
}

int fw_view_start(struct fw *fw)
{
	(void)fw;
	return IRDM_OK;
}

void fw_view_offer(struct fw_view *v, const double *pos_m, uint64_t tick)
{
	(void)v;
	(void)pos_m;
	(void)tick;
}

void fw_view_close(struct fw *fw)
{
	(void)fw;
}
