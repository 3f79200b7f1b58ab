/* SPDX-License-Identifier: MIT */
/*
 * The CANopen master's set-up (irdm/can_master.h): the configuration's
 * checks and bus load, then each drive's SDO configuration and NMT start.
 * Set-up may wait (through cfg->idle, a bounded number of times); the
 * cycle (can_master.c) never does.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "irdm/hal/can_master.h"
#include "irdm/error.h"

#define MODE_CST 10
#define BITRATE_MIN 10000u
#define BITRATE_MAX 1000000u

/* The CST mapping: RPDO1 = controlword 0x6040 (16 bit) + target torque 0x6071
 * (16 bit); TPDO1 = statusword 0x6041 (16 bit) + position actual 0x6064 (32 bit). */
#define RPDO1_BYTES 4
#define TPDO1_BYTES 6
#define PDO_ENTRIES 2
static const uint32_t rpdo1_map[PDO_ENTRIES] = { 0x60400010, 0x60710010 };
static const uint32_t tpdo1_map[PDO_ENTRIES] = { 0x60410010, 0x60640020 };
#define PDO_NOT_VALID 0x80000000u /* COB-ID bit 31 */
#define PDO_NO_RTR 0x40000000u    /* COB-ID bit 30: no remote request (RTR) */
#define CIA402_PROFILE 0x0192u    /* 0x1000's low 16 bits for a drive */
#define ABORT_FAULT 1             /* 0x6007 values (CiA 402) */
#define ABORT_DISABLE_VOLTAGE 2
#define PDO_SYNC_EVERY 1 /* transmission type: synchronous, every SYNC */

unsigned irdm_can_master_cycle_bits(const struct irdm_can_master_cfg *cfg)
{
	unsigned per_axis = irdm_can_frame_bits(RPDO1_BYTES, true) +
			    irdm_can_frame_bits(TPDO1_BYTES, true);

	return irdm_can_frame_bits(cfg->sync_counter ? 1 : 0, true) + cfg->n_axes * per_axis;
}

void irdm_can_master_load_line(const struct irdm_can_master_cfg *cfg, char *line, size_t len)
{
	unsigned bits = irdm_can_master_cycle_bits(cfg);
	double budget_bits = (double)cfg->bitrate * cfg->period_us * 1e-6;

	snprintf(line, len,
		 "CAN bus load: SYNC + %u x RPDO1 (%d B) + %u x TPDO1 (%d B) = %u bits worst case "
		 "in %u us at %u bit/s: %.1f %%",
		 cfg->n_axes, RPDO1_BYTES, cfg->n_axes, TPDO1_BYTES, bits, (unsigned)cfg->period_us,
		 (unsigned)cfg->bitrate, budget_bits > 0 ? 100.0 * bits / budget_bits : INFINITY);
}

static int refuse(char *err, size_t errlen, const char *field, const char *why)
{
	snprintf(err, errlen, "%s: %s", field, why);
	return IRDM_EINVAL;
}

static int check_axes(const struct irdm_can_master_cfg *cfg, char *err, size_t errlen)
{
	if (cfg->n_axes < 1 || cfg->n_axes > IRDM_CAN_AXES_MAX)
		return refuse(err, errlen, "nodes", "1 to 3 drives");
	for (unsigned k = 0; k < cfg->n_axes; k++) {
		const struct irdm_can_axis_cfg *a = &cfg->axis[k];

		if (a->node < IRDM_CO_NODE_MIN || a->node > IRDM_CO_NODE_MAX)
			return refuse(err, errlen, "nodes", "a node id is 1..127");
		for (unsigned j = 0; j < k; j++)
			if (cfg->axis[j].node == a->node)
				return refuse(err, errlen, "nodes", "a node id appears twice");
		if (a->rated_torque_mnm == 0)
			return refuse(err, errlen, "rated_torque_mnm", "must be > 0");
		if (!(isfinite(a->gear_ratio) && a->gear_ratio > 0))
			return refuse(err, errlen, "gear_ratio", "must be finite and > 0");
	}
	return IRDM_OK;
}

