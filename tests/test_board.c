/* SPDX-License-Identifier: MIT */
/*
 * Board files (irdm/board.h): the shipped board parses, matches the device
 * and engine defaults, places the cuboid where the arm reaches it, and the
 * sim back-end accepts its options; every key type refuses a bad value with
 * "file:line: key = value: reason"; duplicates, unknown keys, missing keys
 * and keys that disagree are refused on one line naming the line; the
 * placement transform against rotation matrices multiplied out here; the
 * documented defaults and docs/boards.md against the table.
 *
 * References are independent of the code under test: the arm's defaults
 * (irdm_device_config_default), the engine's haptic coupling, rotation
 * matrices built axis by axis and multiplied here, and a Newton solve of
 * the forward kinematics for reachability.  Tolerances: rotations and round
 * trips 1e-15 (a few ulps of unit vectors and 0.3 m offsets; the rotation
 * matches the reference exactly here), Newton residual 1e-12 m (it reaches
 * 1.4e-17 m).  Runs from the repository root (as make test).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "irdm/board.h"
#include "irdm/device.h"
#include "irdm/engine.h"
#include "irdm/error.h"
#include "irdm/hal/hal.h"
#include "irdm/posix/board_file.h"
#include "irdm/sim/hal_sim.h"
#include "irdm/posix/options_doc.h"
#include "support/solve3.h"

#define SHIPPED "boards/sim-phantom.board"
#define DOC "docs/boards.md"

static struct irdm_board board;
static char err[512];

/* The required keys, with the shipped workspace: a valid board on lines 1-4. */
static const char minimal[] =
	"name = t\n"
	"hal = sim\n"
	"workspace_min_m = -0.035,-0.035,-0.040\n"
	"workspace_max_m = 0.035,0.045,0.030\n";

static int parse(const char *text)
{
	err[0] = 0;
	return irdm_board_parse(&board, "t.board", text, err, sizeof(err));
}

/* minimal + lines (from line 5 on) */
static int parse_with(const char *lines)
{
	static char text[4096];

	snprintf(text, sizeof(text), "%s%s", minimal, lines);
	return parse(text);
}

static void expect_ok(const char *lines)
{
	if (parse_with(lines))
		fail_msg("refused:\n%s\n-> %s", lines, err);
}

/* Refused with code and exactly the message want. */
static void expect_refused(const char *lines, int code, const char *want)
{
	int rc = parse_with(lines);

	if (rc != code || strcmp(err, want))
		fail_msg("'%s':\n got %s '%s'\nwant %s '%s'", lines, irdm_errname(rc), err,
			 irdm_errname(code), want);
}

static size_t slurp(const char *path, char *buf, size_t len)
{
	FILE *f = fopen(path, "r");
	size_t n;

	if (!f)
		fail_msg("cannot open %s (run from the repository root)", path);
	n = fread(buf, 1, len - 1, f);
	fclose(f);
	assert_true(n < len - 1);
	buf[n] = 0;
	return n;
}

/* ---- the table ---- */

static void test_table(void **state)
{
	const struct irdm_opt_table *t = irdm_board_options();
	char why[256];

	(void)state;
	if (irdm_opt_table_check(t, why, sizeof(why)))
		fail_msg("board table: %s", why);
	/* duplicates and "required" are tracked for the first 64 entries only */
	assert_true(t->n_opts <= 64);
}

/*
 * Every key has a default in its entry (.def) unless its help says
 * "(required)" (device2_base_offset_m: required with two arms); no help
 * writes a default of its own; each default parses, and parsed into a
 * default board changes nothing: irdm_board_default() is the table's.
 */
static void test_documented_defaults(void **state)
{
	const struct irdm_opt_table *t = irdm_board_options();
	struct irdm_board def, b;
	char why[256];

	(void)state;
	irdm_board_default(&def);
	for (size_t i = 0; i < t->n_opts; i++) {
		const struct irdm_opt *o = &t->opts[i];

		if (strstr(o->help, "(default"))
			fail_msg("%s: the help writes a default; it belongs in .def", o->name);
		if (strstr(o->help, "(required)") || !strcmp(o->name, "device2_base_offset_m")) {
			assert_null(o->def);
			continue;
		}
		if (!o->def)
			fail_msg("%s: no default", o->name);
		memcpy(&b, &def, sizeof(b));
		if (irdm_opt_parse_value(o, &b, o->def, why, sizeof(why)))
			fail_msg("%s: default '%s': %s", o->name, o->def, why);
		if (memcmp(&b, &def, sizeof(b)))
			fail_msg("%s: default '%s' is not irdm_board_default()'s", o->name, o->def);
	}
	/* all at once, as the loader sets them */
	memset(&b, 0, sizeof(b));
	assert_int_equal(irdm_opt_set_defaults(t, &b, why, sizeof(why)), IRDM_OK);
	/* the default arm is irdm_device_config_default()'s */
	struct irdm_device_config dc;
	memset(&dc, 0, sizeof(dc)); /* padding: compared as bytes */
	irdm_device_config_default(&dc);
	assert_memory_equal(&def.device, &dc, sizeof(dc));
	assert_string_equal(def.hal_options, "");
}

