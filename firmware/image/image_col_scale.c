/* SPDX-License-Identifier: MIT */
/*
 * COLUMN_SCALE (format 2.4): one power of two per force column, by which
 * the column's FIR, STATIC_CORR and EXACT_HEAD values were divided before
 * they were stored.  binary16 holds nothing below 6e-8 and a stiff
 * object's compliances are 1e-9 m/N: scaled, every column uses the top of
 * the format's range.  A power of two, so that dividing and multiplying
 * back are exact; a normal f32, so that its reciprocal is one too.
 */
#include <stdint.h>
#include <string.h>

#include "image_priv.h"

/* A positive normal binary32 with a zero mantissa. */
static bool power_of_two(float f)
{
	uint32_t x, exp;

	memcpy(&x, &f, sizeof(x));
	exp = x >> 23 & 0xffu;
	return !(x & 0x807fffffu) && exp != 0 && exp != 0xffu;
}

int img_check_col_scale(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	bool want = m->flags & IRDM_META_COLUMN_SCALE;
	const float *s;
	int ret;

	ret = img_check_presence(p, IRDM_SEC_COLUMN_SCALE, want,
				 want ? "meta flags say COLUMN_SCALE" : "meta flags lack COLUMN_SCALE");
	if (ret || !want)
		return ret;
	ret = img_check_shape(p, IRDM_SEC_COLUMN_SCALE, (uint64_t[]){ m->n_cols }, 1, "n_cols");
	if (ret)
		return ret;
	s = img_payload(p, IRDM_SEC_COLUMN_SCALE);
	for (uint32_t c = 0; c < m->n_cols; c++)
		if (!power_of_two(s[c]))
			return img_fail(p, IRDM_EFORMAT,
					"column %u: scale %g is not a normal power of two",
					c, (double)s[c]);
	p->img.col_scale = s;
	return IRDM_OK;
}
