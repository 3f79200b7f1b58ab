/* SPDX-License-Identifier: MIT */
/* CiA 402 drives in emulation (irdm/can_drives.h). */
#include <math.h>
#include <string.h>

#include "irdm/can_drives.h"
#include "irdm/error.h"

#define MODE_CST 10
/* the CST mapping the master writes: RPDO1 0x6040 + 0x6071, TPDO1 0x6041 + 0x6064 */
static const uint32_t rpdo_map[3] = { 2, 0x60400010, 0x60710010 };
static const uint32_t tpdo_map[3] = { 2, 0x60410010, 0x60640020 };

static void send(struct irdm_can_drives *dr, const struct irdm_can_frame *f)
{
	(void)irdm_can_send(&dr->port, f);     /* a full queue drops it, as a wire would */
}

static void heartbeat(struct irdm_can_drives *dr, struct irdm_can_drive *d)
{
	struct irdm_can_frame f = { .id = IRDM_CO_HEARTBEAT + d->node, .dlc = 1 };

	f.data[0] = (uint8_t)d->nmt;
	if (!d->no_heartbeat)
		send(dr, &f);
	d->heartbeat_next_us = dr->now_us + 1000ull * d->heartbeat_ms;
}

static void boot(struct irdm_can_drives *dr, struct irdm_can_drive *d)
{
	d->nmt = IRDM_CO_STATE_BOOTUP;
	heartbeat(dr, d);
	d->nmt = IRDM_CO_STATE_PRE_OPERATIONAL;
	irdm_cia402_drive_init(&d->fsa);
	d->rpdo_cw = 0;
	d->rpdo_torque_permille = 0;
}

int irdm_can_drives_init(struct irdm_can_drives *dr, const struct irdm_can_port *port,
			 const struct irdm_device_config *dev, const struct irdm_sim_params *p,
			 unsigned n, unsigned first_node, double period_s)
{
	memset(dr, 0, sizeof(*dr));
	if (n < 1 || n > IRDM_CAN_DRIVES_MAX || first_node < IRDM_CO_NODE_MIN ||
	    first_node + n - 1 > IRDM_CO_NODE_MAX || !(isfinite(period_s) && period_s > 0) ||
	    irdm_sim_device_init(&dr->arm, dev, p) != IRDM_OK)
		return IRDM_EINVAL;
	dr->port = *port;
	dr->n = n;
	dr->period_s = period_s;
	for (unsigned k = 0; k < n; k++) {
		dr->d[k].node = first_node + k;
		dr->d[k].rated_torque_mnm = 1000;
		boot(dr, &dr->d[k]);
	}
	return IRDM_OK;
}

static struct irdm_can_drive *drive_of(struct irdm_can_drives *dr, unsigned node)
{
	for (unsigned k = 0; k < dr->n; k++)
		if (dr->d[k].node == node)
			return &dr->d[k];
	return NULL;
}

static void nmt(struct irdm_can_drives *dr, const struct irdm_can_frame *f)
{
	for (unsigned k = 0; k < dr->n; k++) {
		struct irdm_can_drive *d = &dr->d[k];

		if (f->data[1] && f->data[1] != d->node)
			continue;
		switch (f->data[0]) {
		case IRDM_CO_NMT_START:
			d->nmt = IRDM_CO_STATE_OPERATIONAL;
			break;
		case IRDM_CO_NMT_STOP:
			d->nmt = IRDM_CO_STATE_STOPPED;
			break;
		case IRDM_CO_NMT_PRE_OPERATIONAL:
			d->nmt = IRDM_CO_STATE_PRE_OPERATIONAL;
			break;
		case IRDM_CO_NMT_RESET_NODE:
		case IRDM_CO_NMT_RESET_COMM:
			boot(dr, d);
			break;
		default:
			dr->bad_frames++;
		}
	}
}

static void sdo_reply(struct irdm_can_drives *dr, const struct irdm_can_drive *d,
		      const struct irdm_can_frame *req, uint8_t cmd, uint32_t data)
{
	struct irdm_can_frame f = { .id = IRDM_CO_SDO_TX + d->node, .dlc = 8 };

	f.data[0] = cmd;
	memcpy(f.data + 1, req->data + 1, 3);           /* index, sub-index */
	if (d->sdo_wrong)
		f.data[1] ^= 0x01;                      /* about another object */
	for (int k = 0; k < 4; k++)
		f.data[4 + k] = (uint8_t)(data >> (8 * k));
	send(dr, &f);
}