/* ---- the shipped board ---- */

static void assert_close3(const double *got, const double *want, double tol, const char *what)
{
	for (int i = 0; i < 3; i++)
		if (!(fabs(got[i] - want[i]) <= tol))
			fail_msg("%s[%d] = %.17g, want %.17g (tol %g)", what, i, got[i], want[i], tol);
}

/* Joint angles whose tip is p: Newton on the forward kinematics from the home
 * pose, the Jacobian inverted by Cramer's rule.  Returns the residual (m). */
static double solve_ik(const struct irdm_device_config *c, const double p[3], double q[3])
{
	double tip[3], r[3], j[9], dq[3];

	q[0] = q[1] = q[2] = 0;
	for (int it = 0; it < 50; it++) {
		irdm_device_fk(c, q, tip);
		for (int i = 0; i < 3; i++)
			r[i] = p[i] - tip[i];
		irdm_device_jacobian(c, q, j);
		ts_solve3(j, r, dq);
		for (int k = 0; k < 3; k++)
			q[k] += dq[k];
	}
	irdm_device_fk(c, q, tip);
	return sqrt((p[0] - tip[0]) * (p[0] - tip[0]) + (p[1] - tip[1]) * (p[1] - tip[1]) +
		    (p[2] - tip[2]) * (p[2] - tip[2]));
}

/* p is reachable: a pose within the encoders' ranges puts the tip there. */
static double worst_residual_m;

static void assert_reachable(const struct irdm_device_config *c, const double p[3],
			     const char *what)
{
	double q[3], res = solve_ik(c, p, q);
	int32_t counts[3];

	worst_residual_m = fmax(worst_residual_m, res);
	if (!(res < 1e-12))
		fail_msg("%s (%g, %g, %g): no pose reaches it (residual %g m)", what, p[0], p[1],
			 p[2], res);
	if (irdm_device_counts_from_angles(c, q, counts))
		fail_msg("%s (%g, %g, %g): pose (%g, %g, %g) is outside the encoders' range",
			 what, p[0], p[1], p[2], q[0], q[1], q[2]);
}

static void test_shipped_board(void **state)
{
	struct irdm_device_config dc;
	struct irdm_engine_config got, want;
	static const double top_obj[3] = { 0.05, 0.05, 0.2 };
	static const double top_want[3] = { 0, -0.01, 0 };
	double top[3], centre[3], back[3], d2 = 0;

	(void)state;
	if (irdm_board_load(&board, SHIPPED, err, sizeof(err)))
		fail_msg("%s", err);
	assert_string_equal(board.name, "sim-phantom");
	assert_string_equal(board.hal, "sim");
	assert_int_equal(board.devices, 1);
	assert_int_equal(board.period_us, 1000);

	/* the arm is the default arm, field by field (bytes: exact) */
	memset(&dc, 0, sizeof(dc));
	irdm_device_config_default(&dc);
	assert_memory_equal(&board.device, &dc, sizeof(dc));

	/* the coupling is the engine's haptic default: 1000 N/m, 7.9 N */
	irdm_board_engine_config(&board, &got);
	irdm_engine_config_haptic(&want, 1e-3, 1000.0, 5.0, 7.9);
	assert_memory_equal(&got, &want, sizeof(want));
	assert_true(got.coupling_k_n_per_m == 1000.0);
	assert_true(fabs(got.coupling_b_ns_per_m - 2.25) < 1e-15);
	assert_true(got.max_force_n == 7.9);

	/* the cuboid's top centre: at (0, -0.01, 0), inside the box, within
	 * 2 cm of its centre, reachable */
	irdm_board_object_to_device(&board, top_obj, top);
	assert_close3(top, top_want, 1e-15, "top centre");
	for (int i = 0; i < 3; i++) {
		centre[i] = 0.5 * (board.workspace_min_m[i] + board.workspace_max_m[i]);
		assert_true(top[i] > board.workspace_min_m[i] && top[i] < board.workspace_max_m[i]);
		d2 += (top[i] - centre[i]) * (top[i] - centre[i]);
	}
	printf("top centre %.3g cm from the workspace centre\n", 100 * sqrt(d2));
	assert_true(sqrt(d2) < 0.02);
	assert_reachable(&board.device, top, "top centre");
	irdm_board_device_to_object(&board, top, back);
	assert_close3(back, top_obj, 1e-15, "top centre back");

	/* the box is the arm's reach less 5 mm on every side: the reach's span by
	 * brute force over the encoders' ranges (41 counts per joint) */
	double lo[3] = { 1, 1, 1 }, hi[3] = { -1, -1, -1 };
	for (int a = 0; a <= 40; a++)
		for (int b = 0; b <= 40; b++)
			for (int d = 0; d <= 40; d++) {
				const int k[3] = { a, b, d };
				int32_t cnt[3];
				double q[3], tip[3];

				for (int i = 0; i < 3; i++)
					cnt[i] = dc.count_min[i] + (int32_t)((int64_t)(dc.count_max[i] -
										       dc.count_min[i]) *
									     k[i] / 40);
				assert_int_equal(irdm_device_angles_from_counts(&dc, cnt, q), IRDM_OK);
				irdm_device_fk(&dc, q, tip);
				for (int i = 0; i < 3; i++) {
					lo[i] = fmin(lo[i], tip[i]);
					hi[i] = fmax(hi[i], tip[i]);
				}
			}
	for (int i = 0; i < 3; i++) {
		printf("axis %d: reach %.4f..%.4f, box %.4f..%.4f m\n", i, lo[i], hi[i],
		       board.workspace_min_m[i], board.workspace_max_m[i]);
		assert_true(fabs(board.workspace_min_m[i] - lo[i] - 0.005) < 0.001);
		assert_true(fabs(hi[i] - board.workspace_max_m[i] - 0.005) < 0.001);
	}
}

