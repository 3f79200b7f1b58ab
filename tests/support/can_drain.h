/* SPDX-License-Identifier: MIT */
/* CAN tests: drain a port, counting one identifier. */
#ifndef IRDM_TESTS_CAN_DRAIN_H
#define IRDM_TESTS_CAN_DRAIN_H

#include <stdint.h>

#include "irdm/hal/can_port.h"

/* Receive everything waiting on port; how many frames had identifier id. */
unsigned can_drain_count(const struct irdm_can_port *port, uint32_t id);

#endif
