/* SPDX-License-Identifier: MIT */
/*
 * The CAN back-ends' options (irdm/hal_can.h): one option table per
 * back-end, the keys they share written once (CAN_COMMON); parsing,
 * defaults and docs/hal-options.md come from the tables.
 */
#include <stdio.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/hal/hal_can.h"

#define CO(member) IRDM_OPT_FIELD(struct irdm_hal_can_opts, member)
#define UPTO(lo, hi) .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = (lo), .max = (hi)

/* A comma list of 1..IRDM_CAN_AXES_MAX numbers in [lo, hi]; *n of them. */
static int list(const char *v, unsigned lo, unsigned hi, uint32_t out[], unsigned *n)
{
	struct irdm_opt e = { .name = "item", .type = IRDM_OPT_UNSIGNED, .size = sizeof(uint32_t), UPTO(lo, hi) };
	char buf[64], why[64], *tok = buf;

	if (strlen(v) >= sizeof(buf))
		return IRDM_EFORMAT;
	memcpy(buf, v, strlen(v) + 1);
	for (*n = 0; tok; (*n)++) {
		char *comma = strchr(tok, ',');

		if (comma)
			*comma = 0;
		if (*n == IRDM_CAN_AXES_MAX ||
		    irdm_opt_parse_value(&e, &out[*n], tok, why, sizeof(why)))
			return IRDM_EFORMAT;
		tok = comma ? comma + 1 : NULL;
	}
	return IRDM_OK;
}

static int parse_nodes(const struct irdm_opt *o, void *obj, const char *v, char *why,
		       size_t len)
{
	struct irdm_hal_can_opts *c = obj;
	uint32_t vals[IRDM_CAN_AXES_MAX];
	unsigned n;

	(void)o;
	if (list(v, 1, 127, vals, &n)) {
		snprintf(why, len, "expected 1 to 3 node ids 1..127, e.g. 1,2,3");
		return IRDM_EFORMAT;
	}
	c->n_nodes = n;
	for (unsigned k = 0; k < n; k++)
		c->nodes[k] = vals[k];
	return IRDM_OK;
}

/* One value for every axis, or one per axis. */
static int parse_torque(const struct irdm_opt *o, void *obj, const char *v, char *why,
			size_t len)
{
	struct irdm_hal_can_opts *c = obj;
	uint32_t vals[IRDM_CAN_AXES_MAX];
	unsigned n;

	(void)o;
	if (list(v, 1, 1000000, vals, &n) || n == 2) {
		snprintf(why, len, "expected 1..1000000 mN m, once or per axis (3 values)");
		return IRDM_EFORMAT;
	}
	for (unsigned k = 0; k < IRDM_CAN_AXES_MAX; k++)
		c->rated_torque_mnm[k] = vals[n == 1 ? 0 : k];
	return IRDM_OK;
}

/* DRIVE:MS: drive 1..3 raises EMCY 0x2310 and faults at MS ms. */
static int parse_emcy_at(const struct irdm_opt *o, void *obj, const char *v, char *why,
			 size_t len)
{
	struct irdm_hal_can_opts *c = obj;
	struct irdm_opt drive = { .name = "drive", .type = IRDM_OPT_UNSIGNED, CO(emcy_drive), UPTO(1, IRDM_CAN_AXES_MAX) };
	struct irdm_opt at = { .name = "at", .type = IRDM_OPT_UNSIGNED, CO(emcy_at_ms), UPTO(0, 3600000) };
	struct irdm_hal_can_opts tmp = *c;
	char buf[32], *colon, w[64];

	(void)o;
	snprintf(buf, sizeof(buf), "%s", v);
	colon = strchr(buf, ':');
	if (strlen(v) >= sizeof(buf) || !colon)
		goto bad;
	*colon = 0;
	if (irdm_opt_parse_value(&drive, &tmp, buf, w, sizeof(w)) ||
	    irdm_opt_parse_value(&at, &tmp, colon + 1, w, sizeof(w)))
		goto bad;
	c->emcy_drive = tmp.emcy_drive;
	c->emcy_at_ms = tmp.emcy_at_ms;
	return IRDM_OK;
bad:
	snprintf(why, len, "expected DRIVE:MS, drive 1..3, 0..3600000 ms");
	return IRDM_EFORMAT;
}

