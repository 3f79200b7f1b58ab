/* SPDX-License-Identifier: MIT */
/*
 * The CAN back-ends through the HAL ops (irdm/hal.h): "canemu" (the master
 * on the in-memory bus with emulated drives) end to end - open, start,
 * read, write, a drive fault turning every axis off with one line naming
 * the drive, safe_off - with the bus log from the membus tap; the board
 * options refused by name; "socketcan" on an interface that does not
 * exist; and the tick's ops (read, write, poll, safe_off) over many ticks,
 * a fault among them, in seccomp strict mode with the allocator counted:
 * no system call, no allocation.
 */
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdalign.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "irdm/error.h"
#include "irdm/hal/hal_can.h"
#include "irdm/sim/hal_canemu.h"
#include "irdm/sim/hal_sim.h"
#include "irdm/hal/hal_socketcan.h"

#include "support/alloc_count.h"
#include "support/strict_mode.h"
#include "support/test_files.h"

#define OPTS "nodes=1,2,3 rated_torque_mnm=100 heartbeat_ms=10 heartbeat_timeout_ms=50 " \
	     "tpdo_missing_periods=3 sync_counter=yes"

static struct irdm_device_config arm;
static struct irdm_hal_config cfg;
static struct irdm_hal_dev dev;
static alignas(max_align_t) unsigned char mem[1 << 16];

struct logged {
	struct irdm_can_frame f;
	unsigned from;
};
static struct logged bus_log[4096];
static unsigned n_log;

static void tap(void *ctx, const struct irdm_can_frame *f, unsigned from)
{
	(void)ctx;
	if (n_log < sizeof(bus_log) / sizeof(bus_log[0]))
		bus_log[n_log++] = (struct logged){ *f, from };
}

static int open_as(const char *backend, const char *options)
{
	int rc;

	irdm_device_config_default(&arm);
	cfg = (struct irdm_hal_config){ &arm, options, 1e-3 };
	assert_int_equal(irdm_hal_register(&irdm_hal_canemu_backend), IRDM_OK);
	assert_int_equal(irdm_hal_register(&irdm_hal_socketcan_backend), IRDM_OK);
	assert_int_equal(irdm_hal_init(&dev, backend, &cfg, mem, sizeof(mem)), IRDM_OK);
	rc = irdm_hal_open(&dev);
	if (rc == IRDM_OK && !strcmp(backend, "canemu")) {
		n_log = 0;
		irdm_hal_canemu_bus(&dev)->tap = tap;
	}
	return rc;
}

/*
 * Each back-end's check_options, as irdm-fw calls it before opening: the
 * message names the board file and line it is given, the key and the
 * reason, exactly; docs/hal-options.md shows three of them as they are.
 */