/* The value of a readable object, or an abort code. */
static uint32_t object_read(struct irdm_can_drives *dr, struct irdm_can_drive *d, uint16_t index,
			    uint8_t sub, uint32_t *v, unsigned *size)
{
	int32_t counts[3] = { 0, 0, 0 };

	if (sub != 0)
		return 0x06090011;
	switch (index) {
	case 0x6041:
		*v = irdm_cia402_statusword(d->fsa.state), *size = 2;
		return 0;
	case 0x6061:
	case 0x6060:
		*v = (uint8_t)d->mode, *size = 1;
		return 0;
	case 0x6064:
		irdm_sim_device_read_counts(&dr->arm, counts);
		*v = (uint32_t)counts[d - dr->d], *size = 4;
		return 0;
	case 0x1017:
		*v = d->heartbeat_ms, *size = 2;
		return 0;
	case 0x6076:
		*v = d->rated_torque_mnm, *size = 4;
		return 0;
	default:
		return 0x06020000;
	}
}

/* A download: the abort code, 0 when taken. */
static uint32_t object_write(struct irdm_can_drive *d, uint16_t index, uint8_t sub, uint32_t v,
			     unsigned size)
{
	if ((index == 0x1600 || index == 0x1A00) && sub <= 2)
		return v == (index == 0x1600 ? rpdo_map : tpdo_map)[sub] ? 0 : 0x06040041;
	if (sub != 0)
		return index == 0x6060 || index == 0x1017 || index == 0x6076 ? 0x06090011
									      : 0x06020000;
	switch (index) {
	case 0x6060:
		if (size != 1)
			return 0x06070010;
		if (v != MODE_CST)
			return 0x06090030;
		d->mode = (int8_t)v;
		return 0;
	case 0x1017:
		if (size != 2)
			return 0x06070010;
		d->heartbeat_ms = (uint16_t)v;
		return 0;
	case 0x6076:
		if (size != 4)
			return 0x06070010;
		d->rated_torque_mnm = v;
		return 0;
	case 0x6041:
	case 0x6061:
	case 0x6064:
		return 0x06010002;
	default:
		return 0x06020000;
	}
}

static void sdo(struct irdm_can_drives *dr, struct irdm_can_drive *d, const struct irdm_can_frame *f)
{
	uint16_t index = (uint16_t)(f->data[1] | (f->data[2] << 8));
	uint8_t cmd = f->data[0], sub = f->data[3];
	uint32_t v = 0, abort_code;
	unsigned size = 0;

	if (f->dlc != 8) {
		dr->bad_frames++;
		return;
	}
	if (cmd == 0x40) {                                      /* upload */
		abort_code = object_read(dr, d, index, sub, &v, &size);
		if (abort_code)
			sdo_reply(dr, d, f, 0x80, abort_code);
		else
			sdo_reply(dr, d, f, (uint8_t)(0x43 | ((4 - size) << 2)), v);
		return;
	}
	if ((cmd & 0xE3) != 0x23) {                             /* only expedited downloads */
		sdo_reply(dr, d, f, 0x80, 0x05040001);
		return;
	}
	size = 4 - ((cmd >> 2) & 3);
	for (unsigned k = 0; k < size; k++)
		v |= (uint32_t)f->data[4 + k] << (8 * k);
	abort_code = object_write(d, index, sub, v, size);
	if (abort_code)
		sdo_reply(dr, d, f, 0x80, abort_code);
	else
		sdo_reply(dr, d, f, 0x60, 0);
}

/* The joint torque drive k applies: per mille of the rated torque through the gear. */
static double joint_torque(const struct irdm_can_drives *dr, unsigned k)
{
	const struct irdm_can_drive *d = &dr->d[k];

	if (d->nmt != IRDM_CO_STATE_OPERATIONAL || d->fsa.state != IRDM_CIA402_OPERATION_ENABLED ||
	    d->mode != MODE_CST)
		return 0;
	return d->rpdo_torque_permille * 1e-3 * d->rated_torque_mnm * 1e-3 *
	       dr->arm.dev.gear_ratio[k];
}

