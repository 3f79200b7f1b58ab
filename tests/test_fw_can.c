/* SPDX-License-Identifier: MIT */
/*
 * irdm-fw (the built binary) on the in-process CAN board
 * (boards/canemu-3dof.board: the CANopen master, the in-memory bus, the
 * emulated CiA 402 drives) with scenes/users/press-hold-release.user in
 * virtual time, against the same script on boards/sim-phantom.board with
 * the sim back-end's write_delay=1 (the one-period delay synchronous PDOs
 * have).  Also: the bus load printed at start, and a bad hal_options line
 * refused in one line naming the option.
 *
 * What differs, and so the tolerance (measured, then a margin).  Per
 * tick |F_can - F_sim| against write_delay=1: max 0.021 N (4.5 % of the
 * 0.467 N peak, at release, 3.246 s), p99 0.012 N; peaks 0.4660 vs
 * 0.4667 N at 1.245 vs 1.241 s.  Where it comes from, measured by
 * changing one thing at a time (not kept in the tree):
 *  - timing: in sim back-end terms the emulated bus is closest to
 *    write_delay=0, read_delay=1 (max 0.015 N, p99 0.008 N): an RPDO's
 *    torque acts from the SYNC right after it, and the TPDO carries the
 *    position sampled at that SYNC, before the period's step.  The brief's
 *    reference (write_delay=1) is one of the neighbours, not the match;
 *    it is kept, and the closer model is checked beside it.
 *  - start-up: enabling the drives takes 5 SYNCs, 5 periods of the
 *    emulated arm at zero torque before the first tick (it has started to
 *    fall when calibrated); without them the first ticks' angles match
 *    the sim run exactly, but the largest difference stays (p99 0.008 ->
 *    0.005 N against write_delay=0/read_delay=1).
 *  - torque quantisation (1 per mille of 100 mN m rated: 1.16 mN m at the
 *    joint) is not a factor: 10 mN m rated gives the same numbers.
 * Tolerances: 0.03 N per tick against write_delay=1, 0.02 N against
 * write_delay=0/read_delay=1; peak within 1 %, its time within 20 ms.
 *
 * Needs IRDM and IRDM_FW (make test sets them); runs from the repository root.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "irdm/posix/telemetry_log.h"
#include "irdm/safety.h"
#include "irdm/telemetry.h"
#include "support/run_prog.h"
#include "support/test_files.h"

#define TICKS 6200 /* the script's end + 1 s at 1 kHz */

static char dir[256], image[320], out_text[8192], err_text[4096];

static const char *env_or(const char *name, const char *dflt)
{
	const char *p = getenv(name);

	return p ? p : dflt;
}

static int run(const char *prog, const char *const *args)
{
	return rp_run(dir, prog, args, out_text, sizeof(out_text), err_text, sizeof(err_text));
}

struct trace {
	size_t n, contact;
	double f_n[TICKS];
	double peak_n;
	size_t peak_at;
	bool faulted;
};

static void read_trace(const char *log, struct trace *t)
{
	struct irdm_log_reader *r;
	static struct irdm_tick_record rec;
	char err[256];

	memset(t, 0, sizeof(*t));
	assert_int_equal(irdm_log_open(&r, log, err, sizeof(err)), 0);
	while (t->n < TICKS && irdm_log_next(r, &rec, err, sizeof(err)) == 1) {
		const double *f = rec.dev[0].force_n;
		double n = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);

		t->faulted |= rec.state == IRDM_SAFETY_FAULT;
		t->contact += rec.dev[0].contact_tri != IRDM_TELEM_NO_TRI;
		if (n > t->peak_n)
			t->peak_n = n, t->peak_at = t->n;
		t->f_n[t->n++] = n;
	}
	irdm_log_close(r);
}

static void run_board(const char *board, const char *log)
{
	if (run(env_or("IRDM_FW", "build/irdm-fw"), (const char *const[]){
							    "--board", board, "--image", image, "--user",
							    "scenes/users/press-hold-release.user", "--clock", "virtual", "--log", log, NULL }))
		fail_msg("irdm-fw on %s: %s", board, err_text);
}

/* dir/name: boards/from with the first `find` replaced by `repl`. */
static void edited_board(const char *from, const char *find, const char *repl, const char *name,
			 char *path, size_t len)
{
	static char text[16384];
	size_t flen = strlen(find), rlen = strlen(repl);
	char *at;

	tf_read_text(from, text, sizeof(text));
	at = strstr(text, find);
	assert_non_null(at);
	assert_true(strlen(text) - flen + rlen < sizeof(text));
	memmove(at + rlen, at + flen, strlen(at + flen) + 1);
	memcpy(at, repl, rlen);
	snprintf(path, len, "%s/%s", dir, name);
	tf_write_text(path, text);
}

/* The largest per-tick |F| difference of two runs; where. */
static double worst_diff(const struct trace *a, const struct trace *b, size_t *at)
{
	double worst = 0;

	for (size_t k = 0; k < TICKS; k++)
		if (fabs(a->f_n[k] - b->f_n[k]) > worst)
			worst = fabs(a->f_n[k] - b->f_n[k]), *at = k;
	return worst;
}

