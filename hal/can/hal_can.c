/* SPDX-License-Identifier: MIT */
/* The HAL ops on the CANopen master, shared by the CAN back-ends (irdm/hal_can.h). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/hal/hal_can.h"

static struct irdm_hal_can *can_of(struct irdm_hal_dev *dev)
{
	return dev->data;
}

static void pump(struct irdm_hal_dev *dev)
{
	struct irdm_hal_can *c = can_of(dev);

	if (c->link->pump)
		c->link->pump(dev);
}

static void say(struct irdm_hal_dev *dev, const char *line)
{
	snprintf(dev->why, sizeof(dev->why), "%s", line);
}

/* The master's configuration from the options, the arm and the period. */
static int master_cfg(struct irdm_hal_dev *dev, const struct irdm_hal_can_opts *o,
		      struct irdm_can_master_cfg *mc)
{
	const struct irdm_hal_config *cfg = dev->config;
	uint32_t period_us = (uint32_t)lround(cfg->period_s * 1e6);

	if (o->n_nodes != IRDM_HAL_JOINTS) {
		snprintf(dev->why, sizeof(dev->why),
			 "hal_options: nodes: %u node(s) given, the arm has %d joints", o->n_nodes,
			 IRDM_HAL_JOINTS);
		return IRDM_EINVAL;
	}
	memset(mc, 0, sizeof(*mc));
	mc->n_axes = o->n_nodes;
	for (unsigned k = 0; k < o->n_nodes; k++)
		mc->axis[k] = (struct irdm_can_axis_cfg){ o->nodes[k], o->rated_torque_mnm[k],
							  cfg->device->gear_ratio[k] };
	mc->period_us = period_us;
	mc->bitrate = o->bitrate;
	mc->sync_counter = o->sync_counter;
	mc->heartbeat_ms = o->heartbeat_ms;
	mc->heartbeat_timeout_ms = o->heartbeat_timeout_ms;
	mc->tpdo_missing_periods = o->tpdo_missing_periods;
	mc->master_node = o->master_node;
	/* the drive's deadline: the option, else three periods in whole ms */
	mc->rpdo_timeout_ms = (uint16_t)(o->rpdo_timeout_ms ? o->rpdo_timeout_ms : (3u * period_us + 999u) / 1000u);
	mc->sdo_timeout_polls = (unsigned)((o->sdo_timeout_ms * 1000ull + period_us - 1) / period_us);
	mc->idle = can_of(dev)->link->idle;
	mc->idle_ctx = dev;
	return IRDM_OK;
}

int irdm_hal_can_open(struct irdm_hal_dev *dev, const struct irdm_hal_can_link *link,
		      unsigned extra)
{
	struct irdm_hal_can *c = can_of(dev);
	const struct irdm_hal_config *cfg = dev->config;
	struct irdm_can_master_cfg mc;
	struct irdm_can_port port;
	int rc;

	if (c->state != HAL_CAN_CLOSED)
		return IRDM_EBUSY;
	if (!cfg->device || !(isfinite(cfg->period_s) && cfg->period_s >= 1e-4 && cfg->period_s <= 1)) {
		say(dev, "period: 100 us to 1 s, and an arm");
		return IRDM_EINVAL;
	}
	c->link = link;
	rc = irdm_hal_can_parse(cfg->options, extra, "hal_options", &c->opts, dev->why,
				sizeof(dev->why));
	if (!rc)
		rc = master_cfg(dev, &c->opts, &mc);
	if (!rc)
		rc = irdm_can_master_check(&mc, dev->why, sizeof(dev->why));
	if (rc)
		return rc;
	irdm_can_master_load_line(&mc, dev->info, sizeof(dev->info));
	rc = link->open(dev, &port, dev->why, sizeof(dev->why));
	if (rc)
		return rc;
	rc = irdm_can_master_init(&c->m, &port, &mc, dev->why, sizeof(dev->why));
	if (rc) {
		link->close(dev);
		return rc;
	}
	for (unsigned k = 0; k < c->m.cfg.n_axes; k++) {
		size_t used = strlen(dev->info);

		dev->info[used] = '\n';
		irdm_can_master_identity_line(&c->m, k, dev->info + used + 1,
					      sizeof(dev->info) - used - 1);
	}
	c->written = false;
	c->seq = 0;
	c->state = HAL_CAN_OPEN;
	return IRDM_OK;
}

