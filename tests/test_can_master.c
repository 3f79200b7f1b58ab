/* SPDX-License-Identifier: MIT */
/*
 * The CANopen master (irdm/can_master.h) against the CiA 402 drive
 * emulator (sim/can) on the in-memory bus, every frame the master sends
 * logged through the bus's tap.  The expected bytes are the standard's
 * layouts written out here by hand (docs/canopen.md), not produced by the
 * frame builders the master uses.  Checked: the set-up SDO sequence (CiA
 * 301's PDO mapping procedure included, byte by byte) and each abort
 * named, on a PDO object too; every axis reaching operation enabled; the
 * fault runs (heartbeat stops, EMCY, drive fault, TPDOs dropped, link
 * down) each ending with disable voltage + zero torque to every axis
 * within two periods and one line naming the drive; malformed and
 * unknown frames counted, never trusted; the bus load against a hand computation; one
 * RPDO per axis per SYNC and the SYNC counter.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "irdm/sim/can_drives.h"
#include "irdm/hal/can_master.h"
#include "irdm/sim/can_membus.h"
#include "irdm/error.h"

#include "support/strict_mode.h"

#define LOG_MAX 8192

struct logged {
	struct irdm_can_frame f;
	uint64_t period; /* the master's period when it was sent */
};

static struct irdm_can_membus bus;
static struct irdm_can_drives dr;
static struct irdm_can_master m;
static struct irdm_can_port master_port, drives_port, rogue;
static struct irdm_device_config dev;
static struct irdm_sim_params params;
static struct logged sent[LOG_MAX]; /* what the master sent */
static unsigned n_sent;
static char err[256];

/* A port in front of the master's endpoint that can go down (bus-off),
 * or say "nothing" once before every frame (as SocketCAN does after an
 * error frame). */
static bool rx_down, tx_down, rx_hiccup, hiccup_said;

static int wrap_send(void *ctx, const struct irdm_can_frame *f)
{
	(void)ctx;
	return tx_down ? IRDM_EIO : irdm_can_send(&master_port, f);
}

static int wrap_recv(void *ctx, struct irdm_can_frame *f)
{
	(void)ctx;
	if (rx_hiccup && !hiccup_said) {
		hiccup_said = true;
		return 0;
	}
	hiccup_said = false;
	return rx_down ? IRDM_EIO : irdm_can_recv(&master_port, f);
}

static const struct irdm_can_port_ops wrap_ops = { wrap_send, wrap_recv };
static const struct irdm_can_port wrapped = { &wrap_ops, NULL };

static void tap(void *ctx, const struct irdm_can_frame *f, unsigned from)
{
	(void)ctx;
	if (from == 0 && n_sent < LOG_MAX)
		sent[n_sent++] = (struct logged){ *f, m.period };
}

static void drives_turn(void *ctx)
{
	(void)ctx;
	irdm_can_drives_poll(&dr);
}

static struct irdm_can_master_cfg cfg_3axes(void)
{
	struct irdm_can_master_cfg c = {
		.n_axes = 3,
		.period_us = 1000,
		.bitrate = 1000000,
		.sync_counter = false,
		.heartbeat_ms = 10,
		.heartbeat_timeout_ms = 30,
		.tpdo_missing_periods = 3,
		.master_node = 127,
		.rpdo_timeout_ms = 3,
		.sdo_timeout_polls = 5,
		.idle = drives_turn,
	};

	for (unsigned k = 0; k < 3; k++)
		c.axis[k] = (struct irdm_can_axis_cfg){ k + 1, 500, 11.6 };
	return c;
}

/* The bus, the emulated drives (nodes 1..3), a rogue node; nothing sent yet. */
static void bus_up(void)
{
	memset(&m, 0, sizeof(m));
	rx_down = tx_down = rx_hiccup = hiccup_said = false;
	irdm_can_membus_init(&bus);
	assert_int_equal(irdm_can_membus_port(&bus, &master_port), IRDM_OK);
	assert_int_equal(irdm_can_membus_port(&bus, &drives_port), IRDM_OK);
	assert_int_equal(irdm_can_membus_port(&bus, &rogue), IRDM_OK);
	irdm_device_config_default(&dev);
	irdm_sim_params_default(&params);
	assert_int_equal(irdm_can_drives_init(&dr, &drives_port, &dev, &params, 3, 1, 1e-3), IRDM_OK);
	n_sent = 0;
	bus.tap = tap;
}

static void master_up(const struct irdm_can_master_cfg *c)
{
	int rc = irdm_can_master_init(&m, &wrapped, c, err, sizeof(err));

	if (rc)
		fail_msg("init: %d %s", rc, err);
}

/* One period: the master sends (set-points + SYNC), the drives answer,
 * the master receives.  Return: receive's verdict. */
static int period(const double *tau)
{
	irdm_can_master_send(&m, tau);
	irdm_can_drives_poll(&dr);
	return irdm_can_master_receive(&m);
}

/* Up and running: every axis operation enabled; the periods it took. */
static int run_up(const struct irdm_can_master_cfg *c)
{
	int p;

	bus_up();
	master_up(c);
	irdm_can_master_enable(&m, true);
	for (p = 1; p <= 10; p++) {
		period(NULL);
		if (irdm_can_master_all_enabled(&m))
			return p;
	}
	fail_msg("not enabled in 10 periods");
	return p;
}

static void expect_frame(unsigned i, uint32_t id, unsigned dlc, const uint8_t *bytes)
{
	assert_true(i < n_sent);
	if (sent[i].f.id != id || sent[i].f.dlc != dlc || memcmp(sent[i].f.data, bytes, dlc))
		fail_msg("frame %u: %03X [%u] %02X %02X %02X %02X %02X %02X %02X %02X, expected %03X [%u]",
			 i, (unsigned)sent[i].f.id, sent[i].f.dlc, sent[i].f.data[0],
			 sent[i].f.data[1], sent[i].f.data[2], sent[i].f.data[3], sent[i].f.data[4],
			 sent[i].f.data[5], sent[i].f.data[6], sent[i].f.data[7], (unsigned)id, dlc);
}

