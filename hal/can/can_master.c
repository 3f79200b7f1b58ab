/* SPDX-License-Identifier: MIT */
/*
 * The CANopen master's cycle (irdm/can_master.h): receive and judge, send
 * the set-points and the SYNC, and the torque-off path.  No allocation, no
 * wait: the port's send and recv are non-blocking.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "irdm/hal/can_master.h"
#include "irdm/error.h"

int16_t irdm_can_torque_permille(const struct irdm_can_axis_cfg *a, double tau_joint_nm)
{
	/* joint N m / gear -> motor N m; x 1e6 / rated mN m -> per mille */
	double permille = tau_joint_nm / a->gear_ratio * 1e6 / a->rated_torque_mnm;

	if (!isfinite(permille))
		return 0;
	if (permille > INT16_MAX)
		return INT16_MAX;
	if (permille < -INT16_MAX)
		return -INT16_MAX;
	return (int16_t)lround(permille);
}

/* Send one frame; a full queue drops it (counted: the next period's frame
 * replaces it, latest wins); a link error is returned. */
static int put(struct irdm_can_master *m, const struct irdm_can_frame *f)
{
	int rc = irdm_can_send(&m->port, f);

	if (rc == IRDM_EBUSY) {
		m->tx_dropped++;
		return IRDM_OK;
	}
	return rc;
}

static int send_sync(struct irdm_can_master *m)
{
	struct irdm_can_frame f;

	if (m->cfg.sync_counter)
		m->sync_count = m->sync_count % IRDM_CAN_SYNC_COUNTER_MAX + 1;
	irdm_co_sync(&f, m->cfg.sync_counter ? m->sync_count : 0);
	return put(m, &f);
}

/*
 * The master's own heartbeat (operational), every heartbeat_ms counted in
 * periods, from the first cycle on: each drive consumes it (0x1016) and
 * stops by itself when it goes quiet.  The set-up sends none: a drive's
 * watch starts at the first beat it hears, when the cycle does.
 */
static int beat(struct irdm_can_master *m)
{
	uint64_t every = (uint64_t)m->cfg.heartbeat_ms * 1000u / m->cfg.period_us;
	struct irdm_can_frame f = { .id = IRDM_CO_HEARTBEAT + m->cfg.master_node, .dlc = 1 };

	if (every == 0)
		every = 1;
	if (m->period % every)
		return IRDM_OK;
	f.data[0] = IRDM_CO_STATE_OPERATIONAL;
	m->beats++;
	return put(m, &f);
}

/* Disable voltage and zero torque to every axis, then a SYNC so
 * synchronous drives act on it now.  IRDM_OK, or the first send error. */
static int send_off(struct irdm_can_master *m)
{
	struct irdm_can_frame f;
	int rc = IRDM_OK, r;

	for (unsigned k = 0; k < m->cfg.n_axes; k++) {
		irdm_co_rpdo_cst(&f, m->cfg.axis[k].node, IRDM_CIA402_CW_DISABLE_VOLTAGE, 0);
		m->ax[k].cw = IRDM_CIA402_CW_DISABLE_VOLTAGE;
		r = put(m, &f);
		rc = rc ? rc : r;
	}
	r = send_sync(m);
	return rc ? rc : r;
}

int irdm_can_master_emergency_off(const struct irdm_can_master *m)
{
	struct irdm_can_frame f;
	int rc = IRDM_OK;

	for (unsigned k = 0; k < m->cfg.n_axes; k++)
		if (irdm_can_send(&m->port, &m->off[k]) != IRDM_OK)
			rc = IRDM_EHW;
	/* a counter the drives accept: the one after the last sent */
	irdm_co_sync(&f, m->cfg.sync_counter ? m->sync_count % IRDM_CAN_SYNC_COUNTER_MAX + 1 : 0);
	if (irdm_can_send(&m->port, &f) != IRDM_OK)
		rc = IRDM_EHW;
	return rc;
}