/* Faulted: the master already sent the torque off; the reason to the caller. */
static int faulted(struct irdm_hal_dev *dev)
{
	say(dev, can_of(dev)->m.why);
	return IRDM_EHW;
}

/* The link's flags, then the master's verdict on this period. */
static int receive(struct irdm_hal_dev *dev)
{
	struct irdm_hal_can *c = can_of(dev);
	int rc = irdm_can_master_receive(&c->m);

	if (c->link->check)
		c->link->check(dev, &c->m);
	pump(dev); /* a fault just found sent the torque off: heard now */
	return c->m.faulted ? faulted(dev) : rc;
}

static void send_hold(struct irdm_hal_dev *dev)
{
	(void)irdm_can_master_send(&can_of(dev)->m, NULL);
	pump(dev);
}

/*
 * The cycle with every drive held at disable voltage until each has
 * answered IRDM_HAL_CAN_STEADY_PERIODS SYNCs in a row: the drives'
 * deadlines (RPDO, the master's heartbeat) start with this exchange, and
 * the enable sequence comes only once it runs steadily.  Return: the
 * periods it took, or periods + 1 if it never did (or a fault).
 */
static unsigned steady(struct irdm_hal_dev *dev, unsigned periods)
{
	struct irdm_hal_can *c = can_of(dev);
	unsigned p, run = 0;

	irdm_can_master_enable(&c->m, false);
	for (p = 0; p < periods && run < IRDM_HAL_CAN_STEADY_PERIODS; p++) {
		int rc;

		send_hold(dev);
		c->link->idle(dev);
		rc = receive(dev);
		if (rc == IRDM_EHW)
			return periods + 1;
		run = rc == IRDM_OK ? run + 1 : 0;
	}
	return run < IRDM_HAL_CAN_STEADY_PERIODS ? periods + 1 : p;
}

int irdm_hal_can_start(struct irdm_hal_dev *dev)
{
	struct irdm_hal_can *c = can_of(dev);
	unsigned periods = (unsigned)((c->opts.enable_timeout_ms * 1000ull + c->m.cfg.period_us - 1) /
				      c->m.cfg.period_us);
	unsigned used;
	int k;

	if (c->state == HAL_CAN_CLOSED)
		return IRDM_EINVAL;
	if (c->m.faulted)
		return faulted(dev);
	used = steady(dev, periods);
	if (c->m.faulted)
		return faulted(dev);
	if (used > periods) {
		k = irdm_can_master_first_stale(&c->m);
		if (k >= 0)
			snprintf(dev->why, sizeof(dev->why), "drive %d (node %u): no TPDO1 to the "
							     "disabled SYNCs before enabling (%u ms)",
				 k + 1,
				 c->m.cfg.axis[k].node, (unsigned)c->opts.enable_timeout_ms);
		else
			snprintf(dev->why, sizeof(dev->why), "CAN: fewer than %d SYNCs answered in "
							     "a row before enabling, within %u ms",
				 IRDM_HAL_CAN_STEADY_PERIODS,
				 (unsigned)c->opts.enable_timeout_ms);
		irdm_can_master_safe_off(&c->m);
		pump(dev);
		return IRDM_ETIMEDOUT;
	}
	irdm_can_master_enable(&c->m, true);
	for (unsigned p = used; p < periods && !irdm_can_master_all_enabled(&c->m); p++) {
		send_hold(dev);
		c->link->idle(dev);
		if (receive(dev) == IRDM_EHW)
			return IRDM_EHW;
	}
	k = irdm_can_master_first_not_enabled(&c->m);
	if (k >= 0) {
		irdm_can_master_safe_off(&c->m);
		pump(dev);
		snprintf(dev->why, sizeof(dev->why),
			 "drive %d (node %u): not operation enabled after %u ms (%s)", k + 1,
			 c->m.cfg.axis[k].node, (unsigned)c->opts.enable_timeout_ms,
			 irdm_cia402_name(c->m.ax[k].state));
		return IRDM_ETIMEDOUT;
	}
	send_hold(dev); /* the first read's TPDO is on its way */
	c->written = true;
	c->state = HAL_CAN_RUNNING;
	return IRDM_OK;
}

