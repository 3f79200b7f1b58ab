/* SPDX-License-Identifier: MIT */
/*
 * CANopen frames and the CiA 402 state machine (hal/can), on the host with
 * no CAN: frames in memory.  The expected bytes are written out here from
 * the layouts of CiA 301 (NMT, SYNC, SDO, EMCY, heartbeat) and CiA 402
 * (controlword, statusword, CST mapping), as docs/canopen.md lists them;
 * they are not produced by our encoder.  The drive's transitions are the
 * profile's table, typed in: every one, and no other.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "irdm/hal/canopen.h"
#include "irdm/hal/cia402.h"

/* The frame, its listed bytes and zeros after them. */
#define EXPECT(f, id, dlc, ...) \
	expect_frame(f, id, dlc, (const uint8_t[]){ __VA_ARGS__ }, \
		     sizeof((const uint8_t[]){ __VA_ARGS__ }))

static void expect_frame(const struct irdm_can_frame *f, uint32_t id, uint8_t dlc,
			 const uint8_t *data, size_t n)
{
	uint8_t padded[8] = { 0 };

	memcpy(padded, data, n < 8 ? n : 8);
	if (f->id != id || f->dlc != dlc || memcmp(f->data, padded, 8))
		fail_msg("frame %03x [%u] %02x %02x %02x %02x %02x %02x %02x %02x, want %03x [%u]",
			 f->id, f->dlc, f->data[0], f->data[1], f->data[2], f->data[3], f->data[4],
			 f->data[5], f->data[6], f->data[7], id, dlc);
}

static struct irdm_can_frame make(uint32_t id, uint8_t dlc, const uint8_t *data)
{
	struct irdm_can_frame f = { .id = id, .dlc = dlc };

	memcpy(f.data, data, dlc);
	return f;
}

static void test_frames_sent(void **state)
{
	struct irdm_can_frame f;

	(void)state;
	assert_int_equal(irdm_co_nmt(&f, IRDM_CO_NMT_START, 3), IRDM_OK);
	EXPECT(&f, 0x000, 2, 0x01, 0x03);
	assert_int_equal(irdm_co_nmt(&f, IRDM_CO_NMT_RESET_NODE, 0), IRDM_OK); /* all nodes */
	EXPECT(&f, 0x000, 2, 0x81, 0x00);
	assert_int_equal(irdm_co_nmt(&f, IRDM_CO_NMT_STOP, 128), IRDM_EINVAL);

	assert_int_equal(irdm_co_sync(&f, 0), IRDM_OK);
	EXPECT(&f, 0x080, 0, 0);
	assert_int_equal(irdm_co_sync(&f, 5), IRDM_OK);
	EXPECT(&f, 0x080, 1, 0x05);
	assert_int_equal(irdm_co_sync(&f, 241), IRDM_EINVAL);

	/* RPDO1 of node 2: controlword 0x000F, target torque -250 per mille */
	assert_int_equal(irdm_co_rpdo_cst(&f, 2, 0x000F, -250), IRDM_OK);
	EXPECT(&f, 0x202, 4, 0x0F, 0x00, 0x06, 0xFF);
	assert_int_equal(irdm_co_rpdo_cst(&f, 0, 0, 0), IRDM_EINVAL);

	/* expedited downloads: 0x2F one byte, 0x2B two, 0x23 four */
	assert_int_equal(irdm_co_sdo_write(&f, 1, 0x6060, 0, 10, 1), IRDM_OK); /* CST */
	EXPECT(&f, 0x601, 8, 0x2F, 0x60, 0x60, 0x00, 0x0A);
	assert_int_equal(irdm_co_sdo_write(&f, 1, 0x1017, 0, 100, 2), IRDM_OK); /* heartbeat */
	EXPECT(&f, 0x601, 8, 0x2B, 0x17, 0x10, 0x00, 0x64, 0x00);
	assert_int_equal(irdm_co_sdo_write(&f, 3, 0x1A00, 1, 0x60410010, 4), IRDM_OK);
	EXPECT(&f, 0x603, 8, 0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60);
	assert_int_equal(irdm_co_sdo_write(&f, 3, 0x1A00, 1, 0, 5), IRDM_EINVAL);
	assert_int_equal(irdm_co_sdo_read(&f, 3, 0x6041, 0), IRDM_OK);
	EXPECT(&f, 0x603, 8, 0x40, 0x41, 0x60, 0x00);
}