/*
 * One drive's set-up, as CiA 301 lays the expedited transfers out: an
 * upload request is 0x40, the index little endian, the sub-index, 4 zero
 * bytes; a download's command byte is 0x2F / 0x2B / 0x23 for 1 / 2 / 4
 * bytes (expedited, size given), then the index, the sub-index, the value
 * little endian.  A PDO's COB-ID carries the node: the rows marked add it
 * to data byte 4 (0x200 + n is 0x00 + n, 0x02; 0x180 + n is 0x80 + n,
 * 0x01; bit 31, not valid, is 0x80 in byte 7, bit 30, no RTR, 0x40).
 * The order is the standard's: 0x1019 only while 0x1006 is 0; a PDO's
 * mapping only while it is off.
 */
#define SETUP_SDOS 29
static const struct {
	uint8_t bytes[8];
	bool plus_node;
} setup_sdo[SETUP_SDOS] = {
	{ { 0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0 }, false },             /* read 0x1000 device type */
	{ { 0x40, 0x18, 0x10, 0x01, 0, 0, 0, 0 }, false },             /* read 0x1018:01 vendor */
	{ { 0x40, 0x18, 0x10, 0x02, 0, 0, 0, 0 }, false },             /* :02 product */
	{ { 0x40, 0x18, 0x10, 0x03, 0, 0, 0, 0 }, false },             /* :03 revision */
	{ { 0x40, 0x18, 0x10, 0x04, 0, 0, 0, 0 }, false },             /* :04 serial */
	{ { 0x2F, 0x60, 0x60, 0x00, 0x0A, 0, 0, 0 }, false },          /* 0x6060 = 10 (CST), 1 B */
	{ { 0x2B, 0x17, 0x10, 0x00, 0x0A, 0, 0, 0 }, false },          /* 0x1017 = 10 ms, 2 B */
	{ { 0x23, 0x76, 0x60, 0x00, 0xF4, 0x01, 0, 0 }, false },       /* 0x6076 = 500 mN m */
	{ { 0x23, 0x06, 0x10, 0x00, 0x00, 0x00, 0, 0 }, false },       /* 0x1006 = 0 first */
	{ { 0x2F, 0x19, 0x10, 0x00, 0x00, 0, 0, 0 }, false },          /* 0x1019 = 0: no counter */
	{ { 0x23, 0x06, 0x10, 0x00, 0xE8, 0x03, 0, 0 }, false },       /* 0x1006 = 1000 us */
	{ { 0x23, 0x16, 0x10, 0x01, 0x1E, 0x00, 0x7F, 0x00 }, false }, /* 0x1016:01 node 127, 30 ms */
	{ { 0x2B, 0x07, 0x60, 0x00, 0x02, 0x00, 0, 0 }, false },       /* 0x6007 = 2 disable voltage */
	/* RPDO1 */
	{ { 0x23, 0x00, 0x14, 0x01, 0x00, 0x02, 0x00, 0x80 }, true },  /* 0x1400:01 off */
	{ { 0x2F, 0x00, 0x16, 0x00, 0x00, 0, 0, 0 }, false },          /* 0x1600:00 = 0 */
	{ { 0x23, 0x00, 0x16, 0x01, 0x10, 0x00, 0x40, 0x60 }, false }, /* 0x6040, 16 bit */
	{ { 0x23, 0x00, 0x16, 0x02, 0x10, 0x00, 0x71, 0x60 }, false }, /* 0x6071, 16 bit */
	{ { 0x2F, 0x00, 0x16, 0x00, 0x02, 0, 0, 0 }, false },          /* two entries */
	{ { 0x2F, 0x00, 0x14, 0x02, 0x01, 0, 0, 0 }, false },          /* every SYNC */
	{ { 0x2B, 0x00, 0x14, 0x05, 0x03, 0x00, 0, 0 }, false },       /* deadline 3 ms */
	{ { 0x23, 0x00, 0x14, 0x01, 0x00, 0x02, 0x00, 0x00 }, true },  /* 0x1400:01 on */
	/* TPDO1 */
	{ { 0x23, 0x00, 0x18, 0x01, 0x80, 0x01, 0x00, 0xC0 }, true },  /* 0x1800:01 off, no RTR */
	{ { 0x2F, 0x00, 0x1A, 0x00, 0x00, 0, 0, 0 }, false },          /* 0x1A00:00 = 0 */
	{ { 0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60 }, false }, /* 0x6041, 16 bit */
	{ { 0x23, 0x00, 0x1A, 0x02, 0x20, 0x00, 0x64, 0x60 }, false }, /* 0x6064, 32 bit */
	{ { 0x2F, 0x00, 0x1A, 0x00, 0x02, 0, 0, 0 }, false },          /* two entries */
	{ { 0x2F, 0x00, 0x18, 0x02, 0x01, 0, 0, 0 }, false },          /* every SYNC */
	{ { 0x23, 0x00, 0x18, 0x01, 0x80, 0x01, 0x00, 0x40 }, true },  /* 0x1800:01 on, no RTR */
	{ { 0x40, 0x61, 0x60, 0x00, 0, 0, 0, 0 }, false },             /* read 0x6061 mode display */
};

