/* SPDX-License-Identifier: MIT */
/*
 * The board key table (irdm/board.h): one entry per key, its range, unit,
 * help and default.  The parser, the defaults (irdm_board_default()),
 * `irdm-fw --help-board` and the key table in docs/boards.md all come
 * from it; the arm's defaults are irdm/device.h's IRDM_DEVICE_DEFAULT_*,
 * the limits' irdm/controller.h's IRDM_CTRL_DEFAULT_*, expanded here.
 */
#include <stdio.h>
#include <string.h>

#include "board_priv.h"
#include "irdm/board.h"
#include "irdm/controller.h" /* IRDM_CTRL_DEFAULT_*: the limits' defaults */
#include "irdm/deform.h"     /* IRDM_DEFORM_MAX_RATE_HZ */
#include "irdm/error.h"

/* A little over pi, so that any angle in [-pi, pi] is accepted and the range
 * reads short in the docs. */
#define ANGLE_MAX_RAD 3.1416

/* Ranges generous enough for any desktop or arm-sized device, tight enough
 * to catch a value written in the wrong unit (135 for 0.135 m). */
#define LENGTH_MAX_M 1.0
#define PLACE_MAX_M 10.0

/* Commas in s, plus one. */
static unsigned count_items(const char *s)
{
	unsigned n = 1;

	for (; *s; s++)
		n += *s == ',';
	return n;
}

/*
 * n comma-separated values into out (n elements of elem_size bytes), each
 * read as entry o would read one value of type `type` (o's range applies to
 * each).  Nothing is stored unless all n are valid.  An empty why makes the
 * caller say "expected <metavar>".
 */
static int parse_list(const struct irdm_opt *o, void *out, const char *value, unsigned n,
		      enum irdm_opt_type type, size_t elem_size, const char *const *labels,
		      char *why, size_t len)
{
	char buf[IRDM_BOARD_LINE_MAX], item_why[192], *tok = buf;
	unsigned char tmp[3 * sizeof(double)];
	struct irdm_opt e = *o;

	if (strlen(value) >= sizeof(buf) || n * elem_size > sizeof(tmp) ||
	    count_items(value) != n)
		return IRDM_EFORMAT;
	memcpy(buf, value, strlen(value) + 1);
	e.type = type;
	e.size = elem_size;
	for (unsigned i = 0; i < n; i++) {
		char *comma = strchr(tok, ',');
		if (comma)
			*comma = 0;
		e.offset = i * elem_size;
		if (irdm_opt_parse_value(&e, tmp, irdm_opt_trim(tok), item_why, sizeof(item_why))) {
			snprintf(why, len, "%s: %s", labels[i], item_why);
			return IRDM_EFORMAT;
		}
		tok = comma ? comma + 1 : tok;
	}
	memcpy(out, tmp, n * elem_size);
	return IRDM_OK;
}

static const char *const xyz[] = { "x", "y", "z" };
static const char *const joints[] = { "joint 1", "joint 2", "joint 3" };
static const char *const bodies[] = { "upper arm", "forearm", "crank" }; /* irdm/device.h */

static void *field_of(const struct irdm_opt *o, void *obj)
{
	return (char *)obj + o->offset;
}

static int parse_xyz(const struct irdm_opt *o, void *obj, const char *v, char *why, size_t len)
{
	return parse_list(o, field_of(o, obj), v, 3, IRDM_OPT_DOUBLE, sizeof(double), xyz, why,
			  len);
}

static int parse_joint_doubles(const struct irdm_opt *o, void *obj, const char *v, char *why,
			       size_t len)
{
	return parse_list(o, field_of(o, obj), v, IRDM_DEVICE_JOINTS, IRDM_OPT_DOUBLE,
			  sizeof(double), joints, why, len);
}

static int parse_body_doubles(const struct irdm_opt *o, void *obj, const char *v, char *why,
			      size_t len)
{
	return parse_list(o, field_of(o, obj), v, 3, IRDM_OPT_DOUBLE, sizeof(double), bodies,
			  why, len);
}

static int parse_joint_counts(const struct irdm_opt *o, void *obj, const char *v, char *why,
			      size_t len)
{
	return parse_list(o, field_of(o, obj), v, IRDM_DEVICE_JOINTS, IRDM_OPT_INT,
			  sizeof(int32_t), joints, why, len);
}

static const struct irdm_opt_name sign_names[] = {
	{ "+1", 1 },
	{ "1", 1 },
	{ "-1", -1 },
	{ NULL, 0 },
};

