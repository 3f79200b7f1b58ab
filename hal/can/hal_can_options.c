/* SPDX-License-Identifier: MIT */
/* The CAN back-ends' options (irdm/hal_can.h, docs/canopen.md). */
#include <stdio.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/hal/hal_can.h"

static void defaults(struct irdm_hal_can_opts *o)
{
	memset(o, 0, sizeof(*o));
	o->bitrate = 1000000;
	o->heartbeat_ms = 10;
	o->heartbeat_timeout_ms = 50;
	o->tpdo_missing_periods = 3;
	o->sync_counter = false;
	o->sdo_timeout_ms = 100;
	o->enable_timeout_ms = 100;
	o->substeps = 10;
	o->master_node = 127;
	o->rpdo_timeout_ms = 0;         /* 0: three periods, rounded up to ms */
}

static int bad(char *err, size_t errlen, const char *key, const char *why)
{
	snprintf(err, errlen, "hal_options %s: %s", key, why);
	return IRDM_EINVAL;
}

/* A decimal unsigned in [min, max] from s (len bytes). */
static int number(const char *s, size_t len, uint32_t min, uint32_t max, uint32_t *out)
{
	uint64_t v = 0;

	if (len == 0 || len > 10)
		return IRDM_EINVAL;
	for (size_t i = 0; i < len; i++) {
		if (s[i] < '0' || s[i] > '9')
			return IRDM_EINVAL;
		v = v * 10 + (uint64_t)(s[i] - '0');
	}
	if (v < min || v > max)
		return IRDM_EINVAL;
	*out = (uint32_t)v;
	return IRDM_OK;
}

/* A comma list of 1..3 numbers in [min, max]; *n of them. */
static int list(const char *s, size_t len, uint32_t min, uint32_t max, uint32_t out[],
		unsigned *n)
{
	*n = 0;
	while (len) {
		size_t item = 0;

		while (item < len && s[item] != ',')
			item++;
		if (*n == IRDM_CAN_AXES_MAX || number(s, item, min, max, &out[*n]) != IRDM_OK)
			return IRDM_EINVAL;
		(*n)++;
		if (item == len)
			break;
		s += item + 1;
		len -= item + 1;
		if (!len)
			return IRDM_EINVAL;     /* a trailing comma */
	}
	return *n ? IRDM_OK : IRDM_EINVAL;
}

struct scalar {
	const char *key;
	uint32_t min, max;
	const char *range;
};

static const struct scalar scalars[] = {
	{ "bitrate", 10000, 1000000, "10000..1000000 bit/s" },
	{ "heartbeat_ms", 1, 65535, "1..65535 ms" },
	{ "heartbeat_timeout_ms", 2, 600000, "2..600000 ms" },
	{ "tpdo_missing_periods", 1, 1000, "1..1000 periods" },
	{ "sdo_timeout_ms", 1, 60000, "1..60000 ms" },
	{ "enable_timeout_ms", 1, 60000, "1..60000 ms" },
	{ "substeps", 1, 100, "1..100" },
	{ "master_node", 1, 127, "1..127" },
	{ "rpdo_timeout_ms", 1, 65535, "1..65535 ms" },
};

static void store_scalar(struct irdm_hal_can_opts *o, size_t i, uint32_t v)
{
	switch (i) {
	case 0: o->bitrate = v; break;
	case 1: o->heartbeat_ms = (uint16_t)v; break;
	case 2: o->heartbeat_timeout_ms = v; break;
	case 3: o->tpdo_missing_periods = v; break;
	case 4: o->sdo_timeout_ms = v; break;
	case 5: o->enable_timeout_ms = v; break;
	case 6: o->substeps = v; break;
	case 7: o->master_node = v; break;
	default: o->rpdo_timeout_ms = v; break;
	}
}

static int list_option(const char *key, const char *v, size_t vlen, struct irdm_hal_can_opts *o,
		       char *err, size_t errlen)
{
	uint32_t vals[IRDM_CAN_AXES_MAX];
	unsigned n;

	if (!strcmp(key, "nodes")) {
		if (list(v, vlen, 1, 127, vals, &n))
			return bad(err, errlen, key, "expected 1 to 3 node ids 1..127, e.g. 1,2,3");
		o->n_nodes = n;
		for (unsigned k = 0; k < n; k++)
			o->nodes[k] = vals[k];
		return IRDM_OK;
	}
	/* rated_torque_mnm: one value for every axis, or one per axis */
	if (list(v, vlen, 1, 1000000, vals, &n) || n == 2)
		return bad(err, errlen, key, "expected 1..1000000 mN m, once or per axis (3 values)");
	for (unsigned k = 0; k < IRDM_CAN_AXES_MAX; k++)
		o->rated_torque_mnm[k] = vals[n == 1 ? 0 : k];
	return IRDM_OK;
}