static void test_check_options_name_the_line(void **state)
{
	static const struct {
		const struct irdm_hal_backend *be;
		const char *options, *why;
		bool in_doc;
	} cases[] = {
		{ &irdm_hal_sim_backend, "write_delay=999",
		  "boards/x.board:16: hal_options: write_delay = 999: must be <= 16", true },
		{ &irdm_hal_sim_backend, "substeps=10,delay=1",
		  "boards/x.board:16: hal_options: unknown sim option 'delay' "
		  "(see docs/hal-options.md)",
		  true },
		{ &irdm_hal_sim_backend, "end_stops",
		  "boards/x.board:16: hal_options: 'end_stops': expected key=value", false },
		{ &irdm_hal_canemu_backend, "rated_torque_mnm=100",
		  "boards/x.board:22: hal_options: nodes: missing (one node id per joint, "
		  "e.g. nodes=1,2,3)",
		  true },
		{ &irdm_hal_canemu_backend, "nodes=1,2,3 rated_torque_mnm=100 emcy_at=4:10",
		  "boards/x.board:22: hal_options: emcy_at = 4:10: expected DRIVE:MS, drive 1..3, "
		  "0..3600000 ms",
		  false },
		{ &irdm_hal_socketcan_backend, "iface=can0 nodes=1,2,3 rated_torque_mnm=100 bitrate=5",
		  "boards/x.board:23: hal_options: bitrate = 5: must be >= 10000 bit/s", false },
		{ &irdm_hal_socketcan_backend, "iface=can0 nodes=1,2,3 rated_torque_mnm=100 substeps=2",
		  "boards/x.board:23: hal_options: unknown socketcan option 'substeps' "
		  "(see docs/hal-options.md)",
		  false },
		{ &irdm_hal_socketcan_backend, "nodes=1,2,3 rated_torque_mnm=100",
		  "boards/x.board:23: hal_options: iface: missing (the CAN interface, e.g. "
		  "iface=can0)",
		  false },
	};
	static char doc[16384];
	char err[256], where[64];
	(void)state;

	tf_read_text("docs/hal-options.md", doc, sizeof(doc));
	for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		const struct irdm_hal_backend *be = cases[i].be;

		snprintf(where, sizeof(where), "boards/x.board:%s: hal_options",
			 be == &irdm_hal_sim_backend ? "16" : be == &irdm_hal_canemu_backend ? "22" :
											       "23");
		assert_non_null(be->check_options);
		assert_int_equal(be->check_options(cases[i].options, where, err, sizeof(err)),
				 IRDM_EINVAL);
		assert_string_equal(err, cases[i].why);
		if (cases[i].in_doc && !strstr(doc, cases[i].why))
			fail_msg("docs/hal-options.md does not show '%s'", cases[i].why);
	}
	/* the shipped boards' options pass */
	assert_int_equal(irdm_hal_sim_backend.check_options("write_delay=0,read_delay=0,substeps=10",
							    "s", err, sizeof(err)),
			 IRDM_OK);
	assert_int_equal(irdm_hal_canemu_backend.check_options(OPTS, "c", err, sizeof(err)),
			 IRDM_OK);
}

static void test_options_refused_by_name(void **state)
{
	static const struct {
		const char *options, *why;
	} cases[] = {
		{ "nodes=1,2,3", "hal_options: rated_torque_mnm: missing (the drives' rated torque)" },
		{ "rated_torque_mnm=100", "hal_options: nodes: missing (one node id per joint, e.g. "
					  "nodes=1,2,3)" },
		{ "nodes=1,2 rated_torque_mnm=100",
		  "hal_options: nodes: 2 node(s) given, the arm has 3 joints" },
		{ "nodes=1,2,300 rated_torque_mnm=100",
		  "hal_options: nodes = 1,2,300: expected 1 to 3 node ids 1..127, e.g. 1,2,3" },
		{ "nodes=1,2,3, rated_torque_mnm=100",
		  "hal_options: nodes = 1,2,3,: expected 1 to 3 node ids 1..127, e.g. 1,2,3" },
		{ OPTS " bitrate=2000000", "hal_options: bitrate = 2000000: must be <= 1000000 bit/s" },
		{ OPTS " bitrate=500000", "bitrate: one cycle needs 695 bits worst case, 1000 us at "
					  "500000 bit/s carries 500" },
		{ OPTS " sync_counter=maybe", "hal_options: sync_counter = maybe: expected yes | no" },
		{ OPTS " iface=can0",
		  "hal_options: unknown canemu option 'iface' (see docs/hal-options.md)" },
		{ OPTS " speed", "hal_options: 'speed': expected key=value" },
		{ OPTS " heartbeat_timeout_ms=5", "hal_options: heartbeat_timeout_ms: must exceed "
						  "heartbeat_ms" },
		{ "nodes=1,3,4 rated_torque_mnm=100", "hal_options: nodes: the emulator's nodes are "
						      "consecutive (e.g. 1,2,3)" },
		{ OPTS " master_node=2", "hal_options: master_node: is a drive's node id" },
		{ OPTS " master_node=128", "hal_options: master_node = 128: must be <= 127" },
		{ OPTS " rpdo_timeout_ms=0", "hal_options: rpdo_timeout_ms = 0: must be >= 1 ms" },
	};

	(void)state;
	for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		assert_int_equal(open_as("canemu", cases[i].options), IRDM_EINVAL);
		assert_string_equal(dev.why, cases[i].why);
	}
	assert_int_equal(open_as("socketcan", OPTS), IRDM_EINVAL);
	assert_string_equal(dev.why, "hal_options: iface: missing (the CAN interface, e.g. iface=can0)");
}