static void test_setup_sequence(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	char line[200];

	(void)state;
	bus_up();
	master_up(&c);
	assert_int_equal(n_sent, 3 * SETUP_SDOS + 3);
	for (unsigned node = 1; node <= 3; node++)
		for (unsigned i = 0; i < SETUP_SDOS; i++) {
			uint8_t want[8];

			memcpy(want, setup_sdo[i].bytes, 8);
			if (setup_sdo[i].plus_node)
				want[4] = (uint8_t)(want[4] + node);
			expect_frame((node - 1) * SETUP_SDOS + i, 0x600 + node, 8, want);
		}
	for (unsigned node = 1; node <= 3; node++) {
		uint8_t nmt[2] = { 0x01, (uint8_t)node }; /* start remote node */

		expect_frame(3 * SETUP_SDOS + node - 1, 0x000, 2, nmt);
	}
	irdm_can_drives_poll(&dr);
	for (unsigned k = 0; k < 3; k++) {
		assert_int_equal(dr.d[k].mode, 10);
		assert_int_equal(dr.d[k].heartbeat_ms, 10);
		assert_int_equal(dr.d[k].rated_torque_mnm, 500);
		assert_int_equal(dr.d[k].nmt, IRDM_CO_STATE_OPERATIONAL);
		assert_int_equal(dr.d[k].rpdo1.cob_id, 0x200 + k + 1);
		assert_int_equal(dr.d[k].tpdo1.cob_id, 0x40000180 + k + 1);
		assert_int_equal(dr.d[k].rpdo1.n_mapped, 2);
		assert_int_equal(dr.d[k].tpdo1.n_mapped, 2);
		assert_int_equal(dr.d[k].rpdo1.transmission, 1);
		assert_int_equal(dr.d[k].tpdo1.transmission, 1);
		assert_int_equal(dr.d[k].rpdo1.event_timer_ms, 3);
		assert_int_equal(dr.d[k].sync_overflow, 0);
		assert_int_equal(dr.d[k].cycle_us, 1000);
		assert_int_equal(dr.d[k].hb_consumer, 127u << 16 | 30u);
		assert_int_equal(dr.d[k].abort_option, 2);
	}
	irdm_can_master_identity_line(&m, 1, line, sizeof(line));
	assert_string_equal(line, "drive 2 (node 2): CiA 402 device type 0x00020192, vendor "
				  "0x00000000, product 0x00000402, revision 0x00010000, serial 0x00000002");
}

/* With the SYNC counter: 0x1019 = 240 between 0x1006 = 0 and the period,
 * the drives' overflow set so, and their SYNCs taken (none refused). */
static void test_setup_sync_counter(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	static const uint8_t zero_cycle[8] = { 0x23, 0x06, 0x10, 0x00, 0, 0, 0, 0 };
	static const uint8_t overflow[8] = { 0x2F, 0x19, 0x10, 0x00, 0xF0, 0, 0, 0 };

	(void)state;
	c.sync_counter = true;
	bus_up();
	master_up(&c);
	expect_frame(8, 0x601, 8, zero_cycle);
	expect_frame(9, 0x601, 8, overflow);
	for (unsigned k = 0; k < 3; k++)
		assert_int_equal(dr.d[k].sync_overflow, 240);
	irdm_can_master_enable(&m, true);
	for (int p = 0; p < 100; p++)
		period(NULL);
	assert_true(irdm_can_master_all_enabled(&m));
	assert_int_equal(dr.sync_length_errors, 0);
}

/* The answer of a CiA 402 drive to an upload request f: 4 bytes, 0x1000
 * the drive profile, 0x6061 cyclic synchronous torque, anything else 0. */
static void upload_answer(const struct irdm_can_frame *f, struct irdm_can_frame *a)
{
	uint16_t index = (uint16_t)(f->data[1] | f->data[2] << 8);
	uint32_t v = index == 0x1000 ? 0x00020192 : index == 0x6061 ? 10 :
								      0;

	memset(a->data, 0, 8);
	a->data[0] = 0x43;
	memcpy(a->data + 1, f->data + 1, 3);
	for (int b = 0; b < 4; b++)
		a->data[4 + b] = (uint8_t)(v >> (8 * b));
}

/* A drive that answers every SDO download with these 8 bytes. */
static uint8_t canned[8];
static bool silent;

static void canned_turn(void *ctx)
{
	struct irdm_can_frame f, a = { .id = 0x581, .dlc = 8 };

	(void)ctx;
	while (irdm_can_recv(&rogue, &f) == 1) {
		if (f.id != 0x601 || silent)
			continue;
		if (f.data[0] == 0x40)
			upload_answer(&f, &a);
		else
			memcpy(a.data, canned, 8);
		irdm_can_send(&rogue, &a);
	}
}

static int init_against(const uint8_t answer[8])
{
	struct irdm_can_master_cfg c = cfg_3axes();

	c.n_axes = 1;
	c.idle = canned_turn;
	memcpy(canned, answer, 8);
	bus_up();
	return irdm_can_master_init(&m, &wrapped, &c, err, sizeof(err));
}

static void test_setup_aborts_named(void **state)
{
	static const struct {
		uint8_t answer[8];
		int rc;
		const char *line;
	} cases[] = {
		{ { 0x80, 0x60, 0x60, 0x00, 0x00, 0x00, 0x02, 0x06 }, IRDM_EHW, "drive 1 (node 1): SDO abort 0x06020000 object does not exist in the object "
										"dictionary writing 0x6060:00" },
		{ { 0x80, 0x60, 0x60, 0x00, 0x30, 0x00, 0x09, 0x06 }, IRDM_EHW, "drive 1 (node 1): SDO abort 0x06090030 invalid value for parameter writing "
										"0x6060:00" },
		{ { 0x80, 0x60, 0x60, 0x00, 0x02, 0x00, 0x01, 0x06 }, IRDM_EHW, "drive 1 (node 1): SDO abort 0x06010002 attempt to write a read-only object "
										"writing 0x6060:00" },
		{ { 0x80, 0x60, 0x60, 0x00, 0x00, 0x00, 0x04, 0x05 }, IRDM_EHW, "drive 1 (node 1): SDO abort 0x05040000 SDO protocol timed out writing 0x6060:00" },
		/* a confirmation about another object; an upload's answer; garbage */
		{ { 0x60, 0x61, 0x60, 0x00, 0, 0, 0, 0 }, IRDM_EFORMAT, NULL },
		{ { 0x4F, 0x60, 0x60, 0x00, 0x0A, 0, 0, 0 }, IRDM_EFORMAT, NULL },
		{ { 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF }, IRDM_EFORMAT, NULL },
	};
	static const uint8_t ok[8] = { 0x60, 0x60, 0x60, 0x00, 0, 0, 0, 0 };

	(void)state;
	for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		silent = false;
		assert_int_equal(init_against(cases[i].answer), cases[i].rc);
		if (cases[i].line)
			assert_string_equal(err, cases[i].line);
		else
			assert_non_null(strstr(err, "drive 1 (node 1): malformed SDO answer"));
	}
	silent = true;
	assert_int_equal(init_against(ok), IRDM_ETIMEDOUT);
	assert_string_equal(err, "drive 1 (node 1): no SDO answer (time-out) reading 0x1000:00");
	/* the emulator answering about another object: refused */
	bus_up();
	dr.d[1].sdo_wrong = true;
	{
		struct irdm_can_master_cfg c = cfg_3axes();

		assert_int_equal(irdm_can_master_init(&m, &wrapped, &c, err, sizeof(err)),
				 IRDM_EFORMAT);
		assert_non_null(strstr(err, "drive 2 (node 2): malformed SDO answer"));
	}
}