/* Each of the three is +1 or -1: read as an enum of those names. */
static int parse_signs(const struct irdm_opt *o, void *obj, const char *v, char *why,
		       size_t len)
{
	struct irdm_opt e = *o;

	e.names = sign_names;
	return parse_list(&e, field_of(o, obj), v, IRDM_DEVICE_JOINTS, IRDM_OPT_ENUM,
			  sizeof(int), joints, why, len);
}

/* "auto", or "K,B" each >= 0 (0,0: rigid). */
static int parse_coupling(const struct irdm_opt *o, void *obj, const char *v, char *why,
			  size_t len)
{
	static const char *const kb[] = { "K", "B" };
	struct irdm_board *b = obj;
	struct irdm_opt e = *o;
	double val[2];
	int ret;

	if (!strcmp(v, "auto")) {
		b->coupling_auto = true;
		return IRDM_OK;
	}
	e.range = IRDM_OPT_GE;
	e.min = 0;
	ret = parse_list(&e, val, v, 2, IRDM_OPT_DOUBLE, sizeof(double), kb, why, len);
	if (ret)
		return ret;
	b->coupling_auto = false;
	b->coupling_k_n_per_m = val[0];
	b->coupling_b_ns_per_m = val[1];
	return IRDM_OK;
}

/* "MU_S,MU_D", each >= 0 and MU_D <= MU_S (0,0: frictionless). */
static int parse_friction(const struct irdm_opt *o, void *obj, const char *v, char *why,
			  size_t len)
{
	static const char *const sd[] = { "MU_S", "MU_D" };
	struct irdm_board *b = obj;
	struct irdm_opt e = *o;
	double val[2];
	int ret;

	e.range = IRDM_OPT_GE | IRDM_OPT_LE;
	e.min = 0;
	e.max = 10;
	ret = parse_list(&e, val, v, 2, IRDM_OPT_DOUBLE, sizeof(double), sd, why, len);
	if (ret)
		return ret;
	if (val[1] > val[0]) {
		snprintf(why, len, "MU_D %g is above MU_S %g: a sliding contact holds less "
				   "than a stuck one",
			 val[1], val[0]);
		return IRDM_EFORMAT;
	}
	memcpy(b->friction_mu, val, sizeof(val));
	return IRDM_OK;
}

#define BF(member) IRDM_OPT_FIELD(struct irdm_board, member)
#define DEV(member) IRDM_OPT_FIELD(struct irdm_board, device.member)
#define RANGE(flags, lo, hi) .range = (flags), .min = (lo), .max = (hi)
#define GT0_LE(hi) RANGE(IRDM_OPT_GT | IRDM_OPT_LE, 0, hi)
#define WITHIN(lim) RANGE(IRDM_OPT_GE | IRDM_OPT_LE, -(lim), lim)
#define XYZ_AS(mv) .type = IRDM_OPT_CUSTOM, .parse = parse_xyz, .metavar = mv
#define XYZ XYZ_AS("X,Y,Z")
#define JOINTS .type = IRDM_OPT_CUSTOM, .parse = parse_joint_doubles, .metavar = "J1,J2,J3"
#define BODIES .type = IRDM_OPT_CUSTOM, .parse = parse_body_doubles, \
	       .metavar = "UPPER_ARM,FOREARM,CRANK"