static void test_frames_received(void **state)
{
	struct irdm_can_frame f;
	enum irdm_co_nmt_state st;
	struct irdm_co_emcy e;
	uint16_t sw;
	int32_t pos;
	uint32_t v, abort_code;
	unsigned size;

	(void)state;
	/* TPDO1 of node 1: statusword 0x0237, position 0x12345678; then -1 */
	f = make(0x181, 6, (const uint8_t[]){ 0x37, 0x02, 0x78, 0x56, 0x34, 0x12 });
	assert_int_equal(irdm_co_tpdo_cst(&f, 1, &sw, &pos), IRDM_OK);
	assert_int_equal(sw, 0x0237);
	assert_int_equal(pos, 0x12345678);
	f = make(0x181, 6, (const uint8_t[]){ 0x27, 0x00, 0xFF, 0xFF, 0xFF, 0xFF });
	assert_int_equal(irdm_co_tpdo_cst(&f, 1, &sw, &pos), IRDM_OK);
	assert_int_equal(pos, -1);
	/* malformed: wrong length, another node, another function */
	f.dlc = 5;
	assert_int_equal(irdm_co_tpdo_cst(&f, 1, &sw, &pos), IRDM_EFORMAT);
	f.dlc = 6;
	assert_int_equal(irdm_co_tpdo_cst(&f, 2, &sw, &pos), IRDM_EFORMAT);
	f.id = 0x281;
	assert_int_equal(irdm_co_tpdo_cst(&f, 1, &sw, &pos), IRDM_EFORMAT);

	f = make(0x705, 1, (const uint8_t[]){ 0x05 });
	assert_int_equal(irdm_co_heartbeat(&f, 5, &st), IRDM_OK);
	assert_int_equal(st, IRDM_CO_STATE_OPERATIONAL);
	f.data[0] = 0x85; /* node guarding's toggle bit */
	assert_int_equal(irdm_co_heartbeat(&f, 5, &st), IRDM_OK);
	assert_int_equal(st, IRDM_CO_STATE_OPERATIONAL);
	f.data[0] = 0x7F;
	assert_int_equal(irdm_co_heartbeat(&f, 5, &st), IRDM_OK);
	assert_int_equal(st, IRDM_CO_STATE_PRE_OPERATIONAL);
	f.data[0] = 0x03; /* no such state */
	assert_int_equal(irdm_co_heartbeat(&f, 5, &st), IRDM_EFORMAT);

	/* EMCY of node 2: 0x2310 (current: continuous over-current), register 0x04 */
	f = make(0x082, 8, (const uint8_t[]){ 0x10, 0x23, 0x04, 1, 2, 3, 4, 5 });
	assert_int_equal(irdm_co_emcy(&f, 2, &e), IRDM_OK);
	assert_int_equal(e.code, 0x2310);
	assert_int_equal(e.reg, 0x04);
	assert_int_equal(e.vendor[4], 5);
	assert_string_equal(irdm_co_emcy_class(e.code), "current");
	assert_int_equal(irdm_co_node_of(&f, IRDM_CO_EMCY), 2);
	f.id = 0x080; /* the SYNC, not an EMCY */
	assert_int_equal(irdm_co_node_of(&f, IRDM_CO_EMCY), 0);
	assert_int_equal(irdm_co_emcy(&f, 0, &e), IRDM_EFORMAT);

	/* SDO answers from node 1 about 0x6060:00 */
	f = make(0x581, 8, (const uint8_t[]){ 0x60, 0x60, 0x60, 0x00, 0, 0, 0, 0 });
	assert_int_equal(irdm_co_sdo_answer(&f, 1, 0x6060, 0, &v, &size, &abort_code), IRDM_OK);
	assert_int_equal(size, 0);
	f = make(0x581, 8, (const uint8_t[]){ 0x80, 0x60, 0x60, 0x00, 0x11, 0x00, 0x09, 0x06 });
	assert_int_equal(irdm_co_sdo_answer(&f, 1, 0x6060, 0, &v, &size, &abort_code), IRDM_EHW);
	assert_int_equal(abort_code, 0x06090011);
	assert_string_equal(irdm_co_abort_name(abort_code), "sub-index does not exist");
	assert_string_equal(irdm_co_abort_name(0x06020000),
			    "object does not exist in the object dictionary");
	assert_string_equal(irdm_co_abort_name(0x12345678), "unknown abort code");
	/* an expedited upload of 2 bytes: 0x4B */
	f = make(0x581, 8, (const uint8_t[]){ 0x4B, 0x41, 0x60, 0x00, 0x37, 0x02, 0xEE, 0xEE });
	assert_int_equal(irdm_co_sdo_answer(&f, 1, 0x6041, 0, &v, &size, &abort_code), IRDM_OK);
	assert_int_equal(size, 2);
	assert_int_equal(v, 0x0237);
	/* garbage: another object, a segmented answer, a short frame, another node */
	assert_int_equal(irdm_co_sdo_answer(&f, 1, 0x6040, 0, &v, &size, &abort_code),
			 IRDM_EFORMAT);
	f.data[0] = 0x41;
	assert_int_equal(irdm_co_sdo_answer(&f, 1, 0x6041, 0, &v, &size, &abort_code),
			 IRDM_EFORMAT);
	f.data[0] = 0x4B;
	f.dlc = 7;
	assert_int_equal(irdm_co_sdo_answer(&f, 1, 0x6041, 0, &v, &size, &abort_code),
			 IRDM_EFORMAT);
	f.dlc = 8;
	assert_int_equal(irdm_co_sdo_answer(&f, 2, 0x6041, 0, &v, &size, &abort_code),
			 IRDM_EFORMAT);
}

