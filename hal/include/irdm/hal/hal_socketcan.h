/* SPDX-License-Identifier: MIT */
/*
 * The "socketcan" HAL back-end: CiA 402 drives in cyclic synchronous
 * torque mode on a Linux SocketCAN interface, through the CANopen master
 * (irdm/hal_can.h says how the HAL ops map onto it; docs/canopen.md lists
 * the board's hal_options: iface=, nodes=, rated_torque_mnm=, ...).
 * Register it with irdm_hal_register(&irdm_hal_socketcan_backend).
 */
#ifndef IRDM_HAL_SOCKETCAN_H
#define IRDM_HAL_SOCKETCAN_H

#include "irdm/hal/can_master.h"
#include "irdm/hal/hal.h"
#include "irdm/hal/socketcan.h"

extern const struct irdm_hal_backend irdm_hal_socketcan_backend;

/*
 * The port's latched flags into the master, after each receive: bus-off
 * loses the link (every axis off, "CAN link: bus-off ..."); error passive
 * alone does not (frames still pass: the TPDO and heartbeat checks judge
 * what it costs).
 */
void irdm_hal_socketcan_judge(const struct irdm_socketcan *s, struct irdm_can_master *m);

#endif /* IRDM_HAL_SOCKETCAN_H */
