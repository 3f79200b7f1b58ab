/* SPDX-License-Identifier: MIT */
/*
 * The "canemu" back-end in irdm-fw: the CAN master on an in-memory bus
 * with the emulated CiA 402 drives (sim/hal/hal_canemu.c); a virtual user
 * (--user) can push the arm behind them.
 * Built when the configuration has CONFIG_IRDM_HAL_CANEMU=y (fw_backends.c).
 */
#include "irdm/sim/hal_canemu.h"

#include "fw.h"

const struct fw_backend fw_backend_canemu = {
	.hal = &irdm_hal_canemu_backend,
	.simulated_arm = true,
};
