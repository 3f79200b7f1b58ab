/* SPDX-License-Identifier: MIT */
/* The "canemu" HAL back-end (irdm/hal_canemu.h). */
#include <stdio.h>

#include "irdm/error.h"
#include "irdm/hal/hal_can.h"
#include "irdm/sim/hal_canemu.h"

#include "hal_sim_hand.h"

struct canemu_data {
	struct irdm_hal_can can; /* first: the shared code's view */
	struct irdm_can_membus bus;
	struct irdm_can_drives drives;
	bool emcy_done;       /* the injected emcy_at fault happened */
	struct sim_hand hand; /* the virtual user's, if one holds the arm */
};

static struct canemu_data *data_of(struct irdm_hal_dev *dev)
{
	return dev->data;
}

static int link_open(struct irdm_hal_dev *dev, struct irdm_can_port *port, char *err,
		     size_t errlen)
{
	struct canemu_data *d = data_of(dev);
	const struct irdm_hal_can_opts *o = &d->can.opts;
	struct irdm_can_port drives_port;
	struct irdm_sim_params p;

	for (unsigned k = 1; k < o->n_nodes; k++)
		if (o->nodes[k] != o->nodes[0] + k) {
			snprintf(err, errlen, "hal_options: nodes: the emulator's nodes are "
					      "consecutive (e.g. 1,2,3)");
			return IRDM_EINVAL;
		}
	irdm_can_membus_init(&d->bus);
	irdm_can_membus_port(&d->bus, port);
	irdm_can_membus_port(&d->bus, &drives_port);
	irdm_sim_params_default(&p);
	p.substeps = o->substeps;
	if (irdm_can_drives_init(&d->drives, &drives_port, dev->config->device, &p, o->n_nodes,
				 o->nodes[0], dev->config->period_s) != IRDM_OK) {
		snprintf(err, errlen, "canemu: the emulated arm refuses this board's arm");
		return IRDM_EINVAL;
	}
	/* as the arm of irdm-candrives: at rest in its dock until the first
	 * torque, not sagging through the start-up's disabled SYNCs */
	d->drives.docked = true;
	return IRDM_OK;
}

/* The emulator's turn: it answers what the master just sent. */
static void link_pump(struct irdm_hal_dev *dev)
{
	struct canemu_data *d = data_of(dev);
	const struct irdm_hal_can_opts *o = &d->can.opts;

	irdm_can_drives_poll(&d->drives);
	if (o->emcy_drive && o->emcy_drive <= d->drives.n && !d->emcy_done &&
	    d->drives.now_us >= 1000ull * o->emcy_at_ms) {
		irdm_can_drives_fault(&d->drives, o->emcy_drive - 1, 0x2310);
		d->emcy_done = true;
	}
}

static void link_idle(void *ctx)
{
	link_pump(ctx);
}

static void link_close(struct irdm_hal_dev *dev)
{
	(void)dev; /* memory only: nothing to release */
}

static const struct irdm_hal_can_link canemu_link = {
	.open = link_open,
	.pump = link_pump,
	.idle = link_idle,
	.check = NULL,
	.close = link_close,
};

/*
 * From a signal handler: the in-memory bus is not safe to touch there (the
 * handler may have interrupted a send), so the emulated drives drop their
 * set-points and the arm its torque directly, with plain stores.
 */
static int canemu_emergency_off(struct irdm_hal_dev *dev)
{
	struct canemu_data *d = data_of(dev);

	for (unsigned k = 0; k < d->drives.n; k++) {
		d->drives.d[k].rpdo_cw = 0;
		d->drives.d[k].rpdo_torque_permille = 0;
	}
	irdm_sim_device_torque_off(&d->drives.arm);
	return IRDM_OK;
}

static int canemu_open(struct irdm_hal_dev *dev)
{
	data_of(dev)->emcy_done = false;
	data_of(dev)->hand.user = NULL;
	return irdm_hal_can_open(dev, &canemu_link, IRDM_HAL_CAN_SUBSTEPS | IRDM_HAL_CAN_EMCY_AT);
}

/* The hand first: the SYNC this read may send steps the arm under it. */
static int canemu_read(struct irdm_hal_dev *dev, struct irdm_hal_joint_state *st)
{
	struct canemu_data *d = data_of(dev);

	if (d->can.state != HAL_CAN_CLOSED)
		sim_hand_push(&d->hand, &d->drives.arm);
	return irdm_hal_can_read(dev, st);
}

static const struct irdm_hal_ops canemu_ops = {
	.open = canemu_open,
	.start = irdm_hal_can_start,
	.read = canemu_read,
	.write = irdm_hal_can_write,
	.safe_off = irdm_hal_can_safe_off,
	.poll = irdm_hal_can_poll,
	.close = irdm_hal_can_close,
	.emergency_off = canemu_emergency_off,
};

static int canemu_check_options(const char *options, const char *where, char *err,
				size_t errlen)
{
	return irdm_hal_can_check(options, IRDM_HAL_CAN_SUBSTEPS | IRDM_HAL_CAN_EMCY_AT, where, err,
				  errlen);
}

const struct irdm_hal_backend irdm_hal_canemu_backend = {
	.name = "canemu",
	.ops = &canemu_ops,
	.data_size = sizeof(struct canemu_data),
	.options = &irdm_hal_canemu_options,
	.check_options = canemu_check_options,
};

static struct canemu_data *open_canemu(struct irdm_hal_dev *dev)
{
	return dev && dev->backend == &irdm_hal_canemu_backend &&
			       data_of(dev)->can.state != HAL_CAN_CLOSED ?
		       data_of(dev) :
		       NULL;
}

struct irdm_can_drives *irdm_hal_canemu_drives(struct irdm_hal_dev *dev)
{
	struct canemu_data *d = open_canemu(dev);

	return d ? &d->drives : NULL;
}

struct irdm_can_membus *irdm_hal_canemu_bus(struct irdm_hal_dev *dev)
{
	struct canemu_data *d = open_canemu(dev);

	return d ? &d->bus : NULL;
}

struct sim_hand *irdm_hal_canemu_hand(struct irdm_hal_dev *dev)
{
	struct canemu_data *d = open_canemu(dev);

	return d ? &d->hand : NULL;
}
