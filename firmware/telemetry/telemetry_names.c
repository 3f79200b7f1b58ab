/* SPDX-License-Identifier: MIT */
/* Names for the numbers in a tick record (irdm/telemetry.h). */
#include "irdm/telemetry.h"

const char *irdm_telem_state_name(unsigned state)
{
	static const char *const names[IRDM_TELEM_N_STATES] = {
		"init",
		"ready",
		"enabled",
		"fault",
		"off",
	};

	return state < IRDM_TELEM_N_STATES ? names[state] : "?";
}

const char *irdm_telem_proxy_name(unsigned proxy)
{
	static const char *const names[IRDM_TELEM_N_PROXY] = { "free", "touch", "slide", "release" };

	return proxy < IRDM_TELEM_N_PROXY ? names[proxy] : "?";
}

const char *irdm_telem_fault_name(unsigned bit)
{
	static const char *const names[IRDM_TELEM_N_FAULTS] = {
		"clamp",
		"workspace",
		"velocity",
		"watchdog",
		"overrun",
		"encoder_nan",
		"encoder_range",
		"signal",
		"hal_read",
		"hal_write",
		"hal_fault",
		"engine",
	};

	return bit < IRDM_TELEM_N_FAULTS ? names[bit] : "?";
}