/* The keys every CAN back-end takes. */
#define CAN_COMMON \
	{ .name = "nodes", .type = IRDM_OPT_CUSTOM, .parse = parse_nodes, .metavar = "N1,N2,N3", .help = "the node id (1..127) of the drive of joint 1, 2, 3; canemu: " \
													 "consecutive (required)" }, \
		{ .name = "rated_torque_mnm", .type = IRDM_OPT_CUSTOM, .parse = parse_torque, .metavar = "T | T1,T2,T3", .help = "each drive's rated motor torque, 1..1000000 mN m, once or per " \
																 "axis, written to 0x6076; the target torque is sent in per mille of it " \
																 "(required)" }, \
		{ .name = "bitrate", .type = IRDM_OPT_UNSIGNED, CO(bitrate), UPTO(10000, 1000000), .unit = "bit/s", .help = "only for the bus-load check (the interface's own rate is set " \
															    "outside, ip link)", \
		  .def = "1000000" }, \
		{ .name = "heartbeat_ms", .type = IRDM_OPT_UNSIGNED, CO(heartbeat_ms), UPTO(1, 65535), .unit = "ms", .help = "the drives' heartbeat producer time, written to 0x1017", .def = "10" }, \
		{ .name = "heartbeat_timeout_ms", .type = IRDM_OPT_UNSIGNED, CO(heartbeat_timeout_ms), UPTO(2, 600000), .unit = "ms", .help = "a drive silent longer is lost; must exceed heartbeat_ms; also " \
																	      "each drive's tolerance for the master's heartbeat (0x1016:01, at most 65535)", \
		  .def = "50" }, \
		{ .name = "tpdo_missing_periods", .type = IRDM_OPT_UNSIGNED, CO(tpdo_missing_periods), UPTO(1, 1000), .help = "this many periods in a row without a TPDO1 lose the drive", .def = "3" }, \
		{ .name = "sync_counter", .type = IRDM_OPT_BOOL, CO(sync_counter), .help = "a counter byte (1..240) in the SYNC; 0x1019 = 240 (else 0) on each " \
											   "drive", \
		  .def = "no" }, \
		{ .name = "sdo_timeout_ms", .type = IRDM_OPT_UNSIGNED, CO(sdo_timeout_ms), UPTO(1, 60000), .unit = "ms", .help = "the wait for each SDO answer at set-up", .def = "100" }, \
		{ .name = "enable_timeout_ms", .type = IRDM_OPT_UNSIGNED, CO(enable_timeout_ms), UPTO(1, 60000), .unit = "ms", .help = "start's wait for the disabled exchange and every drive to be " \
																       "operation enabled", \
		  .def = "100" }, \
		{ .name = "master_node", .type = IRDM_OPT_UNSIGNED, CO(master_node), UPTO(1, 127), .help = "the master's own node id, not a drive's: its heartbeat 0x700 + N, " \
													   "each drive's 0x1016:01", \
		  .def = "127" }, \
	{ \
		.name = "rpdo_timeout_ms", .type = IRDM_OPT_UNSIGNED, CO(rpdo_timeout_ms), \
		UPTO(1, 65535), .unit = "ms", \
		.help = "each drive's RPDO1 deadline, 0x1400:05; not given: 3 periods, " \
			"rounded up to ms" \
	}

static const struct irdm_opt socketcan_opts[] = {
	{ .name = "iface", .type = IRDM_OPT_STRING, CO(iface), .metavar = "NAME", .help = "the SocketCAN interface, e.g. can0 (required)" },
	CAN_COMMON,
};

static const struct irdm_opt canemu_opts[] = {
	CAN_COMMON,
	{ .name = "substeps", .type = IRDM_OPT_UNSIGNED, CO(substeps), UPTO(1, 100), .help = "the emulated arm's integration steps a period", .def = "10" },
	{ .name = "emcy_at", .type = IRDM_OPT_CUSTOM, .parse = parse_emcy_at, .metavar = "D:MS", .help = "an injected fault: drive D (1..3) raises EMCY 0x2310 (current) and faults at "
													 "MS ms (0..3600000) of emulated time; not given: none" },
};

const struct irdm_opt_table irdm_hal_socketcan_options = {
	.what = "socketcan option",
	.see = "docs/hal-options.md",
	.opts = socketcan_opts,
	.n_opts = sizeof(socketcan_opts) / sizeof(socketcan_opts[0]),
};

const struct irdm_opt_table irdm_hal_canemu_options = {
	.what = "canemu option",
	.see = "docs/hal-options.md",
	.opts = canemu_opts,
	.n_opts = sizeof(canemu_opts) / sizeof(canemu_opts[0]),
};

static int missing(char *err, size_t errlen, const char *where, const char *key,
		   const char *why)
{
	snprintf(err, errlen, "%s: %s: %s", where, key, why);
	return IRDM_EINVAL;
}

/* The keys checked against each other, after the last word. */
static int check(const struct irdm_hal_can_opts *o, unsigned extra, const char *where,
		 char *err, size_t errlen)
{
	if ((extra & IRDM_HAL_CAN_IFACE) && !o->iface[0])
		return missing(err, errlen, where, "iface",
			       "missing (the CAN interface, e.g. iface=can0)");
	if (o->n_nodes == 0)
		return missing(err, errlen, where, "nodes",
			       "missing (one node id per joint, e.g. nodes=1,2,3)");
	if (o->rated_torque_mnm[0] == 0)
		return missing(err, errlen, where, "rated_torque_mnm",
			       "missing (the drives' rated torque)");
	if (o->heartbeat_timeout_ms <= o->heartbeat_ms)
		return missing(err, errlen, where, "heartbeat_timeout_ms",
			       "must exceed heartbeat_ms");
	for (unsigned k = 0; k < o->n_nodes; k++)
		if (o->nodes[k] == o->master_node)
			return missing(err, errlen, where, "master_node", "is a drive's node id");
	return IRDM_OK;
}

int irdm_hal_can_parse(const char *options, unsigned extra, const char *where,
		       struct irdm_hal_can_opts *o, char *err, size_t errlen)
{
	const struct irdm_opt_table *t = (extra & IRDM_HAL_CAN_IFACE) ? &irdm_hal_socketcan_options : &irdm_hal_canemu_options;

	memset(o, 0, sizeof(*o));
	if (irdm_opt_set_defaults(t, o, err, errlen) ||
	    irdm_opt_parse_words(t, o, where, options, " \t", err, errlen))
		return IRDM_EINVAL;
	return check(o, extra, where, err, errlen);
}

int irdm_hal_can_check(const char *options, unsigned extra, const char *where, char *err,
		       size_t errlen)
{
	struct irdm_hal_can_opts o;

	return irdm_hal_can_parse(options, extra, where, &o, err, errlen);
}