void irdm_can_master_lose(struct irdm_can_master *m, int axis, const char *reason)
{
	bool first = !m->faulted;

	/* torque off first, then say why */
	m->faulted = true;
	m->enable = false;
	(void)send_off(m); /* the link may be the fault: nothing more to do */
	if (!first)
		return;
	if (axis < 0)
		snprintf(m->why, sizeof(m->why), "CAN link: %s", reason);
	else
		snprintf(m->why, sizeof(m->why), "drive %d (node %u): %s", axis + 1,
			 m->cfg.axis[axis].node, reason);
	m->link_lost = axis < 0;
}

/* The configured axis of node, or -1. */
static int axis_of(const struct irdm_can_master *m, unsigned node)
{
	for (unsigned k = 0; k < m->cfg.n_axes; k++)
		if (node && m->cfg.axis[k].node == node)
			return (int)k;
	return -1;
}

static int take_emcy(struct irdm_can_master *m, int k, const struct irdm_can_frame *f)
{
	struct irdm_co_emcy e;
	char reason[96];

	if (irdm_co_emcy(f, m->cfg.axis[k].node, &e) != IRDM_OK) {
		m->bad_frames++;
		return IRDM_EFORMAT;
	}
	m->emcy_frames++;
	if (e.code == 0)
		return IRDM_OK; /* "error reset or no error": nothing to lose */
	snprintf(reason, sizeof(reason), "EMCY 0x%04X (%s), error register 0x%02X", e.code,
		 irdm_co_emcy_class(e.code), e.reg);
	irdm_can_master_lose(m, k, reason);
	return IRDM_OK;
}

static int take_tpdo(struct irdm_can_master *m, int k, const struct irdm_can_frame *f)
{
	struct irdm_can_master_axis *a = &m->ax[k];
	uint16_t sw;
	int32_t counts;

	if (irdm_co_tpdo_cst(f, m->cfg.axis[k].node, &sw, &counts) != IRDM_OK) {
		m->bad_frames++;
		return IRDM_EFORMAT;
	}
	a->sw = sw; /* latest wins: an older one is simply replaced */
	a->counts = counts;
	a->fresh = true;
	a->seen = true;
	return IRDM_OK;
}

static int take_heartbeat(struct irdm_can_master *m, int k, const struct irdm_can_frame *f)
{
	enum irdm_co_nmt_state s;

	if (irdm_co_heartbeat(f, m->cfg.axis[k].node, &s) != IRDM_OK) {
		m->bad_frames++;
		return IRDM_EFORMAT;
	}
	m->ax[k].heartbeat_period = m->period;
	/* A pre-operational beat from a drive that has sent no PDO yet was on
	 * the bus while our NMT start was (drives beat on their own clock):
	 * it is not news.  A drive that never starts sends no TPDO1 and is
	 * lost by that check within tpdo_missing_periods. */
	if (s == IRDM_CO_STATE_PRE_OPERATIONAL && !m->ax[k].seen)
		return IRDM_OK;
	m->ax[k].nmt = s;
	return IRDM_OK;
}

int irdm_can_master_take(struct irdm_can_master *m, const struct irdm_can_frame *f)
{
	int k;

	if ((k = axis_of(m, irdm_co_node_of(f, IRDM_CO_TPDO1))) >= 0)
		return take_tpdo(m, k, f);
	if ((k = axis_of(m, irdm_co_node_of(f, IRDM_CO_HEARTBEAT))) >= 0)
		return take_heartbeat(m, k, f);
	if ((k = axis_of(m, irdm_co_node_of(f, IRDM_CO_EMCY))) >= 0)
		return take_emcy(m, k, f);
	if (axis_of(m, irdm_co_node_of(f, IRDM_CO_SDO_TX)) >= 0)
		m->sdo_stragglers++; /* a late answer: set-up is over, never trusted */
	else
		m->unknown_frames++;
	return IRDM_ENOTSUP;
}