static void test_socketcan_without_interface(void **state)
{
	int rc;

	(void)state;
	rc = open_as("socketcan", "iface=nosuchcan7 " OPTS);
	print_message("socketcan on nosuchcan7: %s: %s\n", irdm_errname(rc), dev.why);
	assert_true(rc == IRDM_EIO || rc == IRDM_ENOTSUP);
	assert_non_null(strstr(dev.why, "nosuchcan7"));
}

static const double NULL_TAU[3] = { 0, 0, 0 };

/* The SocketCAN port's flags into a master running on emulated drives. */
static void test_socketcan_bus_off_loses_link(void **state)
{
	struct irdm_socketcan sock = { .fd = -1 };
	struct irdm_hal_joint_state st;
	struct irdm_can_master *m;

	(void)state;
	assert_int_equal(open_as("canemu", OPTS), IRDM_OK);
	assert_int_equal(irdm_hal_start(&dev), IRDM_OK);
	m = &((struct irdm_hal_can *)dev.data)->m;
	sock.error_passive = true;
	irdm_hal_socketcan_judge(&sock, m);
	assert_false(m->faulted);
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	/* one period without a TPDO: the latest counts stand (the master loses
	 * the drive after tpdo_missing_periods; test_hal_can_wire) */
	irdm_hal_canemu_drives(&dev)->d[2].drop_tpdos = 1;
	assert_int_equal(irdm_hal_write(&dev, NULL_TAU), IRDM_OK);
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	assert_int_equal(m->ax[2].missing, 1);
	assert_int_equal(irdm_hal_write(&dev, NULL_TAU), IRDM_OK);
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	assert_string_equal(dev.why, "");
	sock.bus_off = true;
	n_log = 0;
	irdm_hal_socketcan_judge(&sock, m);
	assert_true(m->faulted && m->link_lost);
	assert_string_equal(m->why, "CAN link: bus-off (the controller left the bus)");
	assert_int_equal(n_log, 4); /* off to 0x201..0x203, then the SYNC */
	for (unsigned i = 0; i < 3; i++) {
		assert_int_equal(bus_log[i].f.id, 0x201 + i);
		assert_int_equal(bus_log[i].f.data[0] | bus_log[i].f.data[1] | bus_log[i].f.data[2] |
					 bus_log[i].f.data[3],
				 0);
	}
	assert_int_equal(bus_log[3].f.id, 0x080);
	irdm_hal_close(&dev);
}

static void run_ticks(int n, const double tau[3], int *bad)
{
	struct irdm_hal_joint_state st;
	uint32_t faults;

	for (int k = 0; k < n; k++) {
		*bad += irdm_hal_read(&dev, &st) != IRDM_OK;
		*bad += irdm_hal_poll(&dev, &faults) != IRDM_OK;
		*bad += irdm_hal_write(&dev, tau) != IRDM_OK;
	}
}

