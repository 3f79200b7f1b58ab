/* SPDX-License-Identifier: MIT */
/* CAN tests: drain a port, counting one identifier (can_drain.h). */
#include "can_drain.h"

unsigned can_drain_count(const struct irdm_can_port *port, uint32_t id)
{
	struct irdm_can_frame f;
	unsigned n = 0;

	while (irdm_can_recv(port, &f) == 1)
		n += f.id == id;
	return n;
}
