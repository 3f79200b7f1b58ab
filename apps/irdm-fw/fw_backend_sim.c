/* SPDX-License-Identifier: MIT */
/*
 * The "sim" back-end in irdm-fw: the simulated arm in process
 * (sim/hal/hal_sim.c); a virtual user (--user) can push its arm.
 * Built when the configuration has CONFIG_IRDM_HAL_SIM=y (fw_backends.c).
 */
#include "irdm/sim/hal_sim.h"

#include "fw.h"

const struct fw_backend fw_backend_sim = {
	.hal = &irdm_hal_sim_backend,
	.simulated_arm = true,
};