/* Every key of the table is written out in the shipped board (device2's
 * commented out: one arm refuses it), each line with a comment or under one. */
static void test_shipped_board_complete(void **state)
{
	const struct irdm_opt_table *t = irdm_board_options();
	static char text[16384];
	char key[96];

	(void)state;
	slurp(SHIPPED, text, sizeof(text));
	for (size_t i = 0; i < t->n_opts; i++) {
		snprintf(key, sizeof(key), "\n%s%s = ",
			 strcmp(t->opts[i].name, "device2_base_offset_m") ? "" : "# ",
			 t->opts[i].name);
		if (!strstr(text, key))
			fail_msg("%s: key '%s' is not written out", SHIPPED, t->opts[i].name);
	}
}

/*
 * Every shipped board: it loads, the sim back-end accepts its arms and
 * hal_options, and every point the shipped user scripts (scenes/users/NAME.user,
 * object frame) send a hand to on its scene lies in the workspace box and in
 * reach of that hand's arm.
 */
struct hand_point {
	unsigned arm; /* 0, 1; LAST_POINT ends a list */
	double p_obj[3];
};

#define LAST_POINT 9
#define MAX_POINTS 16

static const struct {
	const char *path;
	struct hand_point points[MAX_POINTS];
} shipped_boards[] = {
	/* press-hold-release, stroke, tap, pull-and-release on the cuboid scenes */
	{ "boards/sim-phantom.board", { { 0, { 0.05, 0.05, 0.21 } }, { 0, { 0.05, 0.05, 0.19 } }, { 0, { 0.02, 0.05, 0.21 } }, { 0, { 0.02, 0.05, 0.195 } }, { 0, { 0.08, 0.05, 0.195 } }, { 0, { 0.05, 0.05, 0.197 } }, { 0, { 0.05, 0.05, 0.205 } }, { LAST_POINT, { 0 } } } },
	/* swing (the -x face, pushed 2 cm) and swirl (two 2 cm circles on top) */
	{ "boards/sim-phantom-cube.board", { { 0, { -0.01, 0.06, 0.09 } }, { 0, { 0.02, 0.06, 0.09 } }, { 0, { 0.005, 0.06, 0.09 } }, { 0, { 0.06, 0.06, 0.13 } }, { 0, { 0.08, 0.06, 0.115 } }, { 0, { 0.04, 0.06, 0.115 } }, { 0, { 0.06, 0.08, 0.115 } }, { 0, { 0.06, 0.04, 0.115 } }, { LAST_POINT, { 0 } } } },
	/* bunny-press */
	{ "boards/sim-phantom-bunny.board", { { 0, { 0.02, -0.02, 0.14 } }, { 0, { 0.02, -0.02, 0.12 } }, { LAST_POINT, { 0 } } } },
	/* pinch: hand 1 on the face x = 0, hand 2 on x = 0.1, each squeezing 5 mm */
	{ "boards/sim-phantom-pinch.board", { { 0, { -0.01, 0.05, 0.15 } }, { 0, { 0.005, 0.05, 0.15 } }, { 1, { 0.11, 0.05, 0.15 } }, { 1, { 0.095, 0.05, 0.15 } }, { LAST_POINT, { 0 } } } },
};

static void check_board_opens(const struct irdm_board *b, const struct irdm_device_config *dc)
{
	static _Alignas(max_align_t) unsigned char mem[1 << 16];
	struct irdm_hal_config cfg = {
		.device = dc,
		.options = b->hal_options,
		.period_s = b->period_us * 1e-6,
	};
	struct irdm_hal_dev dev;

	assert_int_equal(irdm_hal_register(&irdm_hal_sim_backend), IRDM_OK);
	assert_true(irdm_hal_sim_backend.data_size <= sizeof(mem));
	assert_int_equal(irdm_hal_init(&dev, b->hal, &cfg, mem, sizeof(mem)), IRDM_OK);
	assert_int_equal(irdm_hal_open(&dev), IRDM_OK);
	assert_int_equal(irdm_hal_sim_device(&dev)->p.substeps, 10);
	irdm_hal_close(&dev);
}