/* A drive that confirms every SDO but refuses writes to picky_index with
 * picky_abort (a drive whose PDO stays valid, say). */
static uint16_t picky_index;
static uint32_t picky_abort;

static void picky_turn(void *ctx)
{
	struct irdm_can_frame f, a = { .id = 0x581, .dlc = 8 };

	(void)ctx;
	while (irdm_can_recv(&rogue, &f) == 1) {
		if (f.id != 0x601)
			continue;
		if (f.data[0] == 0x40) {
			upload_answer(&f, &a);
			irdm_can_send(&rogue, &a);
			continue;
		}
		memset(a.data, 0, 8);
		a.data[0] = 0x60; /* download confirmed */
		memcpy(a.data + 1, f.data + 1, 3);
		if ((f.data[1] | f.data[2] << 8) == picky_index) {
			a.data[0] = 0x80; /* abort, the code little endian */
			for (int b = 0; b < 4; b++)
				a.data[4 + b] = (uint8_t)(picky_abort >> (8 * b));
		}
		irdm_can_send(&rogue, &a);
	}
}

/* A drive refusing the master's mapping: the one-line error names the
 * drive, the abort and the object, and nothing after it is sent. */
static void test_setup_pdo_refused_named(void **state)
{
	static const uint32_t other_map[2] = { 0x60400010, 0x60710020 };
	static const struct {
		uint16_t index;
		uint32_t abort_code;
		const char *line;
	} cases[] = {
		{ 0x1600, 0x06010000, "drive 1 (node 1): SDO abort 0x06010000 unsupported access to "
				      "an object writing 0x1600:00" },
		{ 0x1A00, 0x08000022, "drive 1 (node 1): SDO abort 0x08000022 data cannot be stored: "
				      "present device state writing 0x1A00:00" },
		{ 0x1800, 0x06090030, "drive 1 (node 1): SDO abort 0x06090030 invalid value for "
				      "parameter writing 0x1800:01" },
	};
	struct irdm_can_master_cfg c = cfg_3axes();

	(void)state;
	bus_up();
	dr.d[1].rpdo1.map = other_map; /* drive 2 maps 0x6071 as 32 bit */
	assert_int_equal(irdm_can_master_init(&m, &wrapped, &c, err, sizeof(err)), IRDM_EHW);
	assert_string_equal(err, "drive 2 (node 2): SDO abort 0x06040041 object cannot be mapped "
				 "to the PDO writing 0x1600:02");
	assert_int_equal(n_sent, SETUP_SDOS + 17); /* drive 1, then drive 2 up to 0x1600:02 */
	c.n_axes = 1;
	c.idle = picky_turn;
	for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		picky_index = cases[i].index;
		picky_abort = cases[i].abort_code;
		bus_up();
		assert_int_equal(irdm_can_master_init(&m, &wrapped, &c, err, sizeof(err)), IRDM_EHW);
		assert_string_equal(err, cases[i].line);
	}
}

static void test_every_axis_enabled(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	int p = run_up(&c);

	(void)state;
	print_message("every axis operation enabled after %d periods\n", p);
	assert_true(p <= 5);
	for (unsigned k = 0; k < 3; k++) {
		assert_int_equal(dr.d[k].fsa.state, IRDM_CIA402_OPERATION_ENABLED);
		assert_int_equal(m.ax[k].state, IRDM_CIA402_OPERATION_ENABLED);
	}
	/* the controlwords sent to node 1, in order: shutdown, switch on, enable */
	{
		uint16_t want[3] = { 0x06, 0x07, 0x0F };
		unsigned j = 0;

		for (unsigned i = 0; i < n_sent && j < 3; i++)
			if (sent[i].f.id == 0x201) {
				uint16_t cw = (uint16_t)(sent[i].f.data[0] | sent[i].f.data[1] << 8);

				if (j == 0 && cw == 0)
					continue; /* the first period: state still unknown */
				assert_int_equal(cw, want[j++]);
			}
		assert_int_equal(j, 3);
	}
}

/* The torque set-point's bytes: 0.5 N m at the joint, gear 11.6, 500 mN m
 * rated: 0.5 / 11.6 = 43.10 mN m = 86.2 per mille -> 86 = 0x0056. */
static void test_torque_scaling(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	double tau[3] = { 0.5, -0.5, 0 };
	uint8_t n1[4] = { 0x0F, 0x00, 0x56, 0x00 }, n2[4] = { 0x0F, 0x00, 0xAA, 0xFF };

	(void)state;
	run_up(&c);
	n_sent = 0;
	period(tau);
	expect_frame(0, 0x201, 4, n1);
	expect_frame(1, 0x202, 4, n2);
	assert_int_equal(dr.d[0].rpdo_torque_permille, 86);
	assert_int_equal(dr.d[1].rpdo_torque_permille, -86);
	/* rounded, clamped to int16, not finite -> 0 */
	assert_int_equal(irdm_can_torque_permille(&c.axis[0], 0.5 * 86.5 / 86.2), 87);
	assert_int_equal(irdm_can_torque_permille(&c.axis[0], 1e9), 32767);
	assert_int_equal(irdm_can_torque_permille(&c.axis[0], -1e9), -32767);
	assert_int_equal(irdm_can_torque_permille(&c.axis[0], 0.0 / 0.0), 0);
}

/* Every axis got disable voltage + zero torque within two periods of
 * period p0 (the master's period when the fault happened). */
static void expect_off_within_two(uint64_t p0)
{
	bool off[3] = { false, false, false };

	for (unsigned i = 0; i < n_sent; i++) {
		const struct irdm_can_frame *f = &sent[i].f;

		if (sent[i].period < p0 || sent[i].period > p0 + 2)
			continue;
		if (f->id >= 0x201 && f->id <= 0x203 && f->dlc == 4 && f->data[0] == 0 &&
		    f->data[1] == 0 && f->data[2] == 0 && f->data[3] == 0)
			off[f->id - 0x201] = true;
	}
	for (int k = 0; k < 3; k++)
		if (!off[k])
			fail_msg("node %d not commanded off within two periods of %llu", k + 1,
				 (unsigned long long)p0);
	for (unsigned k = 0; k < 3; k++)
		assert_int_equal(dr.d[k].fsa.state == IRDM_CIA402_OPERATION_ENABLED, 0);
}