int irdm_can_master_check(const struct irdm_can_master_cfg *cfg, char *err, size_t errlen)
{
	double budget_bits = (double)cfg->bitrate * cfg->period_us * 1e-6;
	unsigned bits;
	int rc = check_axes(cfg, err, errlen);

	if (rc)
		return rc;
	if (cfg->bitrate < BITRATE_MIN || cfg->bitrate > BITRATE_MAX)
		return refuse(err, errlen, "bitrate", "10000..1000000 bit/s");
	if (cfg->period_us == 0)
		return refuse(err, errlen, "period_us", "must be > 0");
	if (cfg->heartbeat_ms == 0)
		return refuse(err, errlen, "heartbeat_ms", "must be > 0 (the drives' liveness)");
	if (cfg->heartbeat_timeout_ms <= cfg->heartbeat_ms)
		return refuse(err, errlen, "heartbeat_timeout_ms", "must exceed heartbeat_ms");
	if (cfg->tpdo_missing_periods == 0)
		return refuse(err, errlen, "tpdo_missing_periods", "must be > 0");
	if (cfg->master_node < IRDM_CO_NODE_MIN || cfg->master_node > IRDM_CO_NODE_MAX)
		return refuse(err, errlen, "master_node", "1..127");
	for (unsigned k = 0; k < cfg->n_axes; k++)
		if (cfg->axis[k].node == cfg->master_node)
			return refuse(err, errlen, "master_node", "is a drive's node id");
	if (cfg->rpdo_timeout_ms == 0)
		return refuse(err, errlen, "rpdo_timeout_ms", "must be > 0 (the drives' deadline)");
	if (cfg->sdo_timeout_polls == 0 || !cfg->idle)
		return refuse(err, errlen, "sdo_timeout", "must be > 0, with a wait");
	bits = irdm_can_master_cycle_bits(cfg);
	if (bits > budget_bits) {
		snprintf(err, errlen,
			 "bitrate: one cycle needs %u bits worst case, %u us at %u bit/s carries %.0f",
			 bits, (unsigned)cfg->period_us, (unsigned)cfg->bitrate, budget_bits);
		return IRDM_EINVAL;
	}
	return IRDM_OK;
}

/* One object to read or write during set-up. */
enum sdo_dir { SDO_WRITE,
	       SDO_READ };

struct sdo_item {
	uint16_t index;
	uint8_t sub;
	uint8_t size;   /* bytes written; a read takes what comes */
	uint32_t value; /* written; a read's answer */
	enum sdo_dir dir;
	uint32_t skip_abort; /* this abort means "no such object here": go on */
};

/* A write of size bytes of v to index:sub. */
#define WR(i, s, z, v) \
	{ \
		.index = (i), .sub = (s), .size = (z), .value = (v), .dir = SDO_WRITE \
	}

static void say_drive(const struct irdm_can_master *m, unsigned k, const struct sdo_item *it,
		      char *err, size_t errlen, const char *what)
{
	snprintf(err, errlen, "drive %u (node %u): %s %s 0x%04X:%02X", k + 1, m->cfg.axis[k].node,
		 what, it->dir == SDO_READ ? "reading" : "writing", it->index, it->sub);
}

/* The answer to it from drive k, or an error (err says which). */
static int sdo_answer(struct irdm_can_master *m, unsigned k, struct sdo_item *it,
		      const struct irdm_can_frame *f, uint32_t *abort_code, char *err,
		      size_t errlen)
{
	uint32_t value;
	unsigned size;
	char what[IRDM_CAN_WHY_MAX];
	int rc = irdm_co_sdo_answer(f, m->cfg.axis[k].node, it->index, it->sub, &value, &size,
				    abort_code);

	if (rc == IRDM_OK && (it->dir == SDO_READ) == (size != 0)) {
		if (it->dir == SDO_READ)
			it->value = value;
		return IRDM_OK;
	}
	if (rc == IRDM_EHW) {
		snprintf(what, sizeof(what), "SDO abort 0x%08X %s", (unsigned)*abort_code,
			 irdm_co_abort_name(*abort_code));
	} else {
		rc = IRDM_EFORMAT;
		snprintf(what, sizeof(what), "malformed SDO answer %02X %02X %02X %02X (not %s)",
			 f->data[0], f->data[1], f->data[2], f->data[3],
			 it->dir == SDO_READ ? "an upload's answer" : "a confirmation");
	}
	say_drive(m, k, it, err, errlen, what);
	return rc;
}