/* emcy_at=DRIVE:MS: drive 1..3 raises EMCY 0x2310 and faults at MS ms. */
static int emcy_at(const char *v, size_t vlen, struct irdm_hal_can_opts *o, char *err,
		   size_t errlen)
{
	const char *colon = memchr(v, ':', vlen);
	uint32_t drive;

	if (!colon || number(v, (size_t)(colon - v), 1, IRDM_CAN_AXES_MAX, &drive) ||
	    number(colon + 1, vlen - (size_t)(colon - v) - 1, 0, 3600000, &o->emcy_at_ms))
		return bad(err, errlen, "emcy_at", "expected DRIVE:MS, drive 1..3, 0..3600000 ms");
	o->emcy_drive = drive;
	return IRDM_OK;
}

static int option(const char *tok, size_t len, unsigned extra, struct irdm_hal_can_opts *o,
		  char *err, size_t errlen)
{
	const char *eq = memchr(tok, '=', len);
	char key[32];
	size_t klen = eq ? (size_t)(eq - tok) : len, vlen = eq ? len - klen - 1 : 0;

	snprintf(key, sizeof(key), "%.*s", (int)(klen < 31 ? klen : 31), tok);
	if (!eq)
		return bad(err, errlen, key, "expected key=value");
	if (!strcmp(key, "iface") && (extra & IRDM_HAL_CAN_IFACE)) {
		if (vlen == 0 || vlen >= IRDM_HAL_CAN_IFNAME_MAX)
			return bad(err, errlen, key, "an interface name of 1..15 characters");
		snprintf(o->iface, sizeof(o->iface), "%.*s", (int)vlen, eq + 1);
		return IRDM_OK;
	}
	if (!strcmp(key, "emcy_at") && (extra & IRDM_HAL_CAN_EMCY_AT))
		return emcy_at(eq + 1, vlen, o, err, errlen);
	if (!strcmp(key, "sync_counter")) {
		if (vlen == 3 && !strncmp(eq + 1, "yes", 3))
			o->sync_counter = true;
		else if (vlen == 2 && !strncmp(eq + 1, "no", 2))
			o->sync_counter = false;
		else
			return bad(err, errlen, key, "expected yes or no");
		return IRDM_OK;
	}
	if (!strcmp(key, "nodes") || !strcmp(key, "rated_torque_mnm"))
		return list_option(key, eq + 1, vlen, o, err, errlen);
	for (size_t i = 0; i < sizeof(scalars) / sizeof(scalars[0]); i++) {
		uint32_t v;

		if (strcmp(key, scalars[i].key) ||
		    (!strcmp(key, "substeps") && !(extra & IRDM_HAL_CAN_SUBSTEPS)))
			continue;
		if (number(eq + 1, vlen, scalars[i].min, scalars[i].max, &v))
			return bad(err, errlen, key, scalars[i].range);
		store_scalar(o, i, v);
		return IRDM_OK;
	}
	return bad(err, errlen, key, "unknown option for this back-end");
}

int irdm_hal_can_parse(const char *options, unsigned extra, struct irdm_hal_can_opts *o,
		       char *err, size_t errlen)
{
	const char *s = options ? options : "";

	defaults(o);
	s += strspn(s, " \t");
	while (*s) {
		size_t len = strcspn(s, " \t");
		int rc = option(s, len, extra, o, err, errlen);

		if (rc)
			return rc;
		s += len;
		s += strspn(s, " \t");
	}
	if ((extra & IRDM_HAL_CAN_IFACE) && !o->iface[0])
		return bad(err, errlen, "iface", "missing (the CAN interface, e.g. iface=can0)");
	if (o->n_nodes == 0)
		return bad(err, errlen, "nodes", "missing (one node id per joint, e.g. nodes=1,2,3)");
	if (o->rated_torque_mnm[0] == 0)
		return bad(err, errlen, "rated_torque_mnm", "missing (the drives' rated torque)");
	if (o->heartbeat_timeout_ms <= o->heartbeat_ms)
		return bad(err, errlen, "heartbeat_timeout_ms", "must exceed heartbeat_ms");
	for (unsigned k = 0; k < o->n_nodes; k++)
		if (o->nodes[k] == o->master_node)
			return bad(err, errlen, "master_node", "is a drive's node id");
	return IRDM_OK;
}