/* Run periods with torque until the master faults; the period it did. */
static uint64_t run_until_fault(unsigned max)
{
	double tau[3] = { 0.1, 0.1, 0.1 };

	for (unsigned p = 0; p < max; p++) {
		int rc = period(tau);

		if (rc == IRDM_EHW)
			return m.period;
		assert_true(rc == IRDM_OK || rc == IRDM_ETIMEDOUT);
	}
	fail_msg("no fault in %u periods", max);
	return 0;
}

static void test_fault_emcy(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	uint64_t p0;

	(void)state;
	run_up(&c);
	period(NULL);
	p0 = m.period;
	irdm_can_drives_fault(&dr, 1, 0x2310);
	assert_int_equal(run_until_fault(5), p0 + 1); /* found in the same period */
	period(NULL);
	expect_off_within_two(p0);
	assert_string_equal(m.why, "drive 2 (node 2): EMCY 0x2310 (current), error register 0x01");
	assert_int_equal(m.emcy_frames, 1);
}

static void test_fault_drive_state(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	uint64_t p0;

	(void)state;
	run_up(&c);
	p0 = m.period;
	irdm_cia402_drive_fault(&dr.d[2].fsa); /* no EMCY: the statusword says it */
	run_until_fault(5);
	period(NULL);
	expect_off_within_two(p0);
	assert_non_null(strstr(m.why, "drive 3 (node 3): drive fault (statusword 0x"));
	/* never reset by itself: the drive stays in fault, the controlword at 0 */
	for (int p = 0; p < 50; p++)
		assert_int_equal(period(NULL), IRDM_EHW);
	assert_int_equal(dr.d[2].fsa.state, IRDM_CIA402_FAULT);
	assert_int_equal(sent[n_sent - 2].f.data[0], 0x00);
	/* on request: 0x00 then 0x80 (bit 7 rises), then switch on disabled */
	irdm_can_master_reset_faults(&m);
	for (int p = 0; p < 3; p++)
		period(NULL);
	assert_int_equal(dr.d[2].fsa.state, IRDM_CIA402_SWITCH_ON_DISABLED);
}

/* A pre-operational beat that crossed the NMT start on the bus is not news;
 * the same beat once the drive has sent PDOs is (found in make hil's VM:
 * a drive beats on its own clock, so one lands in the master's queue
 * just before the start). */
static void test_preop_beat_crossing_start(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	struct irdm_can_frame hb = { .id = IRDM_CO_HEARTBEAT + 1, .dlc = 1, .data = { IRDM_CO_STATE_PRE_OPERATIONAL } };

	(void)state;
	bus_up();
	master_up(&c);
	irdm_can_master_enable(&m, true);
	dr.d[0].no_heartbeat = true; /* its own (operational) beats would mask the stale one */
	assert_int_equal(irdm_can_send(&rogue, &hb), IRDM_OK);
	for (int p = 1; p <= 10 && !irdm_can_master_all_enabled(&m); p++)
		assert_int_equal(period(NULL), IRDM_OK);
	assert_true(irdm_can_master_all_enabled(&m));
	assert_int_equal(irdm_can_send(&rogue, &hb), IRDM_OK);
	assert_int_equal(period(NULL), IRDM_EHW);
	assert_string_equal(m.why, "drive 1 (node 1): heartbeat says NMT pre-operational");
}

static void test_fault_heartbeat(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	uint64_t p0, p1;

	(void)state;
	run_up(&c);
	for (int p = 0; p < 40; p++) /* heartbeats come: no fault */
		assert_int_equal(period(NULL), IRDM_OK);
	p0 = m.ax[0].heartbeat_period;
	dr.d[0].no_heartbeat = true;
	p1 = run_until_fault(100);
	print_message("heartbeat last seen at period %llu, lost at %llu\n",
		      (unsigned long long)p0, (unsigned long long)p1);
	/* 30 ms time-out at 1 ms periods: lost at the 31st ms of silence */
	assert_int_equal(p1 - p0, 31);
	period(NULL);
	expect_off_within_two(p1);
	assert_string_equal(m.why, "drive 1 (node 1): no heartbeat for 31 ms (time-out 30 ms)");
}

static void test_fault_tpdos_dropped(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	uint64_t p0;

	(void)state;
	run_up(&c);
	dr.d[1].drop_tpdos = 100;
	p0 = m.period;
	assert_int_equal(period(NULL), IRDM_ETIMEDOUT); /* missing 1 */
	assert_int_equal(period(NULL), IRDM_ETIMEDOUT); /* missing 2 */
	assert_int_equal(period(NULL), IRDM_EHW);       /* missing 3: lost */
	period(NULL);
	expect_off_within_two(p0 + 2);
	assert_string_equal(m.why, "drive 2 (node 2): no TPDO1 for 3 periods");
	/* one late TPDO does not bring it back */
	dr.d[1].drop_tpdos = 0;
	assert_int_equal(period(NULL), IRDM_EHW);
}

static void test_fault_link_down(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	uint64_t p0;

	(void)state;
	run_up(&c);
	p0 = m.period;
	rx_down = true; /* bus-off seen by the receive side */
	assert_int_equal(irdm_can_master_receive(&m), IRDM_EHW);
	irdm_can_drives_poll(&dr);
	expect_off_within_two(p0);
	assert_string_equal(m.why, "CAN link: link down (bus-off or interface gone) on receive");
	assert_true(m.link_lost);
	/* a send that fails: safe_off cannot confirm the torque is off */
	tx_down = true;
	assert_int_equal(irdm_can_master_safe_off(&m), IRDM_EHW);
	/* lost on send first */
	run_up(&c);
	tx_down = true;
	assert_int_equal(irdm_can_master_send(&m, NULL), IRDM_EHW);
	assert_string_equal(m.why, "CAN link: link down (bus-off or interface gone) on send");
}