static void test_shipped_boards(void **state)
{
	(void)state;
	for (size_t k = 0; k < sizeof(shipped_boards) / sizeof(shipped_boards[0]); k++) {
		const char *path = shipped_boards[k].path;
		struct irdm_device_config arm[IRDM_BOARD_DEVICES_MAX];

		if (irdm_board_load(&board, path, err, sizeof(err)))
			fail_msg("%s", err);
		for (unsigned a = 0; a < board.devices; a++) {
			assert_int_equal(irdm_board_device(&board, a, &arm[a]), IRDM_OK);
			check_board_opens(&board, &arm[a]);
		}
		for (const struct hand_point *h = shipped_boards[k].points; h->arm != LAST_POINT; h++) {
			double p[3];

			assert_true(h->arm < board.devices);
			irdm_board_object_to_device(&board, h->p_obj, p);
			for (int i = 0; i < 3; i++)
				if (!(p[i] > board.workspace_min_m[i] && p[i] < board.workspace_max_m[i]))
					fail_msg("%s: (%g, %g, %g) is at device (%g, %g, %g), outside "
						 "the workspace",
						 path, h->p_obj[0], h->p_obj[1],
						 h->p_obj[2], p[0], p[1], p[2]);
			assert_reachable(&arm[h->arm], p, path);
		}
	}
	printf("largest Newton residual %.2g m\n", worst_residual_m);
}

/* ---- bad values: every key type, file:line and the reason ---- */

static void test_bad_values(void **state)
{
	static const struct {
		const char *line, *want;
	} bad[] = {
		/* double */
		{ "l1_m = 0", "t.board:5: l1_m = 0: must be > 0 m" },
		{ "l1_m = 135", "t.board:5: l1_m = 135: must be <= 1 m" },
		{ "l2_m = long", "t.board:5: l2_m = long: not a number" },
		{ "max_force_n = 7.9 N", "t.board:5: max_force_n = 7.9 N: unexpected 'N' after the number" },
		{ "deform_rate_hz = nan", "t.board:5: deform_rate_hz = nan: not a finite number" },
		/* unsigned */
		{ "period_us = 50", "t.board:5: period_us = 50: must be >= 100 us" },
		{ "period_us = -1000", "t.board:5: period_us = -1000: not a whole number >= 0" },
		{ "devices = 3", "t.board:5: devices = 3: must be <= 2" },
		{ "devices = 0", "t.board:5: devices = 0: must be >= 1" },
		{ "overrun_fault_count = 0", "t.board:5: overrun_fault_count = 0: must be >= 1" },
		/* int */
		{ "force_priority = 99", "t.board:5: force_priority = 99: must be <= 98" },
		{ "cpu = -2", "t.board:5: cpu = -2: must be >= -1" },
		{ "cpu = any", "t.board:5: cpu = any: not a whole number" },
		/* bool */
		{ "telemetry = maybe", "t.board:5: telemetry = maybe: expected yes | no" },
		/* string */
		{ "hal_options = " /* 256 characters: one too many */
		  "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef"
		  "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef"
		  "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef"
		  "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef",
		  NULL },
		/* x,y,z */
		{ "object_offset_m = 0,0", "t.board:5: object_offset_m = 0,0: expected X,Y,Z" },
		{ "object_offset_m = 0,0,0,0", "t.board:5: object_offset_m = 0,0,0,0: expected X,Y,Z" },
		{ "object_offset_m = 0,,0", "t.board:5: object_offset_m = 0,,0: y: not a number" },
		{ "object_offset_m = 0, 0, 11", "t.board:5: object_offset_m = 0, 0, 11: z: must be <= 10 m" },
		{ "object_rotation_deg = 400,0,0",
		  "t.board:5: object_rotation_deg = 400,0,0: x: must be <= 360 deg" },
		/* per joint */
		{ "gear_ratio = 11.6,0,11.6", "t.board:5: gear_ratio = 11.6,0,11.6: joint 2: must be >= 0.01" },
		/* finite and positive is not enough: each within what a device can be */
		{ "gear_ratio = 1e-300,11.6,11.6",
		  "t.board:5: gear_ratio = 1e-300,11.6,11.6: joint 1: must be >= 0.01" },
		{ "counts_per_rev = 1e-300,4000,4000",
		  "t.board:5: counts_per_rev = 1e-300,4000,4000: joint 1: must be >= 1" },
		{ "counts_per_rev = 1e300,4000,4000",
		  "t.board:5: counts_per_rev = 1e300,4000,4000: joint 1: must be <= 1000000000" },
		{ "torque_limit_nm = 1e-300,1.07,1.07",
		  "t.board:5: torque_limit_nm = 1e-300,1.07,1.07: joint 1: must be >= 0.001 N m" },
		{ "device_damping_ns_per_m = 1e-300",
		  "t.board:5: device_damping_ns_per_m = 1e-300: must be >= 0.001 N s/m" },
		{ "max_stiffness_n_per_m = 1e-300",
		  "t.board:5: max_stiffness_n_per_m = 1e-300: must be >= 1 N/m" },
		{ "max_tip_speed_m_per_s = 1e-300",
		  "t.board:5: max_tip_speed_m_per_s = 1e-300: must be >= 0.001 m/s" },
		{ "max_force_n = 1e-300", "t.board:5: max_force_n = 1e-300: must be >= 0.01 N" },
		{ "torque_limit_nm = 1.07,1.07,200",
		  "t.board:5: torque_limit_nm = 1.07,1.07,200: joint 3: must be <= 100 N m" },
		{ "calibration_pose_rad = 0,0,4",
		  "t.board:5: calibration_pose_rad = 0,0,4: joint 3: must be <= 3.1416 rad" },
		{ "count_min = -3102,-2954.5,-3324",
		  "t.board:5: count_min = -3102,-2954.5,-3324: joint 2: unexpected '.5' after the number" },
		{ "count_max = 1,2,3000000000",
		  "t.board:5: count_max = 1,2,3000000000: joint 3: must be between -2147483648 and 2147483647" },
		{ "encoder_sign = 1,0,-1", "t.board:5: encoder_sign = 1,0,-1: joint 2: expected +1 | 1 | -1" },
		/* per body */
		{ "mass_kg = 0.06,-0.1,0.09", "t.board:5: mass_kg = 0.06,-0.1,0.09: forearm: must be >= 0 kg" },
		/* coupling */
		{ "coupling = stiff", "t.board:5: coupling = stiff: expected auto | K,B" },
		{ "coupling = -1,0", "t.board:5: coupling = -1,0: K: must be >= 0" },
		{ "coupling = 100", "t.board:5: coupling = 100: expected auto | K,B" },
		/* friction */
		{ "friction = 0.5", "t.board:5: friction = 0.5: expected MU_S,MU_D" },
		{ "friction = -0.1,0", "t.board:5: friction = -0.1,0: MU_S: must be >= 0" },
		{ "friction = 0.4,0.5",
		  "t.board:5: friction = 0.4,0.5: MU_D 0.5 is above MU_S 0.4: a sliding contact "
		  "holds less than a stuck one" },
		/* lines */
		{ "l1_m 0.135", "t.board:5: expected 'key = value'" },
	};
	char line[512];

	(void)state;
	for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
		snprintf(line, sizeof(line), "%s\n", bad[i].line);
		if (bad[i].want) {
			expect_refused(line, IRDM_EFORMAT, bad[i].want);
			continue;
		}
		assert_int_equal(parse_with(line), IRDM_EFORMAT);
		assert_non_null(strstr(err, "t.board:5: hal_options = "));
		assert_non_null(strstr(err, ": longer than 255 characters"));
	}
}

