/* SPDX-License-Identifier: MIT */
/* Injected CAN faults, parsed (irdm/can_faults.h). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/sim/can_faults.h"
#include "irdm/hal/canopen.h"
#include "irdm/error.h"

#define FIELDS_MAX 5

static const struct {
	const char *name;
	enum irdm_can_fault_kind kind;
	unsigned fields; /* numbers after the name */
	const char *usage;
} kinds[] = {
	{ "drop", IRDM_CAN_FAULT_DROP, 3, "drop:NODE:SYNC:K" },
	{ "delay", IRDM_CAN_FAULT_DELAY, 4, "delay:NODE:SYNC:K:US" },
	{ "heartbeat-stop", IRDM_CAN_FAULT_HEARTBEAT_STOP, 2, "heartbeat-stop:NODE:SYNC" },
	{ "emcy", IRDM_CAN_FAULT_EMCY, 3, "emcy:NODE:SYNC:CODE" },
	{ "fault", IRDM_CAN_FAULT_STATE, 2, "fault:NODE:SYNC" },
	{ "sdo-wrong", IRDM_CAN_FAULT_SDO_WRONG, 1, "sdo-wrong:NODE" },
	{ "flood", IRDM_CAN_FAULT_FLOOD, 2, "flood:SYNC:COUNT" },
};

/* One unsigned field (decimal or 0x hex) of at most max. */
static int field(const char *s, size_t len, unsigned long long max, unsigned long long *v)
{
	char buf[24], *end;

	if (len == 0 || len >= sizeof(buf) || s[0] == '-' || s[0] == '+')
		return IRDM_EFORMAT;
	memcpy(buf, s, len);
	buf[len] = '\0';
	errno = 0;
	*v = strtoull(buf, &end, 0);
	return *end || errno || *v > max ? IRDM_EFORMAT : IRDM_OK;
}

static int bad(char *err, size_t errlen, const char *word, const char *why, const char *usage)
{
	if (err && errlen)
		snprintf(err, errlen, "fault '%s': %s%s%s", word, why, usage ? ", expected " : "",
			 usage ? usage : "");
	return IRDM_EFORMAT;
}

/* The numbers after the kind's name, checked against their ranges. */
static int numbers(const char *word, const char *p, unsigned n, unsigned long long v[FIELDS_MAX],
		   const unsigned long long max[FIELDS_MAX], const char *usage, char *err,
		   size_t errlen)
{
	for (unsigned k = 0; k < n; k++) {
		const char *end;

		if (*p != ':')
			return bad(err, errlen, word, "too few fields", usage);
		p++;
		end = strchr(p, ':');
		if (!end)
			end = p + strlen(p);
		/* the first field is a node or a SYNC: both count from 1 */
		if (field(p, (size_t)(end - p), max[k], &v[k]) || (k == 0 && v[k] == 0))
			return bad(err, errlen, word, "a number is malformed or out of range", usage);
		p = end;
	}
	return *p ? bad(err, errlen, word, "too many fields", usage) : IRDM_OK;
}

int irdm_can_fault_parse(const char *word, struct irdm_can_fault *f, char *err, size_t errlen)
{
	const unsigned long long node = IRDM_CO_NODE_MAX, sync = UINT64_MAX / 2,
				 k = IRDM_CAN_FAULT_K_MAX;
	unsigned long long v[FIELDS_MAX] = { 0 };

	memset(f, 0, sizeof(*f));
	for (size_t i = 0; i < sizeof(kinds) / sizeof(kinds[0]); i++) {
		size_t len = strlen(kinds[i].name);
		unsigned long long m[FIELDS_MAX] = { node, sync, k, IRDM_CAN_FAULT_DELAY_US_MAX };
		int rc;

		if (strncmp(word, kinds[i].name, len) || (word[len] && word[len] != ':'))
			continue;
		if (kinds[i].kind == IRDM_CAN_FAULT_EMCY)
			m[2] = 0xFFFF;
		if (kinds[i].kind == IRDM_CAN_FAULT_FLOOD)
			m[0] = sync, m[1] = IRDM_CAN_FAULT_FLOOD_MAX;
		rc = numbers(word, word + len, kinds[i].fields, v, m, kinds[i].usage, err, errlen);
		if (rc)
			return rc;
		f->kind = kinds[i].kind;
		if (f->kind == IRDM_CAN_FAULT_FLOOD) {
			f->at_sync = v[0], f->count = (uint32_t)v[1];
			return f->count ? IRDM_OK : bad(err, errlen, word, "COUNT must be >= 1", NULL);
		}
		f->node = (unsigned)v[0];
		f->at_sync = v[1];
		f->count = (uint32_t)v[2];
		f->code = (uint16_t)v[2];
		f->delay_us = (uint32_t)v[3];
		if (f->kind != IRDM_CAN_FAULT_SDO_WRONG && f->at_sync == 0)
			return bad(err, errlen, word, "SYNC counts from 1", NULL);
		if ((f->kind == IRDM_CAN_FAULT_DROP || f->kind == IRDM_CAN_FAULT_DELAY) && !f->count)
			return bad(err, errlen, word, "K must be >= 1", NULL);
		return IRDM_OK;
	}
	return bad(err, errlen, word, "unknown kind, expected one of drop, delay, heartbeat-stop, "
				      "emcy, fault, sdo-wrong, flood",
		   NULL);
}