static void rogue_send(uint32_t id, unsigned dlc, const uint8_t *bytes)
{
	struct irdm_can_frame f = { .id = id, .dlc = (uint8_t)dlc };

	memcpy(f.data, bytes, dlc);
	assert_int_equal(irdm_can_send(&rogue, &f), IRDM_OK);
}

static void test_malformed_counted(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	static const uint8_t junk[8] = { 0x27, 0x00, 0x39, 0x30, 0x00, 0x00, 0x11, 0x22 };
	int32_t before;

	(void)state;
	run_up(&c);
	period(NULL);
	before = m.ax[0].counts;
	/* the drives' TPDOs of this period are read, then the junk */
	irdm_can_master_send(&m, NULL);
	irdm_can_drives_poll(&dr);
	rogue_send(0x181, 5, junk);                      /* TPDO1 of node 1, DLC 5: malformed */
	rogue_send(0x181, 8, junk);                      /* DLC 8 */
	rogue_send(0x701, 2, junk);                      /* heartbeat of 2 bytes */
	rogue_send(0x702, 1, (const uint8_t[]){ 0x33 }); /* no such NMT state */
	rogue_send(0x081, 3, junk);                      /* EMCY of 3 bytes */
	rogue_send(0x123, 8, junk);                      /* nobody's COB-ID */
	rogue_send(0x089, 8, junk);                      /* EMCY from node 9: not ours */
	rogue_send(0x189, 6, junk);                      /* TPDO1 of node 9 */
	rogue_send(0x582, 8, junk);                      /* an SDO answer after set-up */
	assert_int_equal(irdm_can_master_receive(&m), IRDM_OK);
	assert_int_equal(m.bad_frames, 5);
	assert_int_equal(m.unknown_frames, 3);
	assert_int_equal(m.sdo_stragglers, 1);
	assert_false(m.faulted);
	assert_int_equal(m.ax[0].counts, before);
	assert_int_equal(m.ax[0].sw & 0x6F, 0x27);
}

static void test_latest_wins(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	/* statusword 0x0027 (operation enabled), position 1000 then 1234 */
	static const uint8_t a[6] = { 0x27, 0x00, 0xE8, 0x03, 0x00, 0x00 };
	static const uint8_t b[6] = { 0x27, 0x00, 0xD2, 0x04, 0x00, 0x00 };
	static const uint8_t neg[6] = { 0x27, 0x00, 0xFE, 0xFF, 0xFF, 0xFF };

	(void)state;
	run_up(&c);
	irdm_can_master_send(&m, NULL);
	irdm_can_drives_poll(&dr);
	rogue_send(0x181, 6, a);
	rogue_send(0x181, 6, b);
	assert_int_equal(irdm_can_master_receive(&m), IRDM_OK);
	assert_int_equal(m.ax[0].counts, 1234);
	rogue_send(0x181, 6, neg);
	irdm_can_master_receive(&m);
	assert_int_equal(m.ax[0].counts, -2);
}

/* A port that says "nothing" between frames still hands over all of them;
 * a flood is taken at most IRDM_CAN_RX_MAX frames a period. */
static void test_drain_hiccups_and_flood(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	static const uint8_t junk[8] = { 0 };

	(void)state;
	run_up(&c);
	rx_hiccup = true;
	for (int p = 0; p < 20; p++)
		assert_int_equal(period(NULL), IRDM_OK);
	rx_hiccup = false;
	irdm_can_master_send(&m, NULL);
	irdm_can_drives_poll(&dr);
	for (int k = 0; k < 600; k++)
		rogue_send(0x123, 8, junk);
	assert_int_equal(irdm_can_master_receive(&m), IRDM_OK); /* the TPDOs came first */
	assert_int_equal(m.unknown_frames, IRDM_CAN_RX_MAX - 3);
	irdm_can_master_receive(&m);
	assert_int_equal(m.unknown_frames, 2 * IRDM_CAN_RX_MAX - 3);
}

static void test_bus_load(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	char line[200];

	(void)state;
	/*
	 * By hand, 11-bit frames of n bytes: 47 + 8n bits plus at most
	 * floor((34 + 8n - 1) / 4) stuff bits.  SYNC (0 B): 47 + 8 = 55;
	 * RPDO1 (4 B): 79 + 16 = 95; TPDO1 (6 B): 95 + 20 = 115.
	 * SYNC + 3 x 95 + 3 x 115 = 55 + 285 + 345 = 685 bits: 68.5 % of the
	 * 1000 bits of 1 ms at 1 Mbit/s.  With a counter the SYNC is 1 B:
	 * 55 + 10 = 65, 695 bits.
	 */
	assert_int_equal(irdm_can_master_cycle_bits(&c), 685);
	irdm_can_master_load_line(&c, line, sizeof(line));
	assert_string_equal(line, "CAN bus load: SYNC + 3 x RPDO1 (4 B) + 3 x TPDO1 (6 B) = 685 "
				  "bits worst case in 1000 us at 1000000 bit/s: 68.5 %");
	c.sync_counter = true;
	assert_int_equal(irdm_can_master_cycle_bits(&c), 695);
	assert_int_equal(irdm_can_master_check(&c, err, sizeof(err)), IRDM_OK);
	/* 500 kbit/s carries 500 bits a millisecond: refused */
	c.bitrate = 500000;
	assert_int_equal(irdm_can_master_check(&c, err, sizeof(err)), IRDM_EINVAL);
	assert_string_equal(err, "bitrate: one cycle needs 695 bits worst case, 1000 us at "
				 "500000 bit/s carries 500");
	/* ... but 2 ms carries 1000 */
	c.period_us = 2000;
	assert_int_equal(irdm_can_master_check(&c, err, sizeof(err)), IRDM_OK);
	/* and init refuses before sending anything */
	c.period_us = 1000;
	bus_up();
	assert_int_equal(irdm_can_master_init(&m, &wrapped, &c, err, sizeof(err)), IRDM_EINVAL);
	assert_int_equal(n_sent, 0);
}