/* ---- CiA 402 ---- */

#define SOD IRDM_CIA402_SWITCH_ON_DISABLED
#define RTSO IRDM_CIA402_READY_TO_SWITCH_ON
#define SO IRDM_CIA402_SWITCHED_ON
#define OE IRDM_CIA402_OPERATION_ENABLED
#define QSA IRDM_CIA402_QUICK_STOP_ACTIVE
#define FRA IRDM_CIA402_FAULT_REACTION_ACTIVE
#define FLT IRDM_CIA402_FAULT

static void test_statusword_decode(void **state)
{
	static const struct {
		uint16_t sw;
		enum irdm_cia402_state s;
	} cases[] = {
		/* the profile's patterns, with bits the masks ignore set too
		 * (4 voltage enabled, 7 warning, 9 remote, 10 target reached) */
		{ 0x0000, IRDM_CIA402_NOT_READY },
		{ 0x0610, IRDM_CIA402_NOT_READY },
		{ 0x0040, SOD },
		{ 0x0670, SOD },
		{ 0x0021, RTSO },
		{ 0x0631, RTSO },
		{ 0x0023, SO },
		{ 0x02B3, SO },
		{ 0x0027, OE },
		{ 0x0637, OE },
		{ 0x0007, QSA },
		{ 0x0617, QSA },
		{ 0x000F, FRA },
		{ 0x003F, FRA },
		{ 0x0008, FLT },
		{ 0x0638, FLT },
		{ 0x0001, IRDM_CIA402_UNKNOWN },
		{ 0x0061, IRDM_CIA402_UNKNOWN },
	};

	(void)state;
	for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++)
		if (irdm_cia402_decode(cases[k].sw) != cases[k].s)
			fail_msg("statusword 0x%04x: %s, want %s", cases[k].sw,
				 irdm_cia402_name(irdm_cia402_decode(cases[k].sw)),
				 irdm_cia402_name(cases[k].s));
	/* the drive's own statuswords decode to their states */
	for (int s = IRDM_CIA402_NOT_READY; s < IRDM_CIA402_UNKNOWN; s++)
		assert_int_equal(irdm_cia402_decode(irdm_cia402_statusword(s)), s);
}

/*
 * The drive's transitions: the profile's numbered table (2-12, 15, 16 by
 * controlword; 13-14 by fault), each from its state with its command, and
 * every other command from every state leaves it where it is.
 */
static void test_drive_transitions(void **state)
{
	static const uint16_t cmds[] = { 0x0000, 0x0002, 0x0006, 0x0007, 0x000F };
	static const struct {
		enum irdm_cia402_state from;
		uint16_t cw;
		enum irdm_cia402_state to;
	} table[] = {
		{ SOD, 0x0006, RTSO }, /* 2 */
		{ RTSO, 0x0007, SO },  /* 3 */
		{ RTSO, 0x000F, OE },  /* 3 + 4 (switch on + enable operation) */
		{ SO, 0x000F, OE },    /* 4 */
		{ OE, 0x0007, SO },    /* 5 (disable operation) */
		{ SO, 0x0006, RTSO },  /* 6 */
		{ RTSO, 0x0000, SOD }, /* 7 (disable voltage) */
		{ RTSO, 0x0002, SOD }, /* 7 (quick stop) */
		{ OE, 0x0006, RTSO },  /* 8 */
		{ OE, 0x0000, SOD },   /* 9 */
		{ SO, 0x0000, SOD },   /* 10 (disable voltage) */
		{ SO, 0x0002, SOD },   /* 10 (quick stop) */
		{ OE, 0x0002, QSA },   /* 11 */
		{ QSA, 0x0000, SOD },  /* 12 */
		{ QSA, 0x000F, OE },   /* 16 */
	};
	static const enum irdm_cia402_state states[] = { SOD, RTSO, SO, OE, QSA };
	struct irdm_cia402_drive d;

	(void)state;
	for (size_t a = 0; a < sizeof(states) / sizeof(states[0]); a++)
		for (size_t c = 0; c < sizeof(cmds) / sizeof(cmds[0]); c++) {
			enum irdm_cia402_state want = states[a];

			for (size_t t = 0; t < sizeof(table) / sizeof(table[0]); t++)
				if (table[t].from == states[a] && table[t].cw == cmds[c])
					want = table[t].to;
			d.state = states[a];
			d.last_cw = 0;
			irdm_cia402_drive_command(&d, cmds[c]);
			if (d.state != want)
				fail_msg("%s + 0x%04x: %s, want %s", irdm_cia402_name(states[a]),
					 cmds[c], irdm_cia402_name(d.state), irdm_cia402_name(want));
		}
	/* 13, 14: a fault from any state, settled; 15 on bit 7's rising edge only */
	for (size_t a = 0; a < sizeof(states) / sizeof(states[0]); a++) {
		d.state = states[a];
		irdm_cia402_drive_fault(&d);
		assert_int_equal(d.state, FRA);
		irdm_cia402_drive_command(&d, 0x000F); /* no command leaves FRA */
		assert_int_equal(d.state, FRA);
		irdm_cia402_drive_settle(&d);
		assert_int_equal(d.state, FLT);
	}
	d.last_cw = 0x0080;
	irdm_cia402_drive_command(&d, 0x0080); /* held high: no edge */
	assert_int_equal(d.state, FLT);
	for (size_t c = 0; c < sizeof(cmds) / sizeof(cmds[0]); c++) {
		irdm_cia402_drive_command(&d, cmds[c]); /* commands do not leave FAULT */
		assert_int_equal(d.state, FLT);
	}
	irdm_cia402_drive_command(&d, 0x0080); /* the edge: 15 */
	assert_int_equal(d.state, SOD);
}