static void test_canemu_runs_and_faults(void **state)
{
	double tau[3] = { 0.0, 0.098, 0.0 }; /* about the shoulder's gravity torque */
	struct irdm_hal_joint_state st;
	uint32_t faults;
	unsigned mark;
	bool off[3] = { false, false, false };
	int bad = 0;

	(void)state;
	assert_int_equal(open_as("canemu", OPTS), IRDM_OK);
	/* the bus load, then each drive as its 0x1000 and 0x1018 say */
	assert_string_equal(dev.info, "CAN bus load: SYNC + 3 x RPDO1 (4 B) + 3 x TPDO1 (6 B) = "
				      "695 bits worst case in 1000 us at 1000000 bit/s: 69.5 %\n"
				      "drive 1 (node 1): CiA 402 device type 0x00020192, vendor 0x00000000, "
				      "product 0x00000402, revision 0x00010000, serial 0x00000001\n"
				      "drive 2 (node 2): CiA 402 device type 0x00020192, vendor 0x00000000, "
				      "product 0x00000402, revision 0x00010000, serial 0x00000002\n"
				      "drive 3 (node 3): CiA 402 device type 0x00020192, vendor 0x00000000, "
				      "product 0x00000402, revision 0x00010000, serial 0x00000003");
	assert_int_equal(irdm_hal_write(&dev, tau), IRDM_EINVAL); /* not started */
	assert_int_equal(irdm_hal_start(&dev), IRDM_OK);
	run_ticks(100, tau, &bad);
	assert_int_equal(bad, 0);
	{ /* a torque that is not a number: refused, zero sent instead */
		double nan_tau[3] = { 0.0, 0.0 / 0.0, 0.0 };

		assert_int_equal(irdm_hal_write(&dev, nan_tau), IRDM_EFAULT);
		assert_int_equal(irdm_hal_canemu_drives(&dev)->d[1].rpdo_torque_permille, 0);
		assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
		assert_int_equal(irdm_hal_write(&dev, tau), IRDM_OK);
		/* 0.098 N m / 11.6 = 8.45 mN m = 84.5 per mille of 100 mN m -> 84 */
		assert_int_equal(irdm_hal_canemu_drives(&dev)->d[1].rpdo_torque_permille, 84);
	}
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	assert_int_equal(st.seq, 102);
	/* drive 2 raises EMCY 0x4210 (temperature) and faults */
	mark = n_log;
	irdm_can_drives_fault(irdm_hal_canemu_drives(&dev), 1, 0x4210);
	assert_int_equal(irdm_hal_write(&dev, tau), IRDM_OK); /* the EMCY is not read yet */
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_EHW);
	/* in the same tick, before any write: every emulated drive was told off */
	for (unsigned k = 0; k < 3; k++) {
		assert_int_equal(irdm_hal_canemu_drives(&dev)->d[k].rpdo_cw, 0);
		assert_int_equal(irdm_hal_canemu_drives(&dev)->d[k].rpdo_torque_permille, 0);
	}
	assert_int_equal(irdm_hal_poll(&dev, &faults), IRDM_EHW);
	assert_int_equal(faults, IRDM_HAL_FAULT_DRIVE);
	assert_string_equal(dev.why, "drive 2 (node 2): EMCY 0x4210 (temperature), error register 0x01");
	assert_int_equal(irdm_hal_write(&dev, tau), IRDM_EHW);
	/* from the master (endpoint 0), after the EMCY: 0x00 00 00 00 to 0x201..0x203 */
	for (unsigned i = mark; i < n_log; i++) {
		const struct irdm_can_frame *f = &bus_log[i].f;

		if (bus_log[i].from == 0 && f->id >= 0x201 && f->id <= 0x203 && f->dlc == 4 &&
		    !f->data[0] && !f->data[1] && !f->data[2] && !f->data[3])
			off[f->id - 0x201] = true;
	}
	assert_true(off[0] && off[1] && off[2]);
	for (unsigned k = 0; k < 3; k++)
		assert_int_not_equal(irdm_hal_canemu_drives(&dev)->d[k].fsa.state,
				     IRDM_CIA402_OPERATION_ENABLED);
	assert_int_equal(irdm_hal_safe_off(&dev), IRDM_OK);
	assert_int_equal(irdm_hal_start(&dev), IRDM_EHW); /* latched */
	/* the operator's reset: the drive leaves fault, and enables again */
	irdm_hal_can_reset_faults(&dev);
	for (int k = 0; k < 5; k++)
		irdm_hal_read(&dev, &st);
	assert_int_equal(irdm_hal_start(&dev), IRDM_OK);
	irdm_hal_close(&dev);
	assert_null(irdm_hal_canemu_drives(&dev));
}