/* Values that sit just inside the ranges are taken, with what was written. */
static void test_good_values(void **state)
{
	(void)state;
	expect_ok("encoder_sign = -1, +1 ,1\ncount_min = -5,-6,-7\ncount_max = 5,6,7\n"
		  "telemetry = no\ncpu = 1\nforce_priority = 98\nhal_options = read_delay=2\n"
		  "calibration_pose_rad = 0,0,0.0001\n");
	assert_int_equal(board.device.sign[0], -1);
	assert_int_equal(board.device.sign[1], 1);
	assert_int_equal(board.device.sign[2], 1);
	assert_int_equal(board.device.count_min[2], -7);
	assert_int_equal(board.device.count_max[1], 6);
	assert_false(board.telemetry);
	assert_int_equal(board.cpu, 1);
	assert_int_equal(board.force_priority, 98);
	assert_string_equal(board.hal_options, "read_delay=2");
	assert_true(board.calibration_pose_rad[2] == 0.0001);
	/* a coupling the device keeps passive: 1000 * 1e-3 / 2 + 4.4 = 4.9 < 5 */
	expect_ok("coupling = 1000,4.4\n");
	assert_false(board.coupling_auto);
	assert_true(board.coupling_k_n_per_m == 1000 && board.coupling_b_ns_per_m == 4.4);
	expect_ok("coupling = 0,0\n"); /* rigid */
	assert_true(board.coupling_k_n_per_m == 0 && board.coupling_b_ns_per_m == 0);
	expect_ok("coupling = auto\n");
	assert_true(board.coupling_auto);
	/* no newline at the end, CR LF line ends */
	assert_int_equal(parse("name = t\r\nhal = sim\r\nworkspace_min_m = -1,-1,-1\r\n"
			       "workspace_max_m = 1,1,1"),
			 IRDM_OK);
	assert_true(board.workspace_max_m[2] == 1);
}

/* ---- the board as a whole ---- */