/* The master brings a drive to operation enabled; a fault waits for a reset. */
static void test_master_enables(void **state)
{
	struct irdm_cia402_drive d;
	uint16_t cw = 0;
	int steps;

	(void)state;
	irdm_cia402_drive_init(&d);
	for (steps = 0; steps < 10 && d.state != OE; steps++) {
		cw = irdm_cia402_next(irdm_cia402_decode(irdm_cia402_statusword(d.state)), false, cw);
		irdm_cia402_drive_command(&d, cw);
	}
	assert_int_equal(d.state, OE);
	assert_int_equal(steps, 3); /* 2, 3, 4 */
	/* quick stop, then back */
	irdm_cia402_drive_command(&d, IRDM_CIA402_CW_QUICK_STOP);
	assert_int_equal(d.state, QSA);
	for (steps = 0; steps < 10 && d.state != OE; steps++) {
		cw = irdm_cia402_next(irdm_cia402_decode(irdm_cia402_statusword(d.state)), false, cw);
		irdm_cia402_drive_command(&d, cw);
	}
	assert_int_equal(d.state, OE);
	/* a fault is held without a reset request, however long */
	irdm_cia402_drive_fault(&d);
	irdm_cia402_drive_settle(&d);
	for (steps = 0; steps < 10; steps++) {
		cw = irdm_cia402_next(irdm_cia402_decode(irdm_cia402_statusword(d.state)), false, cw);
		irdm_cia402_drive_command(&d, cw);
	}
	assert_int_equal(d.state, FLT);
	/* with one: reset, then up */
	for (steps = 0; steps < 10 && d.state != OE; steps++) {
		cw = irdm_cia402_next(irdm_cia402_decode(irdm_cia402_statusword(d.state)), true, cw);
		irdm_cia402_drive_command(&d, cw);
	}
	assert_int_equal(d.state, OE);
	assert_int_equal(steps, 4); /* 15, 2, 3, 4 */
}

/*
 * Frame lengths on the wire: 47 + 8 n bits, and with worst-case stuffing
 * 111-135 for 8 data bytes and 47-55 for none; three axes' SYNC + 3 RPDO +
 * 3 TPDO of 8 bytes in 1 ms at 1 Mbit/s load the bus 71.3-86.5 %.
 */
static void test_frame_bits(void **state)
{
	unsigned lo = irdm_can_frame_bits(0, false) + 6 * irdm_can_frame_bits(8, false);
	unsigned hi = irdm_can_frame_bits(0, true) + 6 * irdm_can_frame_bits(8, true);

	(void)state;
	assert_int_equal(irdm_can_frame_bits(8, false), 111);
	assert_int_equal(irdm_can_frame_bits(8, true), 135);
	assert_int_equal(irdm_can_frame_bits(0, false), 47);
	assert_int_equal(irdm_can_frame_bits(0, true), 55);
	assert_int_equal(lo, 713);
	assert_int_equal(hi, 865);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_frames_sent),
		cmocka_unit_test(test_frames_received),
		cmocka_unit_test(test_statusword_decode),
		cmocka_unit_test(test_drive_transitions),
		cmocka_unit_test(test_master_enables),
		cmocka_unit_test(test_frame_bits),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
