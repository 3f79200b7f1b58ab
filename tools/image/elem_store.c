/* SPDX-License-Identifier: MIT */
/* Doubles to image storage precision (see elem_store.h). */
#include <string.h>

#include "image/elem_store.h"
#include "irdm/precision.h"

double irdm_elem_put(void *data, uint32_t elem, size_t i, double v)
{
	uint8_t *p = data;
	uint16_t h;
	float f;

	switch (elem) {
	case IRDM_ELEM_F64:
		memcpy(p + i * 8, &v, sizeof(v));
		return v;
	case IRDM_ELEM_F32:
		f = (float)v;
		memcpy(p + i * 4, &f, sizeof(f));
		return f;
	case IRDM_ELEM_F16:
		h = irdm_f32_to_f16((float)v);
		memcpy(p + i * 2, &h, sizeof(h));
		return irdm_f16_to_f32(h);
	default:
		return v;
	}
}
