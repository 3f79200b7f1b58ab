/* SPDX-License-Identifier: MIT */
/*
 * Injected CAN faults (irdm/can_faults.h): every kind parsed, every bad
 * word refused with its reason; and the schedule on the drive emulator
 * over an in-memory bus, counted frame by frame per SYNC: TPDOs dropped for
 * exactly K SYNCs from SYNC n, delayed ones sent on the wall clock, the
 * heartbeat on the wall clock and stopped at SYNC n, an EMCY and a fault
 * at SYNC n, wrong SDO answers from the start, a bounded flood.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "irdm/sim/can_drives.h"
#include "irdm/sim/can_faults.h"
#include "irdm/sim/can_membus.h"

#include "support/can_drain.h"

static struct irdm_can_membus bus;
static struct irdm_can_drives dr;
static struct irdm_can_port master, drives_port;

static void test_parse_each_kind(void **state)
{
	struct irdm_can_fault f;
	char err[160];

	(void)state;
	assert_int_equal(irdm_can_fault_parse("drop:2:500:20", &f, err, sizeof(err)), IRDM_OK);
	assert_int_equal(f.kind, IRDM_CAN_FAULT_DROP);
	assert_int_equal(f.node, 2);
	assert_int_equal(f.at_sync, 500);
	assert_int_equal(f.count, 20);
	assert_int_equal(irdm_can_fault_parse("delay:1:7:3:2500", &f, err, sizeof(err)), IRDM_OK);
	assert_int_equal(f.kind, IRDM_CAN_FAULT_DELAY);
	assert_int_equal(f.count, 3);
	assert_int_equal(f.delay_us, 2500);
	assert_int_equal(irdm_can_fault_parse("heartbeat-stop:3:9", &f, err, sizeof(err)), IRDM_OK);
	assert_int_equal(f.kind, IRDM_CAN_FAULT_HEARTBEAT_STOP);
	assert_int_equal(f.at_sync, 9);
	assert_int_equal(irdm_can_fault_parse("emcy:1:100:0x2310", &f, err, sizeof(err)), IRDM_OK);
	assert_int_equal(f.kind, IRDM_CAN_FAULT_EMCY);
	assert_int_equal(f.code, 0x2310);
	assert_int_equal(irdm_can_fault_parse("fault:3:12", &f, err, sizeof(err)), IRDM_OK);
	assert_int_equal(f.kind, IRDM_CAN_FAULT_STATE);
	assert_int_equal(f.node, 3);
	assert_int_equal(f.at_sync, 12);
	assert_int_equal(irdm_can_fault_parse("sdo-wrong:2", &f, err, sizeof(err)), IRDM_OK);
	assert_int_equal(f.kind, IRDM_CAN_FAULT_SDO_WRONG);
	assert_int_equal(f.at_sync, 0);
	assert_int_equal(irdm_can_fault_parse("flood:40:1000", &f, err, sizeof(err)), IRDM_OK);
	assert_int_equal(f.kind, IRDM_CAN_FAULT_FLOOD);
	assert_int_equal(f.at_sync, 40);
	assert_int_equal(f.count, 1000);
}

static void refused(const char *word, const char *why)
{
	struct irdm_can_fault f;
	char err[200] = "";

	assert_int_equal(irdm_can_fault_parse(word, &f, err, sizeof(err)), IRDM_EFORMAT);
	if (!strstr(err, why))
		fail_msg("'%s': message '%s' lacks '%s'", word, err, why);
	assert_null(strchr(err, '\n'));
}

static void test_parse_refuses(void **state)
{
	(void)state;
	refused("stall:1:2", "unknown kind");
	refused("dropx:1:2:3", "unknown kind");
	refused("drop:1:2", "too few fields");
	refused("drop:1:2:3:4", "too many fields");
	refused("drop:0:2:3", "out of range");
	refused("drop:128:2:3", "out of range");
	refused("drop:1:0:3", "SYNC counts from 1");
	refused("drop:1:2:0", "K must be >= 1");
	refused("drop:1:2:100001", "out of range");
	refused("drop:1:-2:3", "out of range");
	refused("drop:1:2x:3", "malformed");
	refused("drop:1::3", "malformed");
	refused("delay:1:2:3:1000001", "out of range");
	refused("emcy:1:2:0x10000", "out of range");
	refused("flood:5:10001", "out of range");
	refused("flood:5:0", "COUNT must be >= 1");
	refused("sdo-wrong", "too few fields");
	refused("fault:1", "too few fields");
	refused("heartbeat-stop:1:0", "SYNC counts from 1");
}

static void bring_up(void)
{
	struct irdm_device_config dev;
	struct irdm_sim_params params;
	struct irdm_can_frame f;

	irdm_can_membus_init(&bus);
	assert_int_equal(irdm_can_membus_port(&bus, &master), IRDM_OK);
	assert_int_equal(irdm_can_membus_port(&bus, &drives_port), IRDM_OK);
	irdm_device_config_default(&dev);
	irdm_sim_params_default(&params);
	assert_int_equal(irdm_can_drives_init(&dr, &drives_port, &dev, &params, 3, 1, 1e-3),
			 IRDM_OK);
	/* the PDOs synchronous, as the master's set-up leaves them (its SDOs:
	 * test_can_master, test_can_drives) */
	for (unsigned k = 0; k < 3; k++)
		dr.d[k].rpdo1.transmission = dr.d[k].tpdo1.transmission = 1;
	assert_int_equal(irdm_co_nmt(&f, IRDM_CO_NMT_START, 0), IRDM_OK);
	assert_int_equal(irdm_can_send(&master, &f), IRDM_OK);
	irdm_can_drives_poll(&dr);
	while (irdm_can_recv(&master, &f) == 1)
		; /* boot-up heartbeats */
}

