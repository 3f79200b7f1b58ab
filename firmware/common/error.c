/* SPDX-License-Identifier: MIT */
/* Names and descriptions of the project's error codes (irdm/error.h). */
#include "irdm/error.h"

struct err_text {
	const char *name;
	const char *text;
};

/* Indexed by -code. */
static const struct err_text err_table[] = {
	[-IRDM_OK] = { "OK", "success" },
	[-IRDM_EINVAL] = { "EINVAL", "invalid argument" },
	[-IRDM_ENOMEM] = { "ENOMEM", "out of memory" },
	[-IRDM_EIO] = { "EIO", "input/output error" },
	[-IRDM_ETRUNC] = { "ETRUNC", "truncated" },
	[-IRDM_EMAGIC] = { "EMAGIC", "not an IRDM image" },
	[-IRDM_EVERSION] = { "EVERSION", "unsupported version" },
	[-IRDM_ECRC] = { "ECRC", "bad checksum" },
	[-IRDM_ERANGE] = { "ERANGE", "out of range" },
	[-IRDM_EMISSING] = { "EMISSING", "missing or duplicated part" },
	[-IRDM_EFORMAT] = { "EFORMAT", "invalid value" },
	[-IRDM_ECONTACT] = { "ECONTACT", "not touchable" },
	[-IRDM_EFAULT] = { "EFAULT", "faulted" },
	[-IRDM_EBUSY] = { "EBUSY", "busy" },
	[-IRDM_ETHREAD] = { "ETHREAD", "thread not created" },
	[-IRDM_ENUMERIC] = { "ENUMERIC", "numerical failure" },
	[-IRDM_ENOTSUP] = { "ENOTSUP", "not supported" },
	[-IRDM_EPERM] = { "EPERM", "permission refused" },
	[-IRDM_ETIMEDOUT] = { "ETIMEDOUT", "timed out" },
	[-IRDM_EHW] = { "EHW", "hardware fault" },
	[-IRDM_ECHILD] = { "ECHILD", "external program failed" },
	[-IRDM_EEXIST] = { "EEXIST", "exists, not replaced" },
};

_Static_assert(sizeof(err_table) / sizeof(err_table[0]) == 1 - IRDM_ERR_MIN,
	       "every error code has a name");

static const struct err_text *lookup(int code)
{
	if (code > 0 || code < IRDM_ERR_MIN)
		return 0;
	return &err_table[-code];
}

const char *irdm_strerror(int code)
{
	const struct err_text *t = lookup(code);
	return t ? t->text : "unknown error";
}

const char *irdm_errname(int code)
{
	const struct err_text *t = lookup(code);
	return t ? t->name : "E?";
}