static void test_refused_boards(void **state)
{
	(void)state;
	/* a key twice */
	expect_refused("l1_m = 0.1\nhal = sim\n", IRDM_EFORMAT, "t.board:6: hal is already set on line 2");
	/* unknown */
	expect_refused("# fine\ntorque_limit = 1\n", IRDM_EINVAL,
		       "t.board:6: unknown board key 'torque_limit' (see docs/boards.md)");
	/* required keys */
	assert_int_equal(parse("name = t\nworkspace_min_m = -1,-1,-1\nworkspace_max_m = 1,1,1\n"),
			 IRDM_EMISSING);
	assert_string_equal(err, "t.board: missing required key 'hal' (see docs/boards.md)");
	assert_int_equal(parse("hal = sim\nname = t\nworkspace_min_m = -1,-1,-1\n"), IRDM_EMISSING);
	assert_string_equal(err, "t.board: missing required key 'workspace_max_m' (see docs/boards.md)");
	assert_int_equal(parse(""), IRDM_EMISSING);
	assert_string_equal(err, "t.board: missing required key 'name' (see docs/boards.md)");
	assert_int_equal(parse("name =\nhal = sim\nworkspace_min_m = -1,-1,-1\n"
			       "workspace_max_m = 1,1,1\n"),
			 IRDM_EINVAL);
	assert_string_equal(err, "t.board:1: name: must not be empty");
	/* workspace: min == max on one axis is refused as min > max is */
	assert_int_equal(parse("name = t\nhal = sim\nworkspace_max_m = 0.1,0.05,0.1\n"
			       "workspace_min_m = -0.1,0.05,-0.1\n"),
			 IRDM_EINVAL);
	assert_string_equal(err, "t.board:4: workspace_min_m: must be < workspace_max_m (line 3) "
				 "on every axis; y: 0.05 >= 0.05");
	assert_int_equal(parse("name = t\nhal = sim\nworkspace_max_m = 0.1,0.1,-0.2\n"
			       "workspace_min_m = -0.1,-0.1,-0.1\n"),
			 IRDM_EINVAL);
	assert_non_null(strstr(err, "; z: -0.1 >= -0.2"));
	/* devices */
	expect_refused("devices = 2\n", IRDM_EINVAL,
		       "t.board:5: devices = 2: needs device2_base_offset_m");
	expect_refused("device2_base_offset_m = 0.01,0.135,-0.135\n", IRDM_EINVAL,
		       "t.board:5: device2_base_offset_m: only with devices = 2");
	/* encoders */
	expect_refused("count_max = 10,10,10\ncount_min = 0,11,0\n", IRDM_EINVAL,
		       "t.board:6: count_min: must be < count_max (line 5) on every joint; joint 2: 11 >= 10");
	expect_refused("count_max = 0,0,0\ncount_min = 0,0,0\n", IRDM_EINVAL,
		       "t.board:6: count_min: must be < count_max (line 5) on every joint; joint 1: 0 >= 0");
	/* loop */
	expect_refused("watchdog_us = 1000\n", IRDM_EINVAL,
		       "t.board:5: watchdog_us = 1000: must be > period_us = 1000 (default)");
	expect_refused("period_us = 10000\n", IRDM_EINVAL,
		       "t.board: default watchdog_us = 5000: must be > period_us = 10000 (line 5)");
	expect_refused("deform_rate_hz = 2000\n", IRDM_EINVAL,
		       "t.board:5: deform_rate_hz = 2000: must be <= the tick rate, 1000 Hz "
		       "(period_us, default)");
	expect_ok("deform_rate_hz = 1000\n");
	/* coupling */
	expect_refused("coupling = 2000,0\n", IRDM_EINVAL,
		       "t.board:5: coupling = 2000,0: K must be <= max_stiffness_n_per_m = 1000 N/m");
	expect_refused("coupling = 1000,4.6\n", IRDM_EINVAL,
		       "t.board:5: coupling = 1000,4.6: not passive: K period/2 + B = 5.1 N s/m, "
		       "must be < device_damping_ns_per_m = 5");
	/* calibration: inside the counts, the tip inside the box */
	expect_refused("calibration_pose_rad = 0,0.5,0\n", IRDM_EINVAL,
		       "t.board:5: calibration_pose_rad: outside the encoders' [count_min, count_max]");
	expect_refused("calibration_pose_rad = 0,0.39,0\n", IRDM_EINVAL,
		       "t.board:5: calibration_pose_rad: arm 1's tip is outside the workspace; "
		       "y = 0.0513254 m");
	expect_refused("devices = 2\ndevice2_base_offset_m = 0.04,0.135,-0.135\n", IRDM_EINVAL,
		       "t.board: default calibration_pose_rad: arm 2's tip is outside the workspace; "
		       "x = 0.04 m");
}

/* A line longer than IRDM_BOARD_LINE_MAX - 1, from memory and from a file. */
static void test_long_line(void **state)
{
	static char text[2048];
	char path[] = "/tmp/test_board_XXXXXX";
	size_t at = (size_t)snprintf(text, sizeof(text), "%s# ", minimal);
	int fd;
	FILE *f;

	(void)state;
	memset(text + at, 'x', IRDM_BOARD_LINE_MAX - 3); /* 511 characters: fits */
	text[at + IRDM_BOARD_LINE_MAX - 3] = '\n';
	assert_int_equal(parse(text), IRDM_OK);
	text[at + IRDM_BOARD_LINE_MAX - 3] = 'x'; /* 512: one too many */
	assert_int_equal(parse(text), IRDM_EFORMAT);
	assert_string_equal(err, "t.board:5: line longer than 511 characters");

	fd = mkstemp(path);
	assert_true(fd >= 0);
	f = fdopen(fd, "w");
	assert_non_null(f);
	fputs(text, f);
	fclose(f);
	assert_int_equal(irdm_board_load(&board, path, err, sizeof(err)), IRDM_EFORMAT);
	assert_non_null(strstr(err, ":5: line longer than 511 characters"));
	unlink(path);

	assert_int_equal(irdm_board_load(&board, "/nonexistent/x.board", err, sizeof(err)),
			 IRDM_EIO);
	assert_string_equal(err, "/nonexistent/x.board: cannot open: No such file or directory");
}