/* SYNC: sample and send TPDOs, apply the set-points, move the arm a period. */
static void sync(struct irdm_can_drives *dr)
{
	int32_t counts[3] = { 0, 0, 0 };
	double tau[3] = { 0, 0, 0 };

	dr->syncs++;
	irdm_sim_device_read_counts(&dr->arm, counts);
	for (unsigned k = 0; k < dr->n; k++) {
		struct irdm_can_drive *d = &dr->d[k];
		struct irdm_can_frame f = { .id = IRDM_CO_TPDO1 + d->node, .dlc = 6 };
		uint16_t sw;

		irdm_cia402_drive_settle(&d->fsa);
		if (d->nmt == IRDM_CO_STATE_OPERATIONAL)
			irdm_cia402_drive_command(&d->fsa, d->rpdo_cw);
		sw = irdm_cia402_statusword(d->fsa.state);
		f.data[0] = (uint8_t)sw;
		f.data[1] = (uint8_t)(sw >> 8);
		for (int b = 0; b < 4; b++)
			f.data[2 + b] = (uint8_t)((uint32_t)counts[k] >> (8 * b));
		if (d->nmt == IRDM_CO_STATE_OPERATIONAL) {
			if (d->drop_tpdos)
				d->drop_tpdos--;
			else
				send(dr, &f);
		}
		tau[k] = joint_torque(dr, k);
	}
	irdm_sim_device_set_torque(&dr->arm, tau);
	irdm_sim_device_step(&dr->arm, dr->period_s);
	dr->now_us += (uint64_t)llround(dr->period_s * 1e6);
	for (unsigned k = 0; k < dr->n; k++)
		if (dr->d[k].heartbeat_ms && dr->now_us >= dr->d[k].heartbeat_next_us)
			heartbeat(dr, &dr->d[k]);
}

static void frame_in(struct irdm_can_drives *dr, const struct irdm_can_frame *f)
{
	struct irdm_can_drive *d;

	if (f->id == IRDM_CO_NMT && f->dlc == 2) {
		nmt(dr, f);
	} else if (f->id == IRDM_CO_SYNC && f->dlc <= 1) {
		dr->sync_counter = f->dlc ? f->data[0] : 0;
		sync(dr);
	} else if ((d = drive_of(dr, irdm_co_node_of(f, IRDM_CO_SDO_RX)))) {
		sdo(dr, d, f);
	} else if ((d = drive_of(dr, irdm_co_node_of(f, IRDM_CO_RPDO1))) && f->dlc == 4) {
		if (d->nmt == IRDM_CO_STATE_OPERATIONAL) {      /* latest wins */
			d->rpdo_cw = (uint16_t)(f->data[0] | (f->data[1] << 8));
			d->rpdo_torque_permille = (int16_t)(f->data[2] | (f->data[3] << 8));
		}
	} else if (!irdm_co_node_of(f, IRDM_CO_TPDO1) && !irdm_co_node_of(f, IRDM_CO_HEARTBEAT) &&
		   !irdm_co_node_of(f, IRDM_CO_SDO_TX) && !irdm_co_node_of(f, IRDM_CO_EMCY)) {
		dr->bad_frames++;                               /* nothing of ours */
	}
}

int irdm_can_drives_poll(struct irdm_can_drives *dr)
{
	struct irdm_can_frame f;
	int n = 0;

	while (irdm_can_recv(&dr->port, &f) == 1) {
		frame_in(dr, &f);
		n++;
	}
	return n;
}

void irdm_can_drives_fault(struct irdm_can_drives *dr, unsigned k, uint16_t code)
{
	struct irdm_can_frame f = { .id = IRDM_CO_EMCY + dr->d[k].node, .dlc = 8 };

	f.data[0] = (uint8_t)code;
	f.data[1] = (uint8_t)(code >> 8);
	f.data[2] = 0x01;                                       /* error register: generic */
	send(dr, &f);
	irdm_cia402_drive_fault(&dr->d[k].fsa);
}