/* One SYNC per tick and one RPDO per axis before each, also in ticks the
 * loop does not write (the read closes the period), counter +1 each. */
static void test_one_sync_per_tick(void **state)
{
	double tau[3] = { 0.0, 0.098, 0.0 };
	struct irdm_hal_joint_state st;
	unsigned rpdos[3] = { 0, 0, 0 }, syncs = 0, last = 0;

	(void)state;
	assert_int_equal(open_as("canemu", OPTS), IRDM_OK);
	assert_int_equal(irdm_hal_start(&dev), IRDM_OK);
	n_log = 0;
	for (int k = 0; k < 300; k++) {
		assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
		if (k % 3) /* every third tick writes nothing */
			assert_int_equal(irdm_hal_write(&dev, tau), IRDM_OK);
	}
	for (unsigned i = 0; i < n_log; i++) {
		const struct irdm_can_frame *f = &bus_log[i].f;

		if (bus_log[i].from != 0)
			continue;
		if (f->id == 0x080) {
			for (int a = 0; a < 3; a++)
				assert_int_equal(rpdos[a], 1);
			memset(rpdos, 0, sizeof(rpdos));
			if (syncs++)
				assert_int_equal(f->data[0], last % 240 + 1);
			last = f->data[0];
		} else if (f->id != 0x77F) { /* (the master's heartbeat) */
			assert_true(f->id >= 0x201 && f->id <= 0x203);
			rpdos[f->id - 0x201]++;
		}
	}
	/* start's last SYNC was before the log; then one per tick */
	assert_int_equal(syncs, 300);
	irdm_hal_close(&dev);
}

/*
 * start: the cycle runs with every drive held at disable voltage (RPDO1
 * 00 00 00 00) for 5 SYNCs answered by every drive, with the master's
 * heartbeat from the first; only then the enable sequence (0x06, ...).
 */
static void test_start_steady_before_enable(void **state)
{
	unsigned syncs = 0, first_enable_sync = 0, beats_before = 0;

	(void)state;
	assert_int_equal(open_as("canemu", OPTS), IRDM_OK);
	assert_int_equal(irdm_hal_start(&dev), IRDM_OK);
	for (unsigned i = 0; i < n_log; i++) {
		const struct irdm_can_frame *f = &bus_log[i].f;

		if (bus_log[i].from != 0)
			continue;
		if (f->id == 0x080)
			syncs++;
		else if (f->id == 0x77F && !first_enable_sync)
			beats_before++;
		else if (f->id >= 0x201 && f->id <= 0x203 && (f->data[0] | f->data[1]) &&
			 !first_enable_sync)
			first_enable_sync = syncs + 1;
	}
	print_message("start: %u SYNCs, the enable sequence from SYNC %u\n", syncs,
		      first_enable_sync);
	assert_int_equal(first_enable_sync, 6);
	assert_int_equal(beats_before, 1);
	irdm_hal_close(&dev);
}

