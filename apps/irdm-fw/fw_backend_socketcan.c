/* SPDX-License-Identifier: MIT */
/*
 * The "socketcan" back-end in irdm-fw: the CAN master on a SocketCAN
 * interface (hal/can/hal_socketcan.c), for a real arm.
 * Built when the configuration has CONFIG_IRDM_HAL_SOCKETCAN=y (fw_backends.c).
 */
#include "irdm/hal/hal_socketcan.h"

#include "fw.h"

const struct fw_backend fw_backend_socketcan = {
	.hal = &irdm_hal_socketcan_backend,
	.simulated_arm = false,
};
