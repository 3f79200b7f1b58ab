/* SPDX-License-Identifier: MIT */
/* The in-memory CAN bus (irdm/can_membus.h). */
#include <string.h>

#include "irdm/sim/can_membus.h"
#include "irdm/error.h"

static int membus_send(void *ctx, const struct irdm_can_frame *f)
{
	struct irdm_can_endpoint *ep = ctx;
	struct irdm_can_membus *bus = ep->bus;
	unsigned slot = (unsigned)(bus->sent % IRDM_CAN_MEMBUS_FRAMES);

	if (f->dlc > 8 || f->id > 0x7FF)
		return IRDM_EIO; /* a controller would not send it */
	bus->ring[slot] = *f;
	bus->from[slot] = ep->index;
	bus->sent++;
	if (bus->tap)
		bus->tap(bus->tap_ctx, f, ep->index);
	return IRDM_OK;
}

static int membus_recv(void *ctx, struct irdm_can_frame *f)
{
	struct irdm_can_endpoint *ep = ctx;
	struct irdm_can_membus *bus = ep->bus;

	if (bus->sent - ep->next > IRDM_CAN_MEMBUS_FRAMES) {
		ep->lost += bus->sent - ep->next - IRDM_CAN_MEMBUS_FRAMES;
		ep->next = bus->sent - IRDM_CAN_MEMBUS_FRAMES;
	}
	while (ep->next < bus->sent) {
		unsigned slot = (unsigned)(ep->next++ % IRDM_CAN_MEMBUS_FRAMES);

		if (bus->from[slot] == ep->index)
			continue; /* a node does not hear itself */
		*f = bus->ring[slot];
		return 1;
	}
	return 0;
}

static const struct irdm_can_port_ops membus_ops = { membus_send, membus_recv };

void irdm_can_membus_init(struct irdm_can_membus *bus)
{
	memset(bus, 0, sizeof(*bus));
}

int irdm_can_membus_port(struct irdm_can_membus *bus, struct irdm_can_port *port)
{
	struct irdm_can_endpoint *ep;

	if (bus->n_endpoints == IRDM_CAN_MEMBUS_ENDPOINTS)
		return IRDM_ENOMEM;
	ep = &bus->ep[bus->n_endpoints];
	ep->bus = bus;
	ep->index = bus->n_endpoints++;
	ep->next = bus->sent;
	port->ops = &membus_ops;
	port->ctx = ep;
	return IRDM_OK;
}