static const struct irdm_opt board_opts[] = {
	/* the board */
	{ .name = "name", .type = IRDM_OPT_STRING, BF(name), .help = "board name, in logs (required)" },
	{ .name = "hal", .type = IRDM_OPT_STRING, BF(hal), .metavar = "BACKEND", .help = "HAL back-end by its registered name, e.g. sim (required)" },
	{ .name = "hal_options", .type = IRDM_OPT_STRING, BF(hal_options), .metavar = "TEXT", .help = "handed to the back-end as is: key=value words, its keys in "
												      "docs/hal-options.md (irdm-fw --help-board)",
	  .def = "" },
	{ .name = "devices", .type = IRDM_OPT_UNSIGNED, BF(devices), RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 1, IRDM_BOARD_DEVICES_MAX), .help = "arms: 2 for the two-hand pinch, the second at device2_base_offset_m", .def = "1" },

	/* kinematics (irdm/device.h draws the arm) */
	{ .name = "l1_m", .type = IRDM_OPT_DOUBLE, DEV(l1_m), .unit = "m", GT0_LE(LENGTH_MAX_M), .help = "upper arm, shoulder to elbow", IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_L1_M) },
	{ .name = "l2_m", .type = IRDM_OPT_DOUBLE, DEV(l2_m), .unit = "m", GT0_LE(LENGTH_MAX_M), .help = "forearm, elbow to tip", IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_L2_M) },
	{ .name = "base_offset_m", XYZ, DEV(base_offset_m), .unit = "m", WITHIN(LENGTH_MAX_M), .help = "the shoulder in the device frame; the default puts the home-pose tip at "
												       "the origin",
	  IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_BASE_OFFSET_M) },
	{ .name = "device2_base_offset_m", XYZ, BF(device2_base_offset_m), .unit = "m", WITHIN(LENGTH_MAX_M), .help = "the second arm's shoulder; required with devices = 2, refused otherwise" },

	/* encoders, one value per joint */
	{ .name = "counts_per_rev", JOINTS, DEV(counts_per_rev), RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 1, 1e9), .help = "encoder counts per motor turn, after quadrature", IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_COUNTS_PER_REV) },
	{ .name = "gear_ratio", JOINTS, DEV(gear_ratio), RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 0.01, 1000), .help = "motor turns per joint turn (the capstan)", IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_GEAR_RATIO) },
	{ .name = "angle_offset_rad", JOINTS, DEV(angle_offset_rad), .unit = "rad", WITHIN(ANGLE_MAX_RAD), .help = "joint angle at the start of count 0's cell", IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_ANGLE_OFFSET_RAD) },
	{ .name = "encoder_sign", .type = IRDM_OPT_CUSTOM, .parse = parse_signs, DEV(sign), .metavar = "S1,S2,S3", .help = "+1 or -1: count direction against the joint angle "
															   "(device.h: sign)",
	  IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_SIGN) },
	{ .name = "count_min", .type = IRDM_OPT_CUSTOM, .parse = parse_joint_counts, DEV(count_min), .metavar = "C1,C2,C3", .help = "lowest valid count; a count outside [count_min, count_max] faults", IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_COUNT_MIN) },
	{ .name = "count_max", .type = IRDM_OPT_CUSTOM, .parse = parse_joint_counts, DEV(count_max), .metavar = "C1,C2,C3", .help = "highest valid count", IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_COUNT_MAX) },

	/* actuation and mass */
	{ .name = "torque_limit_nm", JOINTS, DEV(torque_limit_nm), .unit = "N m", RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 1e-3, 100), .help = "joint-side torque limit; the tick scales torques to keep the force's "
																       "direction",
	  IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_TORQUE_LIMIT_NM) },
	{ .name = "mass_kg", BODIES, DEV(mass_kg), .unit = "kg", RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 0, 10), .help = "point masses for gravity compensation: upper arm, forearm, drive crank", IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_MASS_KG) },
	{ .name = "com_m", BODIES, DEV(com_m), .unit = "m", WITHIN(LENGTH_MAX_M), .help = "where each mass sits along its link (irdm/device.h)", IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_COM_M) },
	{ .name = "gravity_m_per_s2", .type = IRDM_OPT_DOUBLE, DEV(gravity_m_per_s2), .unit = "m/s^2", RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 0, 20), .help = "gravity along -y; 0 turns gravity compensation off", IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_GRAVITY_M_PER_S2) },

	/* limits */
	{ .name = "max_force_n", .type = IRDM_OPT_DOUBLE, DEV(max_force_n), .unit = "N", RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 0.01, 100), .help = "largest tip force; the engine faults above it", IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_MAX_FORCE_N) },
	{ .name = "max_stiffness_n_per_m", .type = IRDM_OPT_DOUBLE, DEV(k_max_n_per_m), .unit = "N/m", RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 1, 1e6), .help = "stiffest coupling the device renders (device.h: k_max_n_per_m)", IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_K_MAX_N_PER_M) },
	{ .name = "device_damping_ns_per_m", .type = IRDM_OPT_DOUBLE, DEV(b_device_ns_per_m), .unit = "N s/m", RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 1e-3, 1e4), .help = "the device's damping margin, bounds the coupling (Colgate) "
																				    "(device.h: b_device_ns_per_m)",
	  IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_B_DEVICE_NS_PER_M) },
	{ .name = "workspace_min_m", XYZ, BF(workspace_min_m), .unit = "m", WITHIN(LENGTH_MAX_M), .help = "low corner of the box every tip must stay in (required)" },
	{ .name = "workspace_max_m", XYZ, BF(workspace_max_m), .unit = "m", WITHIN(LENGTH_MAX_M), .help = "high corner, > workspace_min_m on every axis (required)" },
	{ .name = "max_tip_speed_m_per_s", .type = IRDM_OPT_DOUBLE, BF(max_tip_speed_m_per_s), .unit = "m/s", RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 1e-3, 10), .help = "a faster tip faults", IRDM_OPT_DEFAULT(IRDM_CTRL_DEFAULT_MAX_TIP_SPEED_M_PER_S) },
	{ .name = "overrun_fault_count", .type = IRDM_OPT_UNSIGNED, BF(overrun_fault_count), RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 1, 1000), .help = "this many overruns in a row fault; one holds the last safe force", IRDM_OPT_DEFAULT(IRDM_CTRL_DEFAULT_OVERRUN_FAULT_COUNT) },
	{ .name = "watchdog_us", .type = IRDM_OPT_UNSIGNED, BF(watchdog_us), .unit = "us", RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 1, 1000000), .help = "one tick longer than this faults; > period_us", IRDM_OPT_DEFAULT(IRDM_CTRL_DEFAULT_WATCHDOG_US) },

	/* the loop */
	{ .name = "period_us", .type = IRDM_OPT_UNSIGNED, BF(period_us), .unit = "us", RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 100, 100000), .help = "force tick period; the image's dt must match", IRDM_OPT_DEFAULT(IRDM_CTRL_DEFAULT_PERIOD_US) },
	{ .name = "force_priority", .type = IRDM_OPT_INT, BF(force_priority), RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 1, 98), .help = "SCHED_FIFO priority of the force thread", .def = "80" },
	{ .name = "cpu", .type = IRDM_OPT_INT, BF(cpu), RANGE(IRDM_OPT_GE | IRDM_OPT_LE, -1, 1023), .help = "the force thread's CPU, -1 for any", .def = "-1" },
	{ .name = "deform_rate_hz", .type = IRDM_OPT_DOUBLE, BF(deform_rate_hz), .unit = "Hz", RANGE(IRDM_OPT_GE | IRDM_OPT_LE, 0, IRDM_DEFORM_MAX_RATE_HZ), .help = "deformed-surface updates, at most the tick rate; 0: off", .def = "0" },
	{ .name = "telemetry", .type = IRDM_OPT_BOOL, BF(telemetry), .help = "per-tick records to the log writer", .def = "yes" },

	/* coupling */
	{ .name = "coupling", .type = IRDM_OPT_CUSTOM, .parse = parse_coupling, .metavar = "auto | K,B", .help = "virtual coupling: auto sizes it from max_stiffness_n_per_m and "
														 "device_damping_ns_per_m (irdm_engine_config_haptic); K N/m, B N s/m with "
														 "K period/2 + B < device_damping_ns_per_m and K <= max_stiffness_n_per_m; "
														 "0,0 is rigid",
	  .def = "auto" },
	{ .name = "friction", .type = IRDM_OPT_CUSTOM, .parse = parse_friction, .metavar = "MU_S,MU_D", .help = "Coulomb friction on the proxy: it sticks while the tangential force is "
														"within MU_S times the normal one and slides on MU_D times it; "
														"0 <= MU_D <= MU_S <= 10; 0,0 is frictionless",
	  .def = "0,0" },

	/* object placement and calibration */
	{ .name = "object_offset_m", XYZ, BF(object_offset_m), .unit = "m", WITHIN(PLACE_MAX_M), .help = "the object frame's origin in the device frame", .def = "0,0,0" },
	{ .name = "object_rotation_deg", XYZ_AS("RX,RY,RZ"), BF(object_rotation_deg), .unit = "deg", WITHIN(360), .help = "object axes into device axes: RX about x, then RY about y, then RZ about z "
															  "(fixed axes)",
	  .def = "0,0,0" },
	{ .name = "calibration_pose_rad", JOINTS, BF(calibration_pose_rad), .unit = "rad", WITHIN(ANGLE_MAX_RAD), .help = "the pose the encoders are zeroed at before torque is enabled; its tip "
															  "must lie in the workspace",
	  .def = "0,0,0" },
};

static const struct irdm_opt_table board_table = {
	.what = "board key",
	.see = "docs/boards.md",
	.opts = board_opts,
	.n_opts = sizeof(board_opts) / sizeof(board_opts[0]),
};

const struct irdm_opt_table *irdm_board_options(void)
{
	return &board_table;
}