/*
 * Read or write one object of drive k and wait (bounded) for the answer.
 * *abort_code: the drive's abort, if it sent one (IRDM_EHW).
 */
static int sdo_transfer(struct irdm_can_master *m, unsigned k, struct sdo_item *it,
			uint32_t *abort_code, char *err, size_t errlen)
{
	unsigned node = m->cfg.axis[k].node;
	struct irdm_can_frame f;
	int rc;

	*abort_code = 0;
	if (it->dir == SDO_READ)
		irdm_co_sdo_read(&f, node, it->index, it->sub);
	else
		irdm_co_sdo_write(&f, node, it->index, it->sub, it->value, it->size);
	if (irdm_can_send(&m->port, &f) != IRDM_OK) {
		say_drive(m, k, it, err, errlen, "CAN link down or queue full");
		return IRDM_EIO;
	}
	for (unsigned poll = 0; poll < m->cfg.sdo_timeout_polls; poll++) {
		m->cfg.idle(m->cfg.idle_ctx);
		while ((rc = irdm_can_recv(&m->port, &f)) == 1)
			if (f.id == IRDM_CO_SDO_TX + node)
				return sdo_answer(m, k, it, &f, abort_code, err, errlen);
			else
				(void)irdm_can_master_take(m, &f);
		if (rc < 0) {
			say_drive(m, k, it, err, errlen, "CAN link down");
			return IRDM_EIO;
		}
	}
	say_drive(m, k, it, err, errlen, "no SDO answer (time-out)");
	return IRDM_ETIMEDOUT;
}

/* Run items in order; an abort a item names as "absent" is passed over
 * (and counted in *skipped, the bits of the items skipped). */
static int sdo_run(struct irdm_can_master *m, unsigned k, struct sdo_item *items, size_t n,
		   uint32_t *skipped, char *err, size_t errlen)
{
	uint32_t abort_code;

	for (size_t i = 0; i < n; i++) {
		int rc = sdo_transfer(m, k, &items[i], &abort_code, err, errlen);

		if (rc == IRDM_EHW && items[i].skip_abort && abort_code == items[i].skip_abort) {
			*skipped |= 1u << i;
			continue;
		}
		if (rc)
			return rc;
	}
	return IRDM_OK;
}

/*
 * A PDO's mapping the way CiA 301 lets it change (most drives refuse a
 * mapping write otherwise): switch the PDO off (COB-ID bit 31), empty the
 * mapping (sub 0 = 0), write the entries, set their number, make it
 * synchronous (transmission type 1: every SYNC), give an RPDO its deadline
 * (event timer :05), switch it on again.  cob_id carries bit 30 (no RTR)
 * for a TPDO.  Return: the items written into it.
 */
#define PDO_ITEMS_MAX (6 + PDO_ENTRIES)

static size_t pdo_items(struct sdo_item *it, uint16_t comm_index, uint16_t map_index,
			uint32_t cob_id, const uint32_t map[PDO_ENTRIES], uint16_t deadline_ms)
{
	size_t n = 0;

	it[n++] = (struct sdo_item)WR(comm_index, 1, 4, cob_id | PDO_NOT_VALID);
	it[n++] = (struct sdo_item)WR(map_index, 0, 1, 0);
	for (uint8_t e = 0; e < PDO_ENTRIES; e++)
		it[n++] = (struct sdo_item)WR(map_index, (uint8_t)(e + 1), 4, map[e]);
	it[n++] = (struct sdo_item)WR(map_index, 0, 1, PDO_ENTRIES);
	it[n++] = (struct sdo_item)WR(comm_index, 2, 1, PDO_SYNC_EVERY);
	if (deadline_ms)
		it[n++] = (struct sdo_item)WR(comm_index, 5, 2, deadline_ms);
	it[n++] = (struct sdo_item)WR(comm_index, 1, 4, cob_id);
	return n;
}