/* irdm_board_load and irdm_board_parse read the same board. */
static void test_load_is_parse(void **state)
{
	static char text[16384];
	struct irdm_board from_file;

	(void)state;
	slurp(SHIPPED, text, sizeof(text));
	assert_int_equal(irdm_board_load(&from_file, SHIPPED, err, sizeof(err)), IRDM_OK);
	assert_int_equal(irdm_board_parse(&board, SHIPPED, text, err, sizeof(err)), IRDM_OK);
	assert_memory_equal(&board, &from_file, sizeof(board));
}

static void test_two_devices(void **state)
{
	struct irdm_device_config d0, d1;

	(void)state;
	memset(&d0, 0, sizeof(d0));
	memset(&d1, 0, sizeof(d1));
	expect_ok("devices = 2\ndevice2_base_offset_m = 0.01,0.13,-0.14\n");
	assert_int_equal(irdm_board_device(&board, 0, &d0), IRDM_OK);
	assert_int_equal(irdm_board_device(&board, 1, &d1), IRDM_OK);
	assert_int_equal(irdm_board_device(&board, 2, &d1), IRDM_EINVAL);
	assert_true(d0.base_offset_m[0] == 0 && d0.base_offset_m[1] == 0.135);
	assert_true(d1.base_offset_m[0] == 0.01 && d1.base_offset_m[1] == 0.13 &&
		    d1.base_offset_m[2] == -0.14);
	/* everything else is the same arm */
	memcpy(d1.base_offset_m, d0.base_offset_m, sizeof(d0.base_offset_m));
	assert_memory_equal(&d0, &d1, sizeof(d0));

	expect_ok("");
	assert_int_equal(irdm_board_device(&board, 1, &d1), IRDM_EINVAL);
}

static void test_engine_config(void **state)
{
	struct irdm_engine_config got, want;

	(void)state;
	expect_ok("coupling = 500,1\nperiod_us = 500\nwatchdog_us = 2000\nmax_force_n = 5\n");
	irdm_board_engine_config(&board, &got);
	irdm_engine_config_haptic(&want, 500e-6, 1000.0, 5.0, 5.0);
	want.coupling_k_n_per_m = 500;
	want.coupling_b_ns_per_m = 1;
	assert_memory_equal(&got, &want, sizeof(want));
}

/* ---- placement ---- */

