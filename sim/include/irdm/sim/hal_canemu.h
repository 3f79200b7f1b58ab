/* SPDX-License-Identifier: MIT */
/*
 * The "canemu" HAL back-end: the CANopen master of the "socketcan"
 * back-end (irdm/hal_can.h, the same code) on an in-memory CAN bus
 * (irdm/can_membus.h) with the CiA 402 drive emulator (irdm/can_drives.h)
 * on it, one emulated drive per joint of the simulated arm.  The emulator
 * runs inside the HAL ops, right after the master sends (its turn): a SYNC
 * steps the arm one period, so the whole bus runs in virtual time on a
 * host without CAN, and makes no system call and no allocation.
 * Options: irdm_hal_canemu_options (docs/hal-options.md): the "socketcan"
 * back-end's without iface, plus substeps=N (the arm's integration steps a
 * period) and emcy_at=D:MS (drive D raises EMCY 0x2310 and faults at MS ms
 * of emulated time: a fault run of irdm-fw).  The nodes must be
 * consecutive (the emulator numbers its drives from the first).
 * Register it with irdm_hal_register(&irdm_hal_canemu_backend).
 */
#ifndef IRDM_HAL_CANEMU_H
#define IRDM_HAL_CANEMU_H

#include "irdm/sim/can_drives.h"
#include "irdm/sim/can_membus.h"
#include "irdm/hal/hal.h"
#include "irdm/sim/sim_device.h"

extern const struct irdm_hal_backend irdm_hal_canemu_backend;

/* The emulated drives (tests inject their faults) and the bus (its tap),
 * of an open canemu instance; NULL otherwise. */
struct irdm_can_drives *irdm_hal_canemu_drives(struct irdm_hal_dev *dev);
struct irdm_can_membus *irdm_hal_canemu_bus(struct irdm_hal_dev *dev);

#endif /* IRDM_HAL_CANEMU_H */
