/* SPDX-License-Identifier: MIT */
/*
 * Where CAN frames go and come from: a SocketCAN socket on a target, an
 * in-memory bus in tests (sim/can).  Two typed operations behind a
 * pointer, so the CANopen code above them is the same on both.  Neither
 * blocks: a frame is there or it is not.
 */
#ifndef IRDM_CAN_PORT_H
#define IRDM_CAN_PORT_H

#include "irdm/hal/canopen.h"

struct irdm_can_port_ops {
	/* Return: IRDM_OK; IRDM_EBUSY if the transmit queue is full; IRDM_EIO
	 * if the link is down (bus-off, interface gone). */
	int (*send)(void *ctx, const struct irdm_can_frame *f);
	/* Return: 1 with a frame; 0 if none is waiting; IRDM_EIO as above. */
	int (*recv)(void *ctx, struct irdm_can_frame *f);
};

struct irdm_can_port {
	const struct irdm_can_port_ops *ops;
	void *ctx;
};

static inline int irdm_can_send(const struct irdm_can_port *p, const struct irdm_can_frame *f)
{
	return p->ops->send(p->ctx, f);
}

static inline int irdm_can_recv(const struct irdm_can_port *p, struct irdm_can_frame *f)
{
	return p->ops->recv(p->ctx, f);
}

#endif /* IRDM_CAN_PORT_H */
