/* SPDX-License-Identifier: MIT */
/*
 * The "socketcan" HAL back-end: the CANopen master (irdm/hal_can.h) on a
 * SocketCAN interface (irdm/socketcan.h).  Set-up waits by sleeping one
 * period; bus-off latched by the port loses the link (every axis off);
 * error passive is counted by the port and left to the TPDO and heartbeat
 * checks, which see whatever it costs.
 */
#include <time.h>

#include "irdm/error.h"
#include "irdm/hal/hal_can.h"
#include "irdm/hal/hal_socketcan.h"
#include "irdm/hal/socketcan.h"

struct socketcan_data {
	struct irdm_hal_can can; /* first: the shared code's view */
	struct irdm_socketcan sock;
};

static struct socketcan_data *data_of(struct irdm_hal_dev *dev)
{
	return dev->data;
}

static int link_open(struct irdm_hal_dev *dev, struct irdm_can_port *port, char *err,
		     size_t errlen)
{
	struct socketcan_data *d = data_of(dev);

	return irdm_socketcan_open(&d->sock, d->can.opts.iface, port, err, errlen);
}

/* Set-up only (never in the tick): one period's sleep. */
static void link_idle(void *ctx)
{
	struct irdm_hal_dev *dev = ctx;
	uint32_t us = data_of(dev)->can.m.cfg.period_us;
	struct timespec ts = { us / 1000000u, (long)(us % 1000000u) * 1000L };

	nanosleep(&ts, NULL);
}

void irdm_hal_socketcan_judge(const struct irdm_socketcan *s, struct irdm_can_master *m)
{
	if (s->bus_off)
		irdm_can_master_lose(m, -1, "bus-off (the controller left the bus)");
}

static void link_check(struct irdm_hal_dev *dev, struct irdm_can_master *m)
{
	irdm_hal_socketcan_judge(&data_of(dev)->sock, m);
}

static void link_close(struct irdm_hal_dev *dev)
{
	irdm_socketcan_close(&data_of(dev)->sock);
}

static const struct irdm_hal_can_link socketcan_link = {
	.open = link_open,
	.pump = NULL, /* a wire: the drives answer on their own */
	.idle = link_idle,
	.check = link_check,
	.close = link_close,
};

static int socketcan_open(struct irdm_hal_dev *dev)
{
	data_of(dev)->sock.fd = -1;
	return irdm_hal_can_open(dev, &socketcan_link, IRDM_HAL_CAN_IFACE);
}

static const struct irdm_hal_ops socketcan_ops = IRDM_HAL_CAN_OPS(socketcan_open, irdm_hal_can_emergency_off);

static int socketcan_check_options(const char *options, const char *where, char *err,
				   size_t errlen)
{
	return irdm_hal_can_check(options, IRDM_HAL_CAN_IFACE, where, err, errlen);
}

const struct irdm_hal_backend irdm_hal_socketcan_backend = {
	.name = "socketcan",
	.ops = &socketcan_ops,
	.data_size = sizeof(struct socketcan_data),
	.options = &irdm_hal_socketcan_options,
	.check_options = socketcan_check_options,
};
