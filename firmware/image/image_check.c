/* SPDX-License-Identifier: MIT */
/*
 * What every check of the loader uses: the table of known section kinds
 * (name, element type) and the one-line reason a failed check leaves.
 */
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>

#include "image_priv.h"

static const struct {
	const char *name;
	uint32_t elem;
} kinds[KIND_MAX + 1] = {
	[IRDM_SEC_META] = { "META", IRDM_ELEM_BYTES },
	[IRDM_SEC_PROVENANCE] = { "PROVENANCE", IRDM_ELEM_BYTES },
	[IRDM_SEC_NODES] = { "NODES", IRDM_ELEM_BYTES },
	[IRDM_SEC_COLUMNS] = { "COLUMNS", IRDM_ELEM_U32 },
	[IRDM_SEC_SURFACE] = { "SURFACE", IRDM_ELEM_U32 },
	[IRDM_SEC_FIR] = { "FIR", ELEM_PRECISION },
	[IRDM_SEC_MODES] = { "MODES", IRDM_ELEM_BYTES },
	[IRDM_SEC_MODE_SHAPES] = { "MODE_SHAPES", ELEM_PRECISION },
	[IRDM_SEC_STATIC_CORR] = { "STATIC_CORR", ELEM_PRECISION },
	[IRDM_SEC_RIGID] = { "RIGID", IRDM_ELEM_BYTES },
	[IRDM_SEC_STABILITY] = { "STABILITY", IRDM_ELEM_BYTES },
	[IRDM_SEC_CONTACT_BVH] = { "CONTACT_BVH", ELEM_ANY },
	[IRDM_SEC_STATIC_CORR_INDEX] = { "STATIC_CORR_INDEX", IRDM_ELEM_U32 },
	[IRDM_SEC_STATIC_CORR_LOWRANK] = { "STATIC_CORR_LOWRANK", IRDM_ELEM_BYTES },
	[IRDM_SEC_EXACT_HEAD] = { "EXACT_HEAD", ELEM_PRECISION },
	[IRDM_SEC_STATIC_CORR_CLUSTERS] = { "STATIC_CORR_CLUSTERS", IRDM_ELEM_BYTES },
	[IRDM_SEC_COLUMN_SCALE] = { "COLUMN_SCALE", IRDM_ELEM_F32 },
	[IRDM_SEC_EXACT_HEAD_INDEX] = { "EXACT_HEAD_INDEX", IRDM_ELEM_U32 },
};

static const char *const elem_names[] = {
	[IRDM_ELEM_BYTES] = "BYTES",
	[IRDM_ELEM_F16] = "F16",
	[IRDM_ELEM_F32] = "F32",
	[IRDM_ELEM_F64] = "F64",
	[IRDM_ELEM_U32] = "U32",
};

static int vreport(char *buf, size_t len, int code, const char *fmt,
		   va_list ap)
{
	if (buf && len)
		vsnprintf(buf, len, fmt, ap);
	return code;
}

/* Write a one-line reason into buf (if any) and return code. */
int img_report(char *buf, size_t len, int code, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	code = vreport(buf, len, code, fmt, ap);
	va_end(ap);
	return code;
}

int img_fail(struct parse *p, int code, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	code = vreport(p->err, p->errlen, code, fmt, ap);
	va_end(ap);
	return code;
}

const char *img_kind_name(uint32_t kind)
{
	if (kind <= KIND_MAX && kinds[kind].name)
		return kinds[kind].name;
	return "unknown kind";
}

const char *irdm_image_kind_name(uint32_t kind)
{
	return img_kind_name(kind);
}

const char *img_elem_name(uint32_t elem)
{
	if (elem < sizeof(elem_names) / sizeof(elem_names[0]))
		return elem_names[elem];
	return "unknown";
}

uint32_t img_kind_elem(uint32_t kind)
{
	return kinds[kind].elem;
}