static void test_config_refused(void **state)
{
	struct irdm_can_master_cfg c;

	(void)state;
	c = cfg_3axes(), c.axis[1].node = 1;
	assert_int_equal(irdm_can_master_check(&c, err, sizeof(err)), IRDM_EINVAL);
	assert_string_equal(err, "nodes: a node id appears twice");
	c = cfg_3axes(), c.axis[2].node = 128;
	assert_int_equal(irdm_can_master_check(&c, err, sizeof(err)), IRDM_EINVAL);
	c = cfg_3axes(), c.heartbeat_timeout_ms = 10;
	assert_int_equal(irdm_can_master_check(&c, err, sizeof(err)), IRDM_EINVAL);
	assert_string_equal(err, "heartbeat_timeout_ms: must exceed heartbeat_ms");
	c = cfg_3axes(), c.axis[0].rated_torque_mnm = 0;
	assert_int_equal(irdm_can_master_check(&c, err, sizeof(err)), IRDM_EINVAL);
	c = cfg_3axes(), c.n_axes = 4;
	assert_int_equal(irdm_can_master_check(&c, err, sizeof(err)), IRDM_EINVAL);
}

/*
 * One RPDO per axis between two SYNCs, and the counter 1, 2, ..., 240, 1,
 * which the strict drives take (0x1019 written); the master's heartbeat
 * (0x77F, operational) every 10 periods, heard by every drive's consumer,
 * and no drive's deadline ever missed.
 */
static void test_one_rpdo_per_sync_and_counter(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	unsigned rpdos[3] = { 0, 0, 0 }, syncs = 0, last = 0, beats = 0;
	double tau[3] = { 0.01, 0.02, 0.03 };

	(void)state;
	c.sync_counter = true;
	run_up(&c);
	n_sent = 0;
	for (int p = 0; p < 500; p++)
		assert_int_equal(period(tau), IRDM_OK);
	for (unsigned i = 0; i < n_sent; i++) {
		const struct irdm_can_frame *f = &sent[i].f;

		if (f->id == 0x080) {
			assert_int_equal(f->dlc, 1);
			for (int k = 0; k < 3; k++)
				assert_int_equal(rpdos[k], 1);
			memset(rpdos, 0, sizeof(rpdos));
			if (syncs > 0)
				assert_int_equal(f->data[0], last == 240 ? 1 : last + 1);
			else /* run_up's periods came first */
				assert_int_equal(f->data[0], m.period - 500 + 1);
			last = f->data[0];
			syncs++;
		} else if (f->id >= 0x201 && f->id <= 0x203) {
			rpdos[f->id - 0x201]++;
		} else if (f->id == 0x77F && f->dlc == 1 && f->data[0] == 0x05) {
			assert_int_equal(sent[i].period % 10, 0);
			beats++;
		} else {
			fail_msg("frame %03X in a running cycle", (unsigned)f->id);
		}
	}
	assert_int_equal(syncs, 500);
	assert_int_equal(beats, 50);
	assert_int_equal(dr.syncs, m.period); /* every SYNC reached the drives */
	assert_int_equal(dr.sync_counter, last);
	assert_int_equal(dr.sync_length_errors, 0);
	for (unsigned k = 0; k < 3; k++) {
		assert_true(dr.d[k].master_beat_seen);
		assert_true(dr.d[k].rpdo_seen);
		assert_int_equal(dr.d[k].lost_code, 0);
	}
	assert_false(m.faulted);
}

/*
 * The master dies mid-run (a kill -9: not one more frame), the drives on
 * the wall clock as a drive process runs: each stops by itself, at the
 * first of its deadlines the master configured.  rpdo_ms: the RPDO1
 * deadline (0x1400:05); the consumer heartbeat is the master's tolerance,
 * 30 ms.  Return: the time from the master's last frame to the last
 * drive's torque-off, in us; each drive's EMCY code in codes.
 */
static uint64_t master_dies(uint16_t rpdo_ms, uint16_t codes[3])
{
	struct irdm_can_master_cfg c = cfg_3axes();
	double tau[3] = { 0.05, -0.05, 0.05 };
	uint64_t t = 1000000, last, worst = 0;

	c.rpdo_timeout_ms = rpdo_ms;
	bus_up();
	dr.wall_heartbeat = true;
	irdm_can_drives_wall(&dr, t);
	master_up(&c);
	irdm_can_master_enable(&m, true);
	for (int p = 0; p < 105; p++) {
		t += 1000;
		irdm_can_drives_wall(&dr, t);
		assert_int_equal(irdm_can_master_send(&m, tau), IRDM_OK);
		irdm_can_drives_poll(&dr);
		(void)irdm_can_master_receive(&m);
	}
	assert_true(irdm_can_master_all_enabled(&m));
	for (unsigned k = 0; k < 3; k++)
		assert_int_not_equal(dr.d[k].rpdo_torque_permille, 0);
	last = t;
	while (t < last + 200000) {
		t += 100;
		irdm_can_drives_wall(&dr, t);
	}
	for (unsigned k = 0; k < 3; k++) {
		assert_int_not_equal(dr.d[k].lost_code, 0);
		assert_int_equal(dr.d[k].rpdo_torque_permille, 0);
		assert_int_equal(dr.d[k].fsa.state, IRDM_CIA402_SWITCH_ON_DISABLED);
		codes[k] = dr.d[k].lost_code;
		if (dr.d[k].lost_at_us - last > worst)
			worst = dr.d[k].lost_at_us - last;
	}
	return worst;
}

static void test_master_dies_drives_stop(void **state)
{
	uint16_t codes[3];
	uint64_t us;

	(void)state;
	/* the RPDO1 deadline first: 3 ms after the last RPDO1 (3 periods) */
	us = master_dies(3, codes);
	print_message("master silent: every drive off %.1f ms after its last frame (RPDO1 "
		      "deadline 3 ms)\n",
		      us / 1000.0);
	for (unsigned k = 0; k < 3; k++)
		assert_int_equal(codes[k], 0x8250);
	assert_true(us > 3000 && us <= 3100);
	/* a drive without an RPDO deadline (the longest 0x1400:05 allows):
	 * the master's heartbeat, 30 ms after the last beat (at most one
	 * heartbeat period, 10 ms, before the last frame) */
	us = master_dies(65535, codes);
	print_message("master silent: every drive off %.1f ms after its last frame (consumer "
		      "heartbeat 30 ms)\n",
		      us / 1000.0);
	for (unsigned k = 0; k < 3; k++)
		assert_int_equal(codes[k], 0x8130);
	assert_true(us > 20000 && us <= 30100);
}