static void schedule(const char *word)
{
	struct irdm_can_fault f;
	char err[160];

	assert_int_equal(irdm_can_fault_parse(word, &f, err, sizeof(err)), IRDM_OK);
	assert_int_equal(irdm_can_drives_schedule(&dr, &f), IRDM_OK);
}

/* One SYNC; the frames of each id it brought back. */
static void sync_count(unsigned *by_id, size_t n_ids)
{
	struct irdm_can_frame f;

	memset(by_id, 0, n_ids * sizeof(*by_id));
	assert_int_equal(irdm_co_sync(&f, 0), IRDM_OK);
	assert_int_equal(irdm_can_send(&master, &f), IRDM_OK);
	irdm_can_drives_poll(&dr);
	while (irdm_can_recv(&master, &f) == 1)
		if (f.id < n_ids)
			by_id[f.id]++;
}

static void test_drop_exactly_k_from_n(void **state)
{
	unsigned ids[0x800];

	(void)state;
	bring_up();
	schedule("drop:2:5:3");
	for (unsigned s = 1; s <= 10; s++) {
		sync_count(ids, 0x800);
		assert_int_equal(ids[0x181], 1);
		assert_int_equal(ids[0x183], 1);
		assert_int_equal(ids[0x182], s >= 5 && s < 8 ? 0 : 1);
	}
	assert_int_equal(dr.tpdos_dropped, 3);
	assert_int_equal(dr.faults_fired, 1);
}

/* Drain what the master hears; how many frames had this id. */
static unsigned count_id(uint32_t id)
{
	return can_drain_count(&master, id);
}