/* 0x1000 and 0x1018: a CiA 402 drive, and which one. */
static int identify(struct irdm_can_master *m, unsigned k, char *err, size_t errlen)
{
	struct sdo_item items[5] = {
		{ .index = 0x1000, .dir = SDO_READ },
		{ .index = 0x1018, .sub = 1, .dir = SDO_READ },
		{ .index = 0x1018, .sub = 2, .dir = SDO_READ },
		{ .index = 0x1018, .sub = 3, .dir = SDO_READ },
		{ .index = 0x1018, .sub = 4, .dir = SDO_READ },
	};
	uint32_t skipped = 0;
	int rc = sdo_run(m, k, items, 5, &skipped, err, errlen);

	if (rc)
		return rc;
	m->ax[k].device_type = items[0].value;
	for (unsigned i = 0; i < 4; i++)
		m->ax[k].identity[i] = items[1 + i].value;
	if ((items[0].value & 0xFFFFu) != CIA402_PROFILE) {
		snprintf(err, errlen, "drive %u (node %u): device type 0x%08X (0x1000) is not a "
				      "CiA 402 drive (profile 0x%04X, not 0x%04X)",
			 k + 1, m->cfg.axis[k].node,
			 (unsigned)items[0].value, (unsigned)(items[0].value & 0xFFFFu),
			 CIA402_PROFILE);
		return IRDM_ENOTSUP;
	}
	return IRDM_OK;
}

/*
 * The SYNC format and the drive's watch on the master, in the order CiA
 * 301 allows: 0x1019 (the counter's overflow, 0 for a SYNC without one)
 * may change only while 0x1006 (the cycle period) is 0, so 0x1006 = 0,
 * then 0x1019, then 0x1006 = the period (the drive's SYNC monitor).  A
 * drive without 0x1006 (abort 0x06020000) has no monitor to stop; without
 * 0x1019 it takes only SYNCs without a counter.  Then the master's
 * heartbeat as the drive's consumer entry 0x1016:01 (node << 16 | ms, the
 * same tolerance the master gives the drives', at most 65535 ms).
 */
static size_t sync_items(const struct irdm_can_master *m, struct sdo_item *it)
{
	uint32_t hb_ms = m->cfg.heartbeat_timeout_ms > 0xFFFF ? 0xFFFF : m->cfg.heartbeat_timeout_ms;
	size_t n = 0;

	it[n] = (struct sdo_item)WR(0x1006, 0, 4, 0);
	it[n++].skip_abort = 0x06020000;
	it[n] = (struct sdo_item)WR(0x1019, 0, 1, m->cfg.sync_counter ? IRDM_CAN_SYNC_COUNTER_MAX : 0);
	it[n++].skip_abort = m->cfg.sync_counter ? 0 : 0x06020000;
	it[n] = (struct sdo_item)WR(0x1006, 0, 4, m->cfg.period_us);
	it[n++].skip_abort = 0x06020000;
	it[n++] = (struct sdo_item)WR(0x1016, 1, 4, (uint32_t)m->cfg.master_node << 16 | hb_ms);
	return n;
}

/*
 * 0x6007, the drive's reaction to a lost master (a heartbeat or an RPDO
 * deadline missed): disable voltage, the torque off at once whatever
 * 0x605E says; a drive that takes only the default (abort 0x06090030)
 * gets "fault" (1): it ends with the drive function disabled, but only
 * after the fault reaction 0x605E names (not written here: the drive's
 * default, which may be a braking ramp under torque).
 */
static int abort_option(struct irdm_can_master *m, unsigned k, char *err, size_t errlen)
{
	struct sdo_item it = WR(0x6007, 0, 2, ABORT_DISABLE_VOLTAGE);
	uint32_t abort_code;
	int rc = sdo_transfer(m, k, &it, &abort_code, err, errlen);

	if (rc == IRDM_EHW && abort_code == 0x06090030) {
		it.value = ABORT_FAULT;
		rc = sdo_transfer(m, k, &it, &abort_code, err, errlen);
	}
	m->ax[k].abort_option = (uint16_t)it.value;
	return rc;
}