/*
 * The emergency path (a signal handler's): a port like SocketCAN's, one
 * write(2) per frame (here into a pipe), and the master mid-run.  In
 * seccomp strict mode (any system call but read, write, _exit and
 * sigreturn kills the child) it sends, per CiA 402, each axis's RPDO1
 * with controlword 0x0000 (disable voltage: bit 1 clear) and target torque
 * (0x6071) 0, then a SYNC whose counter follows the last one sent (CiA
 * 301: 1..240), and receives nothing and changes nothing in the master.
 */
#define EMERGENCY_MAGIC 0x454d4f46u
struct emergency_result {
	unsigned magic;
	int rc;
	unsigned recvs;    /* recv calls: must stay 0 */
	int state_changed; /* the master differs from before */
};

static int frames_fd = -1;
static unsigned emergency_recvs;

static int pipe_send(void *ctx, const struct irdm_can_frame *f)
{
	(void)ctx;
	return write(frames_fd, f, sizeof(*f)) == (ssize_t)sizeof(*f) ? IRDM_OK : IRDM_EIO;
}

static int pipe_recv(void *ctx, struct irdm_can_frame *f)
{
	(void)ctx;
	(void)f;
	emergency_recvs++;
	return 0;
}

static const struct irdm_can_port_ops pipe_ops = { pipe_send, pipe_recv };

static void emergency_child(void *arg, int fd)
{
	struct emergency_result res = { .magic = EMERGENCY_MAGIC };
	const struct irdm_can_master *before = arg;
	static struct irdm_can_master mine;

	mine = m;
	mine.port = (struct irdm_can_port){ &pipe_ops, NULL };
	if (strict_enter())
		strict_exit(fd, &res, sizeof(res), STRICT_UNAVAILABLE);
	res.rc = irdm_can_master_emergency_off(&mine);
	res.recvs = emergency_recvs;
	mine.port = before->port;
	res.state_changed = memcmp(&mine, before, sizeof(mine)) != 0;
	strict_exit(fd, &res, sizeof(res), 0);
}

static void test_emergency_off_frames(void **state)
{
	struct irdm_can_master_cfg c = cfg_3axes();
	double tau[3] = { 0.3, -0.2, 0.1 };
	static struct irdm_can_master before;
	struct irdm_can_frame f[8];
	struct emergency_result res;
	uint8_t off[4] = { 0, 0, 0, 0 };
	int fds[2], status;
	size_t got;
	ssize_t n;

	(void)state;
	c.sync_counter = true;
	run_up(&c);
	for (int p = 0; p < 245; p++) /* past the counter's wrap: 240 -> 1 */
		assert_int_equal(period(tau), IRDM_OK);
	assert_int_equal(dr.d[0].rpdo_torque_permille, irdm_can_torque_permille(&c.axis[0], 0.3));
	assert_int_not_equal(dr.d[0].rpdo_torque_permille, 0);
	before = m;
	assert_int_equal(pipe(fds), 0);
	frames_fd = fds[1];
	status = strict_run(emergency_child, &before, &res, sizeof(res), &got);
	close(fds[1]);
	if (WIFEXITED(status) && WEXITSTATUS(status) == STRICT_UNAVAILABLE) {
		close(fds[0]);
		skip();
	}
	if (WIFSIGNALED(status))
		fail_msg("the emergency path died of signal %d (SIGKILL: a system call other "
			 "than write)",
			 WTERMSIG(status));
	assert_int_equal(WEXITSTATUS(status), 0);
	assert_int_equal(got, sizeof(res));
	assert_int_equal(res.magic, EMERGENCY_MAGIC);
	assert_int_equal(res.rc, IRDM_OK);
	assert_int_equal(res.recvs, 0);
	assert_int_equal(res.state_changed, 0);
	n = read(fds[0], f, sizeof(f));
	close(fds[0]);
	assert_int_equal(n, 4 * (ssize_t)sizeof(f[0])); /* 3 RPDO1 + SYNC, nothing more */
	n_sent = 0;
	for (unsigned k = 0; k < 4; k++)
		sent[n_sent++] = (struct logged){ f[k], m.period };
	for (unsigned k = 0; k < 3; k++)
		expect_frame(k, 0x201 + k, 4, off);
	expect_frame(3, 0x080, 1, (const uint8_t[]){ (uint8_t)(m.sync_count % 240 + 1) });
	/* the emulated CiA 402 drives take them: no torque, not enabled */
	for (unsigned k = 0; k < 4; k++)
		assert_int_equal(irdm_can_send(&master_port, &f[k]), IRDM_OK);
	irdm_can_drives_poll(&dr);
	for (unsigned k = 0; k < 3; k++) {
		assert_int_equal(dr.d[k].rpdo_torque_permille, 0);
		assert_int_not_equal(dr.d[k].fsa.state, IRDM_CIA402_OPERATION_ENABLED);
	}
	assert_int_equal(dr.sync_length_errors, 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_setup_sequence),
		cmocka_unit_test(test_emergency_off_frames),
		cmocka_unit_test(test_setup_sync_counter),
		cmocka_unit_test(test_setup_pdo_refused_named),
		cmocka_unit_test(test_setup_aborts_named),
		cmocka_unit_test(test_every_axis_enabled),
		cmocka_unit_test(test_torque_scaling),
		cmocka_unit_test(test_fault_emcy),
		cmocka_unit_test(test_fault_drive_state),
		cmocka_unit_test(test_preop_beat_crossing_start),
		cmocka_unit_test(test_fault_heartbeat),
		cmocka_unit_test(test_fault_tpdos_dropped),
		cmocka_unit_test(test_fault_link_down),
		cmocka_unit_test(test_malformed_counted),
		cmocka_unit_test(test_latest_wins),
		cmocka_unit_test(test_drain_hiccups_and_flood),
		cmocka_unit_test(test_bus_load),
		cmocka_unit_test(test_config_refused),
		cmocka_unit_test(test_one_rpdo_per_sync_and_counter),
		cmocka_unit_test(test_master_dies_drives_stop),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
