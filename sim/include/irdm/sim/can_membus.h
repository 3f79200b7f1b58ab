/* SPDX-License-Identifier: MIT */
/*
 * A CAN bus in memory (tests, the in-process drive emulator): every frame
 * sent by one endpoint reaches every other endpoint, in order, as on a
 * wire.  Fixed size; a reader that falls IRDM_CAN_MEMBUS_FRAMES behind
 * loses the oldest frames (counted), as a socket's full receive queue does.
 * A log of every frame (for the tests' candump-like checks) is optional.
 */
#ifndef IRDM_CAN_MEMBUS_H
#define IRDM_CAN_MEMBUS_H

#include <stdint.h>

#include "irdm/hal/can_port.h"

#define IRDM_CAN_MEMBUS_FRAMES 1024
#define IRDM_CAN_MEMBUS_ENDPOINTS 4

struct irdm_can_membus;

struct irdm_can_endpoint {
	struct irdm_can_membus *bus;
	unsigned index;
	uint64_t next; /* the next frame this endpoint reads */
	uint64_t lost; /* frames overwritten before it read them */
};

struct irdm_can_membus {
	struct irdm_can_frame ring[IRDM_CAN_MEMBUS_FRAMES];
	unsigned from[IRDM_CAN_MEMBUS_FRAMES]; /* sender endpoint of each */
	uint64_t sent;                         /* frames ever sent */
	struct irdm_can_endpoint ep[IRDM_CAN_MEMBUS_ENDPOINTS];
	unsigned n_endpoints;
	void (*tap)(void *ctx, const struct irdm_can_frame *f, unsigned from); /* or NULL */
	void *tap_ctx;
};

void irdm_can_membus_init(struct irdm_can_membus *bus);

/* A new endpoint as a port.  Return: IRDM_OK; IRDM_ENOMEM if all are taken. */
int irdm_can_membus_port(struct irdm_can_membus *bus, struct irdm_can_port *port);

#endif /* IRDM_CAN_MEMBUS_H */