static const char *nmt_name(enum irdm_co_nmt_state s)
{
	switch (s) {
	case IRDM_CO_STATE_BOOTUP:
		return "boot-up (the drive restarted)";
	case IRDM_CO_STATE_STOPPED:
		return "stopped";
	case IRDM_CO_STATE_PRE_OPERATIONAL:
		return "pre-operational";
	default:
		return "operational";
	}
}

/* Axis k's health this period; false (and the master lost) if it is gone. */
static bool judge_axis(struct irdm_can_master *m, unsigned k)
{
	struct irdm_can_master_axis *a = &m->ax[k];
	uint64_t silent_ms = (m->period - a->heartbeat_period) * m->cfg.period_us / 1000;
	char reason[96];

	if (a->fresh) {
		a->missing = 0;
		a->state = irdm_cia402_decode(a->sw);
	} else if (++a->missing >= m->cfg.tpdo_missing_periods) {
		snprintf(reason, sizeof(reason), "no TPDO1 for %u periods", a->missing);
		irdm_can_master_lose(m, (int)k, reason);
		return false;
	}
	if (silent_ms > m->cfg.heartbeat_timeout_ms) {
		snprintf(reason, sizeof(reason), "no heartbeat for %llu ms (time-out %u ms)",
			 (unsigned long long)silent_ms, (unsigned)m->cfg.heartbeat_timeout_ms);
	} else if (a->nmt != IRDM_CO_STATE_OPERATIONAL) {
		snprintf(reason, sizeof(reason), "heartbeat says NMT %s", nmt_name(a->nmt));
	} else if ((a->state == IRDM_CIA402_FAULT && !m->reset_request) ||
		   a->state == IRDM_CIA402_FAULT_REACTION_ACTIVE) {
		/* (a fault being reset on request is expected until it clears) */
		snprintf(reason, sizeof(reason), "drive fault (statusword 0x%04X, %s)", a->sw,
			 irdm_cia402_name(a->state));
	} else if (m->enable && a->was_enabled && a->state != IRDM_CIA402_OPERATION_ENABLED) {
		snprintf(reason, sizeof(reason), "left operation enabled by itself (now %s)",
			 irdm_cia402_name(a->state));
	} else {
		if (a->state == IRDM_CIA402_OPERATION_ENABLED && m->enable)
			a->was_enabled = true;
		return true;
	}
	irdm_can_master_lose(m, (int)k, reason);
	return false;
}

static int first_fault(const struct irdm_can_master *m)
{
	for (unsigned k = 0; k < m->cfg.n_axes; k++)
		if (m->ax[k].state == IRDM_CIA402_FAULT)
			return (int)k;
	return -1;
}

/*
 * Take what is waiting, at most IRDM_CAN_RX_MAX frames (the cycle stays
 * bounded under a flood; the rest waits for the next period).  A port may
 * say "nothing" (0) after reading a frame that was not data (SocketCAN's
 * error frames), so only a second 0 in a row ends the drain.
 * Return: 0, or the port's error (IRDM_EIO).
 */
static int drain(struct irdm_can_master *m)
{
	struct irdm_can_frame f;
	unsigned zeros = 0;

	for (unsigned n = 0; n < IRDM_CAN_RX_MAX && zeros < 2; n++) {
		int rc = irdm_can_recv(&m->port, &f);

		if (rc < 0)
			return rc;
		if (rc == 1)
			(void)irdm_can_master_take(m, &f);
		zeros = rc == 1 ? 0 : zeros + 1;
	}
	return 0;
}

int irdm_can_master_receive(struct irdm_can_master *m)
{
	bool stale = false;
	int rc;

	for (unsigned k = 0; k < m->cfg.n_axes; k++)
		m->ax[k].fresh = false;
	rc = drain(m);
	if (rc < 0)
		irdm_can_master_lose(m, -1, "link down (bus-off or interface gone) on receive");
	for (unsigned k = 0; k < m->cfg.n_axes && !m->faulted; k++) {
		judge_axis(m, k);
		stale |= !m->ax[k].fresh;
	}
	if (m->faulted)
		return IRDM_EHW;
	if (first_fault(m) < 0)
		m->reset_request = false; /* every fault reset: asked once, done */
	return stale ? IRDM_ETIMEDOUT : IRDM_OK;
}

