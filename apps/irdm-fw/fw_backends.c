/* SPDX-License-Identifier: MIT */
/*
 * The HAL back-ends irdm-fw knows, and which of them this build carries:
 * the build configuration's CONFIG_IRDM_HAL_<NAME>=y|n decides
 * (docs/build-config.md; -DIRDM_CONFIG_HAL_<NAME>=0|1, 1 when not given),
 * each built one from its own file (fw_backend_<name>.c).  main() registers
 * those with the HAL core's table (irdm/hal.h) and nothing else: a build
 * without the simulated back-ends does not link the simulator at all.
 */
#include <stdio.h>
#include <string.h>

#include "irdm/error.h"

#include "fw.h"

#ifndef IRDM_CONFIG_HAL_SIM
#define IRDM_CONFIG_HAL_SIM 1
#endif
#ifndef IRDM_CONFIG_HAL_CANEMU
#define IRDM_CONFIG_HAL_CANEMU 1
#endif
#ifndef IRDM_CONFIG_HAL_SOCKETCAN
#define IRDM_CONFIG_HAL_SOCKETCAN 1
#endif

#if IRDM_CONFIG_HAL_SIM
extern const struct fw_backend fw_backend_sim;
#define BUILT_SIM (&fw_backend_sim)
#else
#define BUILT_SIM NULL
#endif
#if IRDM_CONFIG_HAL_CANEMU
extern const struct fw_backend fw_backend_canemu;
#define BUILT_CANEMU (&fw_backend_canemu)
#else
#define BUILT_CANEMU NULL
#endif
#if IRDM_CONFIG_HAL_SOCKETCAN
extern const struct fw_backend fw_backend_socketcan;
#define BUILT_SOCKETCAN (&fw_backend_socketcan)
#else
#define BUILT_SOCKETCAN NULL
#endif

static const struct {
	const char *name;               /* as a board file names it */
	const char *config;             /* its build switch */
	const struct fw_backend *built; /* NULL: left out of this build */
} known[] = {
	{ "sim", "CONFIG_IRDM_HAL_SIM", BUILT_SIM },
	{ "canemu", "CONFIG_IRDM_HAL_CANEMU", BUILT_CANEMU },
	{ "socketcan", "CONFIG_IRDM_HAL_SOCKETCAN", BUILT_SOCKETCAN },
};

#define N_KNOWN (sizeof(known) / sizeof(known[0]))

static int known_index(const char *name)
{
	for (size_t i = 0; i < N_KNOWN; i++)
		if (!strcmp(name, known[i].name))
			return (int)i;
	return -1;
}

void fw_backends_register(void)
{
	for (size_t i = 0; i < N_KNOWN; i++)
		if (known[i].built)
			irdm_hal_register(known[i].built->hal);
}

const struct fw_backend *fw_backend_of(const char *name)
{
	int i = known_index(name);

	return i < 0 ? NULL : known[i].built;
}

int fw_backend_check_built(struct fw *fw)
{
	int i = known_index(fw->board.hal);

	if (i < 0 || known[i].built)
		return IRDM_OK;
	snprintf(fw->err, sizeof(fw->err), "%s:%u: hal = %s: not built in this irdm-fw (%s)",
		 fw->args.board, fw->board.hal_line, fw->board.hal, known[i].config);
	return IRDM_ENOTSUP;
}

const char *fw_user_hal_why(struct fw *fw)
{
	if (known_index(fw->board.hal) < 0)
		snprintf(fw->err, sizeof(fw->err), "%s: hal '%s': no such back-end in this build "
						   "(sim, canemu, socketcan)",
			 fw->args.board, fw->board.hal);
	else
		snprintf(fw->err, sizeof(fw->err), "a virtual user needs a back-end with a "
						   "simulated arm, and %s's hal '%s' has none (hal = sim or canemu)",
			 fw->args.board, fw->board.hal);
	return fw->err;
}
