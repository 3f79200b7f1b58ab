/* SPDX-License-Identifier: MIT */
/*
 * Storage precision of image data (IRDM_ELEM_*): the one place the firmware
 * turns an element of any precision into a double.  Inline, so the loops
 * that read responses (FIR sums, deformation) keep the switch out of the
 * call overhead; the branch is the same every iteration and predicts well.
 */
#ifndef IRDM_PRECISION_H
#define IRDM_PRECISION_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "irdm/image_format.h"

/* IEEE binary16 <-> binary32 (round to nearest even; overflow -> inf). */
float irdm_f16_to_f32(uint16_t h);
uint16_t irdm_f32_to_f16(float f);

/* Bytes per element of a precision (0 for an unknown one). */
size_t irdm_elem_size(uint32_t elem);

/* Element i of an array of the given precision, as double (NaN for an
 * unknown precision).  Unaligned data is fine. */
static inline double irdm_elem_get(const void *data, uint32_t elem, size_t i)
{
	const uint8_t *p = data;
	uint16_t h;
	uint32_t u;
	float f;
	double d;

	switch (elem) {
	case IRDM_ELEM_F64:
		memcpy(&d, p + i * 8, sizeof(d));
		return d;
	case IRDM_ELEM_F32:
		memcpy(&f, p + i * 4, sizeof(f));
		return f;
	case IRDM_ELEM_F16:
		memcpy(&h, p + i * 2, sizeof(h));
		return irdm_f16_to_f32(h);
	case IRDM_ELEM_U32:
		memcpy(&u, p + i * 4, sizeof(u));
		return u;
	case IRDM_ELEM_BYTES:
		return p[i];
	default:
		return NAN;
	}
}

#endif /* IRDM_PRECISION_H */