static void test_canemu_start_times_out(void **state)
{
	(void)state;
	/* 2 ms: not even the disabled SYNCs that come before enabling */
	assert_int_equal(open_as("canemu", OPTS " enable_timeout_ms=2"), IRDM_OK);
	assert_int_equal(irdm_hal_start(&dev), IRDM_ETIMEDOUT);
	assert_string_equal(dev.why, "CAN: fewer than 5 SYNCs answered in a row before enabling, "
				     "within 2 ms");
	irdm_hal_close(&dev);
	/* 6 ms: those, then not the enable sequence (3 SYNCs at least) */
	assert_int_equal(open_as("canemu", OPTS " enable_timeout_ms=6"), IRDM_OK);
	assert_int_equal(irdm_hal_start(&dev), IRDM_ETIMEDOUT);
	assert_non_null(strstr(dev.why, "drive 1 (node 1): not operation enabled after 6 ms ("));
	irdm_hal_close(&dev);
}

/* ---- the tick's ops in seccomp strict mode ---- */

#define STRICT_TICKS 2000
#define STRICT_MAGIC 0x43414e53u

struct strict_result {
	uint32_t magic;
	int prctl_errno;
	unsigned long allocs;
	int bad, faults_seen;
};

static void strict_child(void *arg, int fd)
{
	double tau[3] = { 0.0, 0.098, 0.0 };
	struct strict_result res = { .magic = STRICT_MAGIC };
	struct irdm_hal_joint_state st;
	uint32_t faults;
	bool slip = arg != NULL;

	run_ticks(10, tau, &res.bad); /* every path once before the filter */
	res.prctl_errno = strict_enter();
	if (res.prctl_errno)
		strict_exit(fd, &res, sizeof(res), STRICT_UNAVAILABLE);
	alloc_arm();
	run_ticks(STRICT_TICKS, tau, &res.bad);
	if (slip)
		syscall(SYS_getppid);
	/* a drive drops its TPDOs: lost after 3 periods, every axis off */
	irdm_hal_canemu_drives(&dev)->d[2].drop_tpdos = 1000;
	for (int k = 0; k < 10; k++) {
		irdm_hal_read(&dev, &st);
		if (irdm_hal_poll(&dev, &faults) == IRDM_EHW)
			res.faults_seen++;
		irdm_hal_write(&dev, tau);
	}
	res.bad += irdm_hal_safe_off(&dev) != IRDM_OK;
	res.bad += irdm_hal_safe_off(&dev) != IRDM_OK;
	res.allocs = alloc_calls();
	strict_exit(fd, &res, sizeof(res), 0);
}

static int run_strict(bool slip, struct strict_result *res)
{
	size_t got;
	int status;

	assert_int_equal(open_as("canemu", OPTS), IRDM_OK);
	assert_int_equal(irdm_hal_start(&dev), IRDM_OK);
	status = strict_run(strict_child, slip ? (void *)1 : NULL, res, sizeof(*res), &got);
	irdm_hal_close(&dev);
	if (WIFEXITED(status) && WEXITSTATUS(status) == STRICT_UNAVAILABLE) {
		print_message("  seccomp strict mode not available (errno %d): skipped\n",
			      res->prctl_errno);
		skip();
	}
	return status;
}

static void test_tick_ops_no_system_call_no_allocation(void **state)
{
	struct strict_result res;
	int status;

	(void)state;
	status = run_strict(false, &res);
	if (WIFSIGNALED(status))
		fail_msg("strict-mode child died of signal %d (SIGKILL: a system call in the tick)",
			 WTERMSIG(status));
	assert_int_equal(WEXITSTATUS(status), 0);
	assert_int_equal(res.magic, STRICT_MAGIC);
	print_message("  %d ticks + 10 with a drive lost: %d failed ops, %d polls with the fault, "
		      "%lu allocator calls%s\n",
		      STRICT_TICKS, res.bad, res.faults_seen, res.allocs,
		      alloc_counting() ? "" : " (not counted: ASan owns the allocator)");
	assert_int_equal(res.bad, 0);
	/* tick 1 still reads the TPDO of the SYNC before the drop; ticks 2, 3, 4
	 * miss it; lost at the third: ticks 4..10 poll the fault */
	assert_int_equal(res.faults_seen, 7);
	assert_int_equal(res.allocs, 0);
	/* the control: one system call is caught */
	status = run_strict(true, &res);
	assert_true(WIFSIGNALED(status));
	assert_int_equal(WTERMSIG(status), SIGKILL);
}