static void test_delay_on_the_wall_clock(void **state)
{
	unsigned ids[0x800];

	(void)state;
	bring_up();
	irdm_can_drives_wall(&dr, 1000000);
	schedule("delay:1:2:2:500");
	sync_count(ids, 0x800);
	assert_int_equal(ids[0x181], 1);
	sync_count(ids, 0x800); /* SYNC 2: held */
	assert_int_equal(ids[0x181], 0);
	assert_int_equal(irdm_can_drives_wall(&dr, 1000499), 1000500);
	assert_int_equal(count_id(0x181), 0);
	assert_int_equal(irdm_can_drives_wall(&dr, 1000500), UINT64_MAX);
	assert_int_equal(count_id(0x181), 1);
	sync_count(ids, 0x800); /* SYNC 3: held again */
	assert_int_equal(ids[0x181], 0);
	sync_count(ids, 0x800); /* SYNC 4: the held one first, then its own */
	assert_int_equal(ids[0x181], 2);
	assert_int_equal(dr.tpdos_delayed, 2);
}

static void test_heartbeat_wall_and_stop(void **state)
{
	unsigned ids[0x800];
	const uint64_t t0 = 5000000;

	(void)state;
	bring_up();
	dr.wall_heartbeat = true;
	for (unsigned k = 0; k < 3; k++)
		dr.d[k].heartbeat_ms = 10;
	schedule("heartbeat-stop:3:2");
	for (uint64_t ms = 0; ms <= 100; ms++) /* no SYNC: the wall clock alone */
		irdm_can_drives_wall(&dr, t0 + 1000 * ms);
	assert_int_equal(count_id(0x703), 11); /* at 0, 10, ..., 100 ms */
	sync_count(ids, 0x800);
	sync_count(ids, 0x800); /* SYNC 2: node 3 goes silent */
	for (uint64_t ms = 101; ms <= 200; ms++)
		irdm_can_drives_wall(&dr, t0 + 1000 * ms);
	assert_int_equal(count_id(0x703), 0);
	for (uint64_t ms = 201; ms <= 300; ms++)
		irdm_can_drives_wall(&dr, t0 + 1000 * ms);
	assert_int_equal(count_id(0x701), 10); /* the others beat on */
}

/* word makes node 2 fault at SYNC 4; the EMCY frames heard. */
static unsigned fault_at_4(const char *word)
{
	struct irdm_can_frame f;
	uint16_t sw;
	int32_t pos;
	unsigned emcy = 0;

	bring_up();
	schedule(word);
	for (unsigned s = 1; s <= 4; s++) {
		assert_int_equal(irdm_co_sync(&f, 0), IRDM_OK);
		assert_int_equal(irdm_can_send(&master, &f), IRDM_OK);
		irdm_can_drives_poll(&dr);
		while (irdm_can_recv(&master, &f) == 1) {
			if (f.id == 0x082) {
				assert_int_equal(s, 4);
				assert_int_equal(f.data[0] | f.data[1] << 8, 0x2310);
				emcy++;
			}
			if (f.id == 0x182) {
				assert_int_equal(irdm_co_tpdo_cst(&f, 2, &sw, &pos), IRDM_OK);
				assert_int_equal(irdm_cia402_decode(sw) == IRDM_CIA402_FAULT ||
							 irdm_cia402_decode(sw) ==
								 IRDM_CIA402_FAULT_REACTION_ACTIVE,
						 s == 4);
			}
		}
	}
	return emcy;
}

static void test_emcy_and_fault_at_n(void **state)
{
	(void)state;
	assert_int_equal(fault_at_4("emcy:2:4:0x2310"), 1);
}

static void test_fault_without_emcy(void **state)
{
	(void)state;
	assert_int_equal(fault_at_4("fault:2:4"), 0);
}

static void test_sdo_wrong_from_start(void **state)
{
	struct irdm_can_frame f;
	unsigned answers = 0;

	(void)state;
	bring_up();
	schedule("sdo-wrong:1");
	assert_int_equal(irdm_co_sdo_read(&f, 1, 0x6041, 0), IRDM_OK);
	assert_int_equal(irdm_can_send(&master, &f), IRDM_OK);
	assert_int_equal(irdm_co_sdo_read(&f, 2, 0x6041, 0), IRDM_OK);
	assert_int_equal(irdm_can_send(&master, &f), IRDM_OK);
	irdm_can_drives_poll(&dr);
	while (irdm_can_recv(&master, &f) == 1) {
		uint32_t v, abort_code;
		unsigned size;
		unsigned node = f.id - 0x580;

		answers++;
		assert_int_equal(irdm_co_sdo_answer(&f, node, 0x6041, 0, &v, &size, &abort_code),
				 node == 1 ? IRDM_EFORMAT : IRDM_OK);
	}
	assert_int_equal(answers, 2);
}