static void test_canemu_matches_delayed_sim(void **state)
{
	static struct trace can, sim, sim_rd;
	char board[320], can_log[320], sim_log[320], rd_log[320];
	double worst, worst_rd;
	size_t worst_at = 0, rd_at = 0;

	(void)state;
	snprintf(can_log, sizeof(can_log), "%s/can.log", dir);
	snprintf(sim_log, sizeof(sim_log), "%s/sim.log", dir);
	snprintf(rd_log, sizeof(rd_log), "%s/sim-rd.log", dir);
	run_board("boards/canemu-3dof.board", can_log);
	assert_non_null(strstr(out_text, "hal 'canemu': CAN bus load: SYNC + 3 x RPDO1 (4 B) + 3 x "
					 "TPDO1 (6 B) = 695 bits worst case in 1000 us at 1000000 "
					 "bit/s: 69.5 %"));
	assert_non_null(strstr(out_text, "state: off"));
	edited_board("boards/sim-phantom.board", "write_delay=0", "write_delay=1",
		     "sim-delayed.board", board, sizeof(board));
	run_board(board, sim_log);
	edited_board("boards/sim-phantom.board", "read_delay=0", "read_delay=1", "sim-rd.board",
		     board, sizeof(board));
	run_board(board, rd_log);
	read_trace(can_log, &can);
	read_trace(sim_log, &sim);
	read_trace(rd_log, &sim_rd);
	assert_int_equal(can.n, TICKS);
	assert_int_equal(sim.n, TICKS);
	assert_int_equal(sim_rd.n, TICKS);
	assert_false(can.faulted);
	worst = worst_diff(&can, &sim, &worst_at);
	worst_rd = worst_diff(&can, &sim_rd, &rd_at);
	print_message("canemu: peak %.4f N at %.3f s, %zu contact ticks; sim write_delay=1: peak "
		      "%.4f N at %.3f s, %zu contact ticks; max |dF| %.4f N at %.3f s; against "
		      "write_delay=0 read_delay=1: %.4f N at %.3f s\n",
		      can.peak_n, can.peak_at * 1e-3, can.contact, sim.peak_n, sim.peak_at * 1e-3,
		      sim.contact, worst, worst_at * 1e-3, worst_rd, rd_at * 1e-3);
	/* the run means something: a press of a few tenths of a newton */
	assert_true(sim.peak_n > 0.3 && sim.contact > 1000);
	assert_true(fabs(can.peak_n - sim.peak_n) <= 0.01 * sim.peak_n);
	assert_true(can.peak_at >= sim.peak_at - 20 && can.peak_at <= sim.peak_at + 20);
	assert_true(labs((long)can.contact - (long)sim.contact) <= (long)sim.contact / 50);
	assert_true(worst <= 0.03);
	assert_true(worst_rd <= 0.02);
}

static void test_bad_options_one_line(void **state)
{
	char board[320];
	int rc;

	(void)state;
	edited_board("boards/canemu-3dof.board", "rated_torque_mnm=100", "rated_torque_xxx=100",
		     "bad.board", board, sizeof(board));
	rc = run(env_or("IRDM_FW", "build/irdm-fw"), (const char *const[]){
							     "--board", board, "--image", image, "--clock", "virtual", "--duration", "0.1",
							     "-q", NULL });
	assert_int_not_equal(rc, 0);
	/* one line: the board file and line, the option, the reason */
	assert_true(!strncmp(err_text, "irdm-fw: EINVAL: ", 17));
	assert_non_null(strstr(err_text, "bad.board:22: hal_options: unknown canemu option "
					 "'rated_torque_xxx' (see docs/hal-options.md)\n"));
	assert_ptr_equal(strchr(err_text, '\n'), err_text + strlen(err_text) - 1);
}

/* A drive faulting mid-run: torque off, the run ends in fault, and the
 * reason names the drive in one line (stderr and the summary). */
static void test_fault_reason_one_line(void **state)
{
	char board[320];
	int rc;

	(void)state;
	edited_board("boards/canemu-3dof.board", "substeps=10", "substeps=10 emcy_at=2:500",
		     "emcy.board", board, sizeof(board));
	rc = run(env_or("IRDM_FW", "build/irdm-fw"), (const char *const[]){
							     "--board", board, "--image", image, "--user", "scenes/users/press-hold-release.user",
							     "--clock", "virtual", NULL });
	print_message("exit %d; stderr: %s", rc, err_text);
	assert_int_not_equal(rc, 0);
	assert_non_null(strstr(err_text, "irdm-fw: EFAULT: fault "));
	assert_non_null(strstr(err_text, ": torque off: drive 2 (node 2): EMCY 0x2310 (current), "
					 "error register 0x01\n"));
	assert_non_null(strstr(out_text, "(torque off): drive 2 (node 2): EMCY 0x2310 (current), "
					 "error register 0x01\n"));
}

static int setup(void **state)
{
	(void)state;
	if (tf_tmpdir(dir, sizeof(dir), "fwcan"))
		return -1;
	snprintf(image, sizeof(image), "%s/cuboid.img", dir);
	return run(env_or("IRDM", "build/irdm"), (const char *const[]){
							 "precompute", "-q", "--scene", "scenes/cuboid-paper.scene", "--resolution", "4,4,8",
							 "--representation", "modal:40", "--max_error", "none", "-o", image, NULL }) ?
		       -1 :
		       0;
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_canemu_matches_delayed_sim),
		cmocka_unit_test(test_bad_options_one_line),
		cmocka_unit_test(test_fault_reason_one_line),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