static void matmul(const double a[9], const double b[9], double c[9])
{
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
			c[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
}

/* Rz(z) Ry(y) Rx(x), each axis rotation written out and multiplied here. */
static void reference_rotation(const double deg[3], double r[9])
{
	double a = deg[0] * M_PI / 180, b = deg[1] * M_PI / 180, c = deg[2] * M_PI / 180;
	const double rx[9] = { 1, 0, 0, 0, cos(a), -sin(a), 0, sin(a), cos(a) };
	const double ry[9] = { cos(b), 0, sin(b), 0, 1, 0, -sin(b), 0, cos(b) };
	const double rz[9] = { cos(c), -sin(c), 0, sin(c), cos(c), 0, 0, 0, 1 };
	double t[9];

	matmul(ry, rx, t);
	matmul(rz, t, r);
}

static void place(const char *offset, const char *rotation)
{
	char lines[256];

	snprintf(lines, sizeof(lines), "object_offset_m = %s\nobject_rotation_deg = %s\n", offset,
		 rotation);
	expect_ok(lines);
}

static void test_placement_axes(void **state)
{
	static const double ex[3] = { 1, 0, 0 }, ey[3] = { 0, 1, 0 }, ez[3] = { 0, 0, 1 };
	double v[3];

	(void)state;
	/* 90 deg about z maps x to y (and y to -x) */
	place("0,0,0", "0,0,90");
	irdm_board_vector_to_device(&board, ex, v);
	assert_close3(v, ey, 1e-15, "Rz(90) x");
	irdm_board_vector_to_device(&board, ey, v);
	assert_close3(v, (double[3]){ -1, 0, 0 }, 1e-15, "Rz(90) y");
	irdm_board_vector_to_object(&board, ey, v);
	assert_close3(v, ex, 1e-15, "Rz(90)^T y");

	/* the order: x first, then z.  Rx(90): y -> z, z -> -y; then Rz(90):
	 * x -> y, y -> -x.  So x -> y, y -> z, z -> x (Rx after Rz would give x -> z) */
	place("0,0,0", "90,0,90");
	irdm_board_vector_to_device(&board, ex, v);
	assert_close3(v, ey, 1e-15, "x");
	irdm_board_vector_to_device(&board, ey, v);
	assert_close3(v, ez, 1e-15, "y");
	irdm_board_vector_to_device(&board, ez, v);
	assert_close3(v, ex, 1e-15, "z");

	/* the offset moves points, not vectors */
	place("0.1,-0.2,0.3", "0,0,90");
	irdm_board_object_to_device(&board, ex, v);
	assert_close3(v, (double[3]){ 0.1, 0.8, 0.3 }, 1e-15, "point x");
	irdm_board_device_to_object(&board, (double[3]){ 0.1, -0.2, 0.3 }, v);
	assert_close3(v, (double[3]){ 0, 0, 0 }, 1e-15, "origin");
}

static void test_placement_general(void **state)
{
	static const double deg[3] = { 30, -50, 120 };
	static const double p[3] = { 0.07, -0.02, 0.15 }, t[3] = { -0.05, -0.21, 0.05 };
	double r[9], want[3], got[3], back[3], rtr[9], rt[9], worst = 0;

	(void)state;
	place("-0.05,-0.21,0.05", "30,-50,120");
	reference_rotation(deg, r);
	for (int i = 0; i < 9; i++)
		worst = fmax(worst, fabs(board.object_rotation[i] - r[i]));
	printf("rotation vs reference: %.2g\n", worst);
	assert_true(worst < 1e-15);

	/* orthonormal: R^T R = I */
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
			rt[3 * i + j] = board.object_rotation[3 * j + i];
	matmul(rt, board.object_rotation, rtr);
	for (int i = 0; i < 9; i++)
		assert_true(fabs(rtr[i] - (i % 4 == 0)) < 1e-15);

	/* a point, by the reference, and back (also in place) */
	for (int i = 0; i < 3; i++)
		want[i] = t[i] + r[3 * i] * p[0] + r[3 * i + 1] * p[1] + r[3 * i + 2] * p[2];
	irdm_board_object_to_device(&board, p, got);
	assert_close3(got, want, 1e-15, "point");
	irdm_board_device_to_object(&board, got, back);
	assert_close3(back, p, 1e-15, "round trip");
	irdm_board_object_to_device(&board, back, back);
	assert_close3(back, want, 1e-15, "in place");
	irdm_board_vector_to_object(&board, p, got);
	irdm_board_vector_to_device(&board, got, got);
	assert_close3(got, p, 1e-15, "vector round trip");
}

/* ---- docs/boards.md ---- */

static void test_docs_current(void **state)
{
	static const char begin[] = "<!-- begin board keys -->\n";
	static const char end[] = "<!-- end board keys -->\n";
	static char doc[65536];
	char *table = NULL, *a, *b;
	size_t len = 0;
	FILE *f;

	(void)state;
	slurp(DOC, doc, sizeof(doc));
	a = strstr(doc, begin);
	b = a ? strstr(a, end) : NULL;
	if (!a || !b)
		fail_msg("%s: no '%s' ... '%s' block", DOC, "<!-- begin board keys -->",
			 "<!-- end board keys -->");
	a += strlen(begin);
	*b = 0;
	f = open_memstream(&table, &len);
	assert_non_null(f);
	irdm_opt_print_markdown(f, irdm_board_options());
	fclose(f);
	if (strcmp(a, table))
		fail_msg("%s is not what irdm_opt_print_markdown() writes from the board table: "
			 "regenerate the block between the markers",
			 DOC);
	free(table);
}

/* The messages docs/boards.md shows are the parser's. */
static void test_doc_examples(void **state)
{
	static const char *const lines[] = {
		"torque_limit_nm = 1.07,0,1.07\n",
		"name = x\n",
		"torque_limit = 1\n",
		NULL,
	};
	static char doc[65536], text[1024], msg[4][160];
	struct irdm_board b;

	(void)state;
	slurp(DOC, doc, sizeof(doc));
	for (int i = 0; i < 3; i++) {
		/* the bad line at line 12 (the duplicate's first at line 1: "name") */
		snprintf(text, sizeof(text), "%s%s%s", minimal, "#\n#\n#\n#\n#\n#\n#\n", lines[i]);
		assert_int_not_equal(irdm_board_parse(&b, "boards/x.board", text, msg[i],
						      sizeof(msg[i])),
				     IRDM_OK);
	}
	assert_int_equal(irdm_board_parse(&b, "boards/x.board", "name = x\n", msg[3],
					  sizeof(msg[3])),
			 IRDM_EMISSING);
	for (int i = 0; i < 4; i++)
		if (!strstr(doc, msg[i]))
			fail_msg("%s does not show the parser's message '%s'", DOC, msg[i]);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_table),
		cmocka_unit_test(test_documented_defaults),
		cmocka_unit_test(test_shipped_board),
		cmocka_unit_test(test_shipped_board_complete),
		cmocka_unit_test(test_shipped_boards),
		cmocka_unit_test(test_bad_values),
		cmocka_unit_test(test_good_values),
		cmocka_unit_test(test_refused_boards),
		cmocka_unit_test(test_long_line),
		cmocka_unit_test(test_load_is_parse),
		cmocka_unit_test(test_two_devices),
		cmocka_unit_test(test_engine_config),
		cmocka_unit_test(test_placement_axes),
		cmocka_unit_test(test_placement_general),
		cmocka_unit_test(test_docs_current),
		cmocka_unit_test(test_doc_examples),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