/*
 * canemu's emergency op, mid-run with torque on, as a signal handler runs
 * it (strict mode: no system call): the in-memory bus may be mid-send
 * there, so it sends no frame; every emulated drive holds controlword
 * 0x0000 (CiA 402 disable voltage) and target torque 0 as if it had
 * received the off RPDO1, and the arm's torque is zero at once.
 */
#define EMERGENCY_MAGIC 0x454d4f46u
struct emergency_result {
	uint32_t magic;
	int rc;
	unsigned frames; /* frames on the bus during the call */
	uint16_t cw[3];
	int16_t torque[3];
	double arm_nm; /* sum of |command| and |motor| torques */
};

static void emergency_child(void *arg, int fd)
{
	struct emergency_result res = { .magic = EMERGENCY_MAGIC };
	struct irdm_can_drives *dr = irdm_hal_canemu_drives(&dev);
	unsigned mark = n_log;

	(void)arg;
	if (strict_enter())
		strict_exit(fd, &res, sizeof(res), STRICT_UNAVAILABLE);
	res.rc = irdm_hal_emergency_off(&dev);
	res.frames = n_log - mark;
	for (unsigned k = 0; k < 3; k++) {
		res.cw[k] = dr->d[k].rpdo_cw;
		res.torque[k] = dr->d[k].rpdo_torque_permille;
		res.arm_nm += fabs(dr->arm.cmd_nm[k]) + fabs(dr->arm.motor_nm[k]);
	}
	strict_exit(fd, &res, sizeof(res), 0);
}

static void test_canemu_emergency_off(void **state)
{
	double tau[3] = { 0.05, 0.098, -0.05 };
	struct irdm_can_drives *dr;
	struct emergency_result res;
	size_t got;
	int status, bad = 0;

	(void)state;
	assert_int_equal(open_as("canemu", OPTS), IRDM_OK);
	assert_int_equal(irdm_hal_start(&dev), IRDM_OK);
	run_ticks(50, tau, &bad);
	assert_int_equal(bad, 0);
	dr = irdm_hal_canemu_drives(&dev);
	assert_int_equal(dr->d[1].rpdo_torque_permille, 84); /* as test_canemu_runs_and_faults */
	assert_int_equal(dr->d[1].rpdo_cw, 0x0F);            /* enable operation */
	status = strict_run(emergency_child, NULL, &res, sizeof(res), &got);
	irdm_hal_close(&dev);
	if (WIFEXITED(status) && WEXITSTATUS(status) == STRICT_UNAVAILABLE)
		skip();
	if (WIFSIGNALED(status))
		fail_msg("canemu's emergency op died of signal %d", WTERMSIG(status));
	assert_int_equal(got, sizeof(res));
	assert_int_equal(res.magic, EMERGENCY_MAGIC);
	assert_int_equal(res.rc, IRDM_OK);
	assert_int_equal(res.frames, 0);
	for (unsigned k = 0; k < 3; k++) {
		assert_int_equal(res.cw[k], 0x0000);
		assert_int_equal(res.torque[k], 0);
	}
	assert_true(res.arm_nm == 0.0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_check_options_name_the_line),
		cmocka_unit_test(test_options_refused_by_name),
		cmocka_unit_test(test_socketcan_without_interface),
		cmocka_unit_test(test_canemu_emergency_off),
		cmocka_unit_test(test_socketcan_bus_off_loses_link),
		cmocka_unit_test(test_canemu_runs_and_faults),
		cmocka_unit_test(test_one_sync_per_tick),
		cmocka_unit_test(test_start_steady_before_enable),
		cmocka_unit_test(test_canemu_start_times_out),
		cmocka_unit_test(test_tick_ops_no_system_call_no_allocation),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
