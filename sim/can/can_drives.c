/* SPDX-License-Identifier: MIT */
/* CiA 402 drives in emulation (irdm/can_drives.h). */
#include <math.h>
#include <string.h>

#include "irdm/sim/can_drives.h"
#include "irdm/error.h"

#define MODE_CST 10
#define DEVICE_TYPE 0x00020192u /* 0x1000: CiA 402 (0x0192), servo drive */
#define VENDOR_ID 0x00000000u   /* 0x1018:01: none registered (an emulator) */
#define PRODUCT_CODE 0x00000402u
#define REVISION 0x00010000u
#define ABORT_FAULT 1 /* 0x6007 (CiA 402): its default */
#define ABORT_DISABLE_VOLTAGE 2
#define ABORT_QUICK_STOP 3
#define EMCY_SYNC_LENGTH 0x8240u  /* unexpected SYNC data length */
#define EMCY_HEARTBEAT 0x8130u    /* heartbeat (life guard) lost */
#define EMCY_RPDO_TIMEOUT 0x8250u /* RPDO time-out */
/* the CST mapping the master writes: RPDO1 0x6040 + 0x6071, TPDO1 0x6041 + 0x6064 */
static const uint32_t rpdo_map[IRDM_CAN_PDO_ENTRIES] = { 0x60400010, 0x60710010 };
static const uint32_t tpdo_map[IRDM_CAN_PDO_ENTRIES] = { 0x60410010, 0x60640020 };

static void send(struct irdm_can_drives *dr, const struct irdm_can_frame *f)
{
	(void)irdm_can_send(&dr->port, f); /* a full queue drops it, as a wire would */
}

static void heartbeat(struct irdm_can_drives *dr, struct irdm_can_drive *d)
{
	struct irdm_can_frame f = { .id = IRDM_CO_HEARTBEAT + d->node, .dlc = 1 };

	f.data[0] = (uint8_t)d->nmt;
	if (!d->no_heartbeat)
		send(dr, &f);
	d->heartbeat_next_us = (dr->wall_heartbeat ? dr->wall_us : dr->now_us) +
			       1000ull * d->heartbeat_ms;
}

static void boot(struct irdm_can_drives *dr, struct irdm_can_drive *d)
{
	d->nmt = IRDM_CO_STATE_BOOTUP;
	heartbeat(dr, d);
	d->nmt = IRDM_CO_STATE_PRE_OPERATIONAL;
	irdm_cia402_drive_init(&d->fsa);
	/* a reset restores the communication objects from the stored configuration */
	irdm_can_pdo_boot(&d->rpdo1, IRDM_CO_RPDO1 + d->node, rpdo_map);
	irdm_can_pdo_boot(&d->tpdo1, IRDM_CAN_PDO_NO_RTR | (IRDM_CO_TPDO1 + d->node), tpdo_map);
	d->rpdo_cw = 0;
	d->rpdo_torque_permille = 0;
	d->cycle_us = 0;
	d->sync_overflow = 0;
	d->hb_consumer = 0;
	d->abort_option = ABORT_FAULT;
	d->master_beat_seen = false;
	d->rpdo_seen = false;
	d->lost_code = 0;
}

/* The clock the deadlines run on: the heartbeats' (SYNCs' or the wall's). */
static uint64_t deadline_now(const struct irdm_can_drives *dr)
{
	return dr->wall_heartbeat ? dr->wall_us : dr->now_us;
}

/*
 * The connection to the master is lost (code: which deadline): say so by
 * EMCY (bytes 3-4: the torque applied from now on, per mille) and take
 * the reaction 0x6007 names; all but "none" zero the torque at once.
 */