static int configure_drive(struct irdm_can_master *m, unsigned k, char *err, size_t errlen)
{
	unsigned node = m->cfg.axis[k].node;
	struct sdo_item items[3 + 4 + 2 * PDO_ITEMS_MAX] = {
		WR(0x6060, 0, 1, MODE_CST),
		WR(0x1017, 0, 2, m->cfg.heartbeat_ms),
		WR(0x6076, 0, 4, m->cfg.axis[k].rated_torque_mnm),
	};
	struct sdo_item mode = { .index = 0x6061, .dir = SDO_READ };
	uint32_t skipped = 0;
	size_t n = 3;
	int rc = identify(m, k, err, errlen);

	if (rc)
		return rc;
	n += sync_items(m, items + n);
	rc = sdo_run(m, k, items, n, &skipped, err, errlen);
	if (!rc)
		rc = abort_option(m, k, err, errlen);
	if (rc)
		return rc;
	n = pdo_items(items, 0x1400, 0x1600, IRDM_CO_RPDO1 + node, rpdo1_map,
		      m->cfg.rpdo_timeout_ms);
	n += pdo_items(items + n, 0x1800, 0x1A00, PDO_NO_RTR | (IRDM_CO_TPDO1 + node), tpdo1_map, 0);
	n += 1;
	items[n - 1] = mode;
	rc = sdo_run(m, k, items, n, &skipped, err, errlen);
	if (rc)
		return rc;
	/* the mode the drive runs, read back: a drive may keep another */
	if ((uint8_t)items[n - 1].value != MODE_CST) {
		snprintf(err, errlen, "drive %u (node %u): mode of operation display 0x6061 is %d, "
				      "not 10 (cyclic synchronous torque)",
			 k + 1, node,
			 (int8_t)items[n - 1].value);
		return IRDM_ENOTSUP;
	}
	return IRDM_OK;
}

void irdm_can_master_identity_line(const struct irdm_can_master *m, unsigned k, char *line,
				   size_t len)
{
	const struct irdm_can_master_axis *a = &m->ax[k];

	snprintf(line, len, "drive %u (node %u): CiA 402 device type 0x%08X, vendor 0x%08X, "
			    "product 0x%08X, revision 0x%08X, serial 0x%08X",
		 k + 1, m->cfg.axis[k].node,
		 (unsigned)a->device_type, (unsigned)a->identity[0], (unsigned)a->identity[1],
		 (unsigned)a->identity[2], (unsigned)a->identity[3]);
}

int irdm_can_master_init(struct irdm_can_master *m, const struct irdm_can_port *port,
			 const struct irdm_can_master_cfg *cfg, char *err, size_t errlen)
{
	struct irdm_can_frame f;
	int rc;

	memset(m, 0, sizeof(*m));
	rc = irdm_can_master_check(cfg, err, errlen);
	if (rc)
		return rc;
	m->cfg = *cfg;
	m->port = *port;
	for (unsigned k = 0; k < cfg->n_axes; k++) {
		m->ax[k].state = IRDM_CIA402_UNKNOWN;
		irdm_co_rpdo_cst(&m->off[k], cfg->axis[k].node, IRDM_CIA402_CW_DISABLE_VOLTAGE, 0);
	}
	for (unsigned k = 0; k < cfg->n_axes; k++) {
		rc = configure_drive(m, k, err, errlen);
		if (rc)
			return rc;
	}
	for (unsigned k = 0; k < cfg->n_axes; k++) {
		irdm_co_nmt(&f, IRDM_CO_NMT_START, cfg->axis[k].node);
		if (irdm_can_send(&m->port, &f) != IRDM_OK) {
			snprintf(err, errlen, "drive %u (node %u): NMT start not sent: CAN link down",
				 k + 1, cfg->axis[k].node);
			return IRDM_EIO;
		}
	}
	/* heartbeats count from here: the producer time was just written */
	for (unsigned k = 0; k < cfg->n_axes; k++) {
		m->ax[k].heartbeat_period = 0;
		m->ax[k].nmt = IRDM_CO_STATE_OPERATIONAL;
	}
	return IRDM_OK;
}