/* The set-point of axis k this period. */
static void setpoint(struct irdm_can_master *m, unsigned k, const double *tau_joint_nm,
		     bool torque_on, uint16_t *cw, int16_t *permille)
{
	struct irdm_can_master_axis *a = &m->ax[k];

	*permille = 0;
	if (a->state == IRDM_CIA402_FAULT && m->reset_request) {
		*cw = irdm_cia402_next(a->state, true, a->cw);
		return;
	}
	if (!m->enable) {
		*cw = IRDM_CIA402_CW_DISABLE_VOLTAGE;
		return;
	}
	*cw = irdm_cia402_next(a->state, m->reset_request, a->cw);
	if (torque_on && tau_joint_nm)
		*permille = irdm_can_torque_permille(&m->cfg.axis[k], tau_joint_nm[k]);
}

int irdm_can_master_send(struct irdm_can_master *m, const double *tau_joint_nm)
{
	bool torque_on = irdm_can_master_all_enabled(m);
	struct irdm_can_frame f;
	int rc = IRDM_OK;

	if (m->faulted) {
		rc = send_off(m);
	} else {
		for (unsigned k = 0; k < m->cfg.n_axes && rc == IRDM_OK; k++) {
			uint16_t cw;
			int16_t permille;

			setpoint(m, k, tau_joint_nm, torque_on, &cw, &permille);
			irdm_co_rpdo_cst(&f, m->cfg.axis[k].node, cw, permille);
			m->ax[k].cw = cw;
			rc = put(m, &f);
		}
		if (rc == IRDM_OK)
			rc = send_sync(m);
	}
	if (rc == IRDM_OK)
		rc = beat(m);
	m->period++;
	if (rc != IRDM_OK && !m->faulted)
		irdm_can_master_lose(m, -1, "link down (bus-off or interface gone) on send");
	return m->faulted ? IRDM_EHW : IRDM_OK;
}

void irdm_can_master_enable(struct irdm_can_master *m, bool on)
{
	m->enable = on && !m->faulted;
	for (unsigned k = 0; k < m->cfg.n_axes; k++)
		m->ax[k].was_enabled = false;
}

int irdm_can_master_first_stale(const struct irdm_can_master *m)
{
	for (unsigned k = 0; k < m->cfg.n_axes; k++)
		if (!m->ax[k].fresh)
			return (int)k;
	return -1;
}

int irdm_can_master_first_not_enabled(const struct irdm_can_master *m)
{
	for (unsigned k = 0; k < m->cfg.n_axes; k++)
		if (m->ax[k].state != IRDM_CIA402_OPERATION_ENABLED)
			return (int)k;
	return -1;
}

bool irdm_can_master_all_enabled(const struct irdm_can_master *m)
{
	return !m->faulted && irdm_can_master_first_not_enabled(m) < 0;
}

int irdm_can_master_safe_off(struct irdm_can_master *m)
{
	irdm_can_master_enable(m, false);
	return send_off(m) == IRDM_OK ? IRDM_OK : IRDM_EHW;
}

void irdm_can_master_reset_faults(struct irdm_can_master *m)
{
	m->faulted = false;
	m->link_lost = false;
	m->why[0] = '\0';
	m->reset_request = true;
	for (unsigned k = 0; k < m->cfg.n_axes; k++) {
		m->ax[k].missing = 0;
		m->ax[k].heartbeat_period = m->period;
	}
}

void irdm_can_master_stop(struct irdm_can_master *m)
{
	struct irdm_can_frame f;

	for (unsigned k = 0; k < m->cfg.n_axes; k++) {
		irdm_co_nmt(&f, IRDM_CO_NMT_STOP, m->cfg.axis[k].node);
		(void)put(m, &f);
	}
}