static void connection_lost(struct irdm_can_drives *dr, struct irdm_can_drive *d, uint16_t code)
{
	struct irdm_can_frame f = { .id = IRDM_CO_EMCY + d->node, .dlc = 8 };
	uint16_t cw = d->rpdo_cw;

	d->lost_code = code;
	d->lost_at_us = deadline_now(dr);
	switch (d->abort_option) {
	case ABORT_FAULT:
		irdm_cia402_drive_fault(&d->fsa);
		irdm_cia402_drive_settle(&d->fsa);
		cw = IRDM_CIA402_CW_DISABLE_VOLTAGE;
		break;
	case ABORT_DISABLE_VOLTAGE:
		cw = IRDM_CIA402_CW_DISABLE_VOLTAGE;
		irdm_cia402_drive_command(&d->fsa, cw);
		break;
	case ABORT_QUICK_STOP:
		cw = IRDM_CIA402_CW_QUICK_STOP;
		irdm_cia402_drive_command(&d->fsa, cw);
		break;
	default:
		break; /* 0: no reaction, the torque stays */
	}
	if (d->abort_option != 0) {
		d->rpdo_cw = cw;
		d->rpdo_torque_permille = 0;
	}
	f.data[0] = (uint8_t)code;
	f.data[1] = (uint8_t)(code >> 8);
	f.data[2] = 0x11; /* error register: generic + communication */
	f.data[3] = (uint8_t)(uint16_t)d->rpdo_torque_permille;
	f.data[4] = (uint8_t)((uint16_t)d->rpdo_torque_permille >> 8);
	send(dr, &f);
}

/* The master's heartbeat and RPDO1 deadlines of drive d at now_us; the
 * next time one falls due (UINT64_MAX: none). */
static uint64_t watch(struct irdm_can_drives *dr, struct irdm_can_drive *d, uint64_t now_us)
{
	uint64_t hb_us = 1000ull * (d->hb_consumer & 0xFFFFu), ev_us = 1000ull * d->rpdo1.event_timer_ms;
	uint64_t next = UINT64_MAX;

	if (d->lost_code || d->nmt == IRDM_CO_STATE_STOPPED)
		return next;
	if (hb_us && d->master_beat_seen) {
		if (now_us > d->master_beat_us + hb_us) {
			connection_lost(dr, d, EMCY_HEARTBEAT);
			return next;
		}
		next = d->master_beat_us + hb_us + 1;
	}
	if (ev_us && d->rpdo_seen && d->nmt == IRDM_CO_STATE_OPERATIONAL) {
		if (now_us > d->rpdo_us + ev_us) {
			connection_lost(dr, d, EMCY_RPDO_TIMEOUT);
			return UINT64_MAX;
		}
		if (d->rpdo_us + ev_us + 1 < next)
			next = d->rpdo_us + ev_us + 1;
	}
	return next;
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
	memcpy(f.data + 1, req->data + 1, 3); /* index, sub-index */
	if (d->sdo_wrong)
		f.data[1] ^= 0x01; /* about another object */
	for (int k = 0; k < 4; k++)
		f.data[4 + k] = (uint8_t)(data >> (8 * k));
	send(dr, &f);
}