static void test_flood_bounded(void **state)
{
	unsigned ids[0x800];

	(void)state;
	bring_up();
	schedule("flood:2:500");
	sync_count(ids, 0x800);
	assert_int_equal(ids[IRDM_CAN_FLOOD_ID], 0);
	sync_count(ids, 0x800);
	assert_int_equal(ids[IRDM_CAN_FLOOD_ID], 500);
	assert_int_equal(dr.flood_sent, 500);
	sync_count(ids, 0x800);
	assert_int_equal(ids[IRDM_CAN_FLOOD_ID], 0);
}

/* Docked, the arm does not move (gravity pulls on it) until a drive
 * applies torque; then it does. */
static void test_dock_until_torque(void **state)
{
	unsigned ids[0x800];
	double q0[3], q[3], qd[3];
	struct irdm_can_frame f;

	(void)state;
	bring_up();
	dr.docked = true;
	for (unsigned k = 0; k < 3; k++)
		dr.d[k].mode = 10; /* cyclic synchronous torque */
	irdm_sim_device_state(&dr.arm, q0, qd);
	for (int s = 0; s < 50; s++)
		sync_count(ids, 0x800);
	irdm_sim_device_state(&dr.arm, q, qd);
	assert_memory_equal(q, q0, sizeof(q));
	for (unsigned r = 0; r < 6; r++) { /* shutdown, switch on, enable, hold */
		static const uint16_t cw[6] = { 0x06, 0x07, 0x0F, 0x0F, 0x0F, 0x0F };

		for (unsigned node = 1; node <= 3; node++) {
			assert_int_equal(irdm_co_rpdo_cst(&f, node, cw[r], node == 2 ? 10 : 0),
					 IRDM_OK);
			assert_int_equal(irdm_can_send(&master, &f), IRDM_OK);
		}
		irdm_can_drives_poll(&dr);
		sync_count(ids, 0x800);
	}
	for (int s = 0; s < 20 && dr.docked; s++)
		sync_count(ids, 0x800);
	assert_false(dr.docked);
	for (int s = 0; s < 50; s++)
		sync_count(ids, 0x800);
	irdm_sim_device_state(&dr.arm, q, qd);
	assert_true(q[1] != q0[1]);
}

static void test_schedule_refuses(void **state)
{
	struct irdm_can_fault f = { .kind = IRDM_CAN_FAULT_DROP, .node = 4, .at_sync = 1, .count = 1 };

	(void)state;
	bring_up();
	assert_int_equal(irdm_can_drives_schedule(&dr, &f), IRDM_EINVAL);
	f.node = 1;
	for (unsigned k = 0; k < IRDM_CAN_FAULTS_MAX; k++)
		assert_int_equal(irdm_can_drives_schedule(&dr, &f), IRDM_OK);
	assert_int_equal(irdm_can_drives_schedule(&dr, &f), IRDM_ENOMEM);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_parse_each_kind),
		cmocka_unit_test(test_parse_refuses),
		cmocka_unit_test(test_drop_exactly_k_from_n),
		cmocka_unit_test(test_delay_on_the_wall_clock),
		cmocka_unit_test(test_heartbeat_wall_and_stop),
		cmocka_unit_test(test_emcy_and_fault_at_n),
		cmocka_unit_test(test_fault_without_emcy),
		cmocka_unit_test(test_sdo_wrong_from_start),
		cmocka_unit_test(test_flood_bounded),
		cmocka_unit_test(test_dock_until_torque),
		cmocka_unit_test(test_schedule_refuses),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