int irdm_hal_can_read(struct irdm_hal_dev *dev, struct irdm_hal_joint_state *st)
{
	struct irdm_hal_can *c = can_of(dev);
	int rc;

	if (c->state == HAL_CAN_CLOSED)
		return IRDM_EINVAL;
	if (!c->written)
		send_hold(dev); /* nobody wrote last period: its SYNC, zero torque */
	c->written = false;
	rc = receive(dev);
	/*
	 * A drive without a fresh TPDO1: on a wire the answer to a SYNC just
	 * sent (the hold above) or one a little late is not here yet.  The
	 * master loses the drive after tpdo_missing_periods (EHW above);
	 * until then the latest counts stand, as the option says.
	 */
	if (rc == IRDM_ETIMEDOUT)
		rc = IRDM_OK;
	if (rc)
		return rc;
	dev->why[0] = '\0'; /* a late TPDO's line is not the reason of a later fault */
	for (unsigned a = 0; a < IRDM_HAL_JOINTS; a++)
		st->counts[a] = c->m.ax[a].counts;
	st->seq = ++c->seq;
	return IRDM_OK;
}

int irdm_hal_can_write(struct irdm_hal_dev *dev, const double tau_nm[IRDM_HAL_JOINTS])
{
	struct irdm_hal_can *c = can_of(dev);
	double tau[IRDM_HAL_JOINTS];
	int rc = IRDM_OK;

	if (c->state != HAL_CAN_RUNNING)
		return IRDM_EINVAL;
	if (c->m.faulted) {
		(void)irdm_can_master_send(&c->m, NULL); /* off again, with the SYNC */
		pump(dev);
		c->written = true;
		return faulted(dev);
	}
	for (unsigned a = 0; a < IRDM_HAL_JOINTS; a++) {
		tau[a] = isfinite(tau_nm[a]) ? tau_nm[a] : 0.0;
		if (!isfinite(tau_nm[a]))
			rc = IRDM_EFAULT;
	}
	if (irdm_can_master_send(&c->m, tau) == IRDM_EHW)
		rc = faulted(dev);
	pump(dev);
	c->written = true;
	return rc;
}

int irdm_hal_can_safe_off(struct irdm_hal_dev *dev)
{
	struct irdm_hal_can *c = can_of(dev);
	int rc;

	if (c->state == HAL_CAN_CLOSED)
		return IRDM_OK; /* nothing open: nothing can apply torque */
	rc = irdm_can_master_safe_off(&c->m);
	pump(dev);
	c->written = true;
	if (c->state == HAL_CAN_RUNNING)
		c->state = HAL_CAN_OFF;
	if (rc)
		say(dev, "CAN link: torque off not sent (link down): cut the power");
	return rc;
}

int irdm_hal_can_poll(struct irdm_hal_dev *dev, uint32_t *faults)
{
	struct irdm_hal_can *c = can_of(dev);

	if (c->state == HAL_CAN_CLOSED)
		return IRDM_EINVAL;
	*faults = 0;
	if (!c->m.faulted)
		return IRDM_OK;
	*faults = c->m.link_lost ? IRDM_HAL_FAULT_LINK : IRDM_HAL_FAULT_DRIVE;
	return faulted(dev);
}

void irdm_hal_can_close(struct irdm_hal_dev *dev)
{
	struct irdm_hal_can *c = can_of(dev);

	if (c->state == HAL_CAN_CLOSED)
		return;
	irdm_can_master_safe_off(&c->m);
	irdm_can_master_stop(&c->m);
	pump(dev);
	c->link->close(dev);
	c->state = HAL_CAN_CLOSED;
}

int irdm_hal_can_emergency_off(struct irdm_hal_dev *dev)
{
	struct irdm_hal_can *c = can_of(dev);

	if (c->state == HAL_CAN_CLOSED)
		return IRDM_OK;
	return irdm_can_master_emergency_off(&c->m);
}

void irdm_hal_can_reset_faults(struct irdm_hal_dev *dev)
{
	irdm_can_master_reset_faults(&can_of(dev)->m);
	dev->why[0] = '\0';
}