/* The value of a readable object, or an abort code. */
static uint32_t object_read(struct irdm_can_drives *dr, struct irdm_can_drive *d, uint16_t index,
			    uint8_t sub, uint32_t *v, unsigned *size)
{
	int32_t counts[3] = { 0, 0, 0 };

	if (index == 0x1018) {
		static const uint32_t identity[5] = { 4, VENDOR_ID, PRODUCT_CODE, REVISION, 0 };

		if (sub > 4)
			return 0x06090011;
		*v = sub == 4 ? d->node : identity[sub], *size = sub == 0 ? 1 : 4;
		return 0;
	}
	if (index == 0x1400 || index == 0x1800) {
		const struct irdm_can_pdo *p = index == 0x1400 ? &d->rpdo1 : &d->tpdo1;

		switch (sub) {
		case 1:
			*v = p->cob_id, *size = 4;
			return 0;
		case 2:
			*v = p->transmission, *size = 1;
			return 0;
		case 5:
			*v = p->event_timer_ms, *size = 2;
			return 0;
		default:
			return 0x06090011;
		}
	}
	if (index == 0x1016) {
		if (sub > 1)
			return 0x06090011;
		*v = sub == 0 ? 1 : d->hb_consumer, *size = sub == 0 ? 1 : 4;
		return 0;
	}
	if (sub != 0)
		return 0x06090011;
	switch (index) {
	case 0x1000:
		*v = DEVICE_TYPE, *size = 4;
		return 0;
	case 0x1006:
		*v = d->cycle_us, *size = 4;
		return 0;
	case 0x1019:
		*v = d->sync_overflow, *size = 1;
		return 0;
	case 0x6007:
		*v = (uint16_t)d->abort_option, *size = 2;
		return 0;
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

/* 0x1016: one consumer entry (node << 16 | time ms; 0 off). */
static uint32_t write_consumer(struct irdm_can_drive *d, uint8_t sub, uint32_t v, unsigned size)
{
	if (sub == 0)
		return 0x06010002;
	if (sub != 1)
		return 0x06090011;
	if (size != 4)
		return 0x06070010;
	if (v & 0xFF000000u || ((v >> 16) & 0xFF) > IRDM_CO_NODE_MAX)
		return 0x06090030;
	d->hb_consumer = v;
	d->master_beat_seen = false; /* runs from the next heartbeat heard */
	return 0;
}

/* A download: the abort code, 0 when taken. */
static uint32_t object_write(struct irdm_can_drive *d, uint16_t index, uint8_t sub, uint32_t v,
			     unsigned size)
{
	switch (index) {
	case 0x1400:
		return irdm_can_pdo_write_comm(&d->rpdo1, sub, v, size);
	case 0x1800:
		return irdm_can_pdo_write_comm(&d->tpdo1, sub, v, size);
	case 0x1600:
		return irdm_can_pdo_write_map(&d->rpdo1, sub, v, size);
	case 0x1A00:
		return irdm_can_pdo_write_map(&d->tpdo1, sub, v, size);
	}
	if (index == 0x1016)
		return write_consumer(d, sub, v, size);
	if (index == 0x1018 || index == 0x1000)
		return 0x06010002;
	if (sub != 0)
		return index == 0x6060 || index == 0x1017 || index == 0x6076 || index == 0x1006 ||
				       index == 0x1019 || index == 0x6007 ?
			       0x06090011 :
			       0x06020000;
	switch (index) {
	case 0x1006:
		if (size != 4)
			return 0x06070010;
		d->cycle_us = v;
		return 0;
	case 0x1019:
		if (size != 1)
			return 0x06070010;
		/* CiA 301: only while no cycle period is set */
		if (d->cycle_us != 0)
			return 0x08000022;
		if (v == 1 || v > 240)
			return 0x06090030;
		d->sync_overflow = (uint8_t)v;
		return 0;
	case 0x6007:
		if (size != 2)
			return 0x06070010;
		if ((int16_t)v < 0 || (int16_t)v > ABORT_QUICK_STOP)
			return 0x06090030; /* no vendor reactions here */
		d->abort_option = (int16_t)v;
		return 0;
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
	if (cmd == 0x40) { /* upload */
		abort_code = object_read(dr, d, index, sub, &v, &size);
		if (abort_code)
			sdo_reply(dr, d, f, 0x80, abort_code);
		else
			sdo_reply(dr, d, f, (uint8_t)(0x43 | ((4 - size) << 2)), v);
		return;
	}
	if ((cmd & 0xE3) != 0x23) { /* only expedited downloads */
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

/* The flood: count frames of the highest priority but NMT's. */
static void flood(struct irdm_can_drives *dr, uint32_t count)
{
	struct irdm_can_frame f = { .id = IRDM_CAN_FLOOD_ID, .dlc = 8 };

	memset(f.data, 0xFF, sizeof(f.data));
	for (uint32_t k = 0; k < count; k++)
		if (irdm_can_send(&dr->port, &f) == IRDM_OK)
			dr->flood_sent++;
}

static void fire(struct irdm_can_drives *dr, const struct irdm_can_fault *f)
{
	struct irdm_can_drive *d = drive_of(dr, f->node);

	dr->faults_fired++;
	switch (f->kind) {
	case IRDM_CAN_FAULT_DROP:
		d->drop_tpdos = f->count;
		break;
	case IRDM_CAN_FAULT_DELAY:
		d->delay_tpdos = f->count;
		d->delay_us = f->delay_us;
		break;
	case IRDM_CAN_FAULT_HEARTBEAT_STOP:
		d->no_heartbeat = true;
		break;
	case IRDM_CAN_FAULT_EMCY:
		irdm_can_drives_fault(dr, (unsigned)(d - dr->d), f->code);
		break;
	case IRDM_CAN_FAULT_STATE:
		irdm_cia402_drive_fault(&d->fsa);
		break;
	case IRDM_CAN_FAULT_SDO_WRONG:
		d->sdo_wrong = true;
		break;
	case IRDM_CAN_FAULT_FLOOD:
		flood(dr, f->count);
		break;
	}
}

/* A TPDO out, unless a fault drops or holds it. */
static void tpdo_out(struct irdm_can_drives *dr, struct irdm_can_drive *d,
		     const struct irdm_can_frame *f)
{
	if (d->drop_tpdos) {
		d->drop_tpdos--;
		dr->tpdos_dropped++;
		return;
	}
	if (d->held) { /* the older one first: order kept */
		send(dr, &d->held_frame);
		d->held = false;
	}
	if (d->delay_tpdos) {
		d->delay_tpdos--;
		d->held = true;
		d->held_frame = *f;
		d->held_due_us = dr->wall_us + d->delay_us;
		dr->tpdos_delayed++;
		return;
	}
	send(dr, f);
	dr->tpdos_sent++;
}

/*
 * Does drive d take a SYNC of dlc bytes?  Its 0x1019 says the length; any
 * other is answered as CiA 301 says: EMCY 0x8240, and the drive leaves
 * operation for pre-operational (its PDOs stop).
 */
static bool sync_accepted(struct irdm_can_drives *dr, struct irdm_can_drive *d, uint8_t dlc)
{
	struct irdm_can_frame f = { .id = IRDM_CO_EMCY + d->node, .dlc = 8 };

	if (dlc == (d->sync_overflow ? 1 : 0))
		return true;
	if (d->nmt == IRDM_CO_STATE_STOPPED)
		return false;
	dr->sync_length_errors++;
	f.data[0] = (uint8_t)EMCY_SYNC_LENGTH;
	f.data[1] = (uint8_t)(EMCY_SYNC_LENGTH >> 8);
	f.data[2] = 0x11; /* error register: generic + communication */
	f.data[3] = dlc;
	send(dr, &f);
	d->nmt = IRDM_CO_STATE_PRE_OPERATIONAL;
	return false;
}

/* SYNC: sample and send TPDOs, apply the set-points, move the arm a period. */
static void sync(struct irdm_can_drives *dr, uint8_t dlc)
{
	int32_t counts[3] = { 0, 0, 0 };
	double tau[3] = { 0, 0, 0 };
	bool taken[IRDM_CAN_DRIVES_MAX];

	for (unsigned k = 0; k < dr->n; k++)
		taken[k] = sync_accepted(dr, &dr->d[k], dlc);
	dr->syncs++;
	for (unsigned k = 0; k < dr->n_faults; k++)
		if (dr->fault[k].at_sync == dr->syncs)
			fire(dr, &dr->fault[k]);
	irdm_sim_device_read_counts(&dr->arm, counts);
	for (unsigned k = 0; k < dr->n; k++) {
		struct irdm_can_drive *d = &dr->d[k];
		struct irdm_can_frame f = { .id = IRDM_CO_TPDO1 + d->node, .dlc = 6 };
		uint16_t sw;

		irdm_cia402_drive_settle(&d->fsa);
		if (d->nmt == IRDM_CO_STATE_OPERATIONAL && taken[k])
			irdm_cia402_drive_command(&d->fsa, d->rpdo_cw);
		sw = irdm_cia402_statusword(d->fsa.state);
		f.data[0] = (uint8_t)sw;
		f.data[1] = (uint8_t)(sw >> 8);
		for (int b = 0; b < 4; b++)
			f.data[2 + b] = (uint8_t)((uint32_t)counts[k] >> (8 * b));
		if (d->nmt == IRDM_CO_STATE_OPERATIONAL && taken[k] && irdm_can_pdo_live(&d->tpdo1))
			tpdo_out(dr, d, &f);
		tau[k] = joint_torque(dr, k);
	}
	irdm_sim_device_set_torque(&dr->arm, tau);
	if (dr->before_step)
		dr->before_step(dr->hook_ctx, dr);
	if (dr->docked && (tau[0] != 0 || tau[1] != 0 || tau[2] != 0))
		dr->docked = false;
	if (!dr->docked)
		irdm_sim_device_step(&dr->arm, dr->period_s);
	dr->now_us += (uint64_t)llround(dr->period_s * 1e6);
	for (unsigned k = 0; k < dr->n && !dr->wall_heartbeat; k++) {
		if (dr->d[k].heartbeat_ms && dr->now_us >= dr->d[k].heartbeat_next_us)
			heartbeat(dr, &dr->d[k]);
		(void)watch(dr, &dr->d[k], dr->now_us);
	}
}

/* A heartbeat on the bus: the master's, for each drive that consumes it. */
static void master_beat(struct irdm_can_drives *dr, const struct irdm_can_frame *f)
{
	unsigned node = f->id - IRDM_CO_HEARTBEAT;

	for (unsigned k = 0; k < dr->n; k++) {
		struct irdm_can_drive *d = &dr->d[k];

		if (f->dlc != 1 || !(d->hb_consumer & 0xFFFFu) || ((d->hb_consumer >> 16) & 0xFF) != node)
			continue;
		d->master_beat_seen = true;
		d->master_beat_us = deadline_now(dr);
	}
}

static void frame_in(struct irdm_can_drives *dr, const struct irdm_can_frame *f)
{
	struct irdm_can_drive *d;

	if (f->id == IRDM_CO_NMT && f->dlc == 2) {
		nmt(dr, f);
	} else if (f->id == IRDM_CO_SYNC && f->dlc <= 8) {
		dr->sync_counter = f->dlc ? f->data[0] : 0;
		sync(dr, f->dlc);
	} else if ((d = drive_of(dr, irdm_co_node_of(f, IRDM_CO_SDO_RX)))) {
		sdo(dr, d, f);
	} else if ((d = drive_of(dr, irdm_co_node_of(f, IRDM_CO_RPDO1))) && f->dlc == 4) {
		/* latest wins; a PDO not valid is not listened to */
		if (d->nmt == IRDM_CO_STATE_OPERATIONAL && irdm_can_pdo_live(&d->rpdo1) &&
		    !d->lost_code) {
			d->rpdo_cw = (uint16_t)(f->data[0] | (f->data[1] << 8));
			d->rpdo_torque_permille = (int16_t)(f->data[2] | (f->data[3] << 8));
			d->rpdo_seen = true;
			d->rpdo_us = deadline_now(dr);
		}
	} else if (irdm_co_node_of(f, IRDM_CO_HEARTBEAT)) {
		master_beat(dr, f); /* (our own drives' beats are not ours to watch) */
	} else if (!irdm_co_node_of(f, IRDM_CO_TPDO1) && !irdm_co_node_of(f, IRDM_CO_SDO_TX) &&
		   !irdm_co_node_of(f, IRDM_CO_EMCY)) {
		dr->bad_frames++; /* nothing of ours */
	}
}

int irdm_can_drives_poll(struct irdm_can_drives *dr)
{
	struct irdm_can_frame f;
	int n = 0, rc;

	while ((rc = irdm_can_recv(&dr->port, &f)) == 1) {
		frame_in(dr, &f);
		n++;
	}
	return rc == IRDM_EIO ? IRDM_EIO : n;
}

uint64_t irdm_can_drives_wall(struct irdm_can_drives *dr, uint64_t now_us)
{
	uint64_t next = UINT64_MAX, due;

	dr->wall_us = now_us;
	for (unsigned k = 0; k < dr->n; k++) {
		struct irdm_can_drive *d = &dr->d[k];

		if (d->held && now_us >= d->held_due_us) {
			send(dr, &d->held_frame);
			d->held = false;
		}
		if (d->held && d->held_due_us < next)
			next = d->held_due_us;
		if (!dr->wall_heartbeat)
			continue;
		due = watch(dr, d, now_us);
		if (due < next)
			next = due;
		if (!d->heartbeat_ms)
			continue;
		if (now_us >= d->heartbeat_next_us)
			heartbeat(dr, d);
		if (d->heartbeat_next_us < next)
			next = d->heartbeat_next_us;
	}
	return next;
}

int irdm_can_drives_schedule(struct irdm_can_drives *dr, const struct irdm_can_fault *f)
{
	if (f->kind != IRDM_CAN_FAULT_FLOOD && !drive_of(dr, f->node))
		return IRDM_EINVAL;
	if (dr->n_faults == IRDM_CAN_FAULTS_MAX)
		return IRDM_ENOMEM;
	if (f->at_sync == 0)
		fire(dr, f);
	else
		dr->fault[dr->n_faults++] = *f;
	return IRDM_OK;
}

void irdm_can_drives_fault(struct irdm_can_drives *dr, unsigned k, uint16_t code)
{
	struct irdm_can_frame f = { .id = IRDM_CO_EMCY + dr->d[k].node, .dlc = 8 };

	f.data[0] = (uint8_t)code;
	f.data[1] = (uint8_t)(code >> 8);
	f.data[2] = 0x01; /* error register: generic */
	send(dr, &f);
	irdm_cia402_drive_fault(&dr->d[k].fsa);
}
