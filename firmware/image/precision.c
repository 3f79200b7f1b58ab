/* SPDX-License-Identifier: MIT */
/*
 * IEEE 754 binary16 <-> binary32 conversions and element access for the
 * precisions an image may store (F16, F32, F64, U32, bytes).
 *
 * Done on bit patterns, not with a compiler's half type: C11 has none, and
 * the result must not depend on the FPU's rounding mode.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "irdm/precision.h"

static uint32_t f32_bits(float f)
{
	uint32_t x;

	memcpy(&x, &f, sizeof(x));
	return x;
}

static float f32_from_bits(uint32_t x)
{
	float f;

	memcpy(&f, &x, sizeof(f));
	return f;
}

float irdm_f16_to_f32(uint16_t h)
{
	uint32_t sign = (uint32_t)(h & 0x8000u) << 16;
	uint32_t exp = (h >> 10) & 0x1fu;
	uint32_t mant = h & 0x3ffu;
	float mag;

	if (exp == 0x1f) /* inf, or NaN with its payload kept */
		return f32_from_bits(sign | 0x7f800000u | mant << 13);
	if (exp != 0) /* normal: rebias 15 -> 127 */
		return f32_from_bits(sign | (exp + 112u) << 23 | mant << 13);
	/* zero or subnormal: mant * 2^-24, exact in binary32 */
	mag = (float)mant * 0x1p-24f;
	return f32_from_bits(sign | f32_bits(mag));
}

/* |x| below the smallest normal half (2^-14): result is a subnormal or 0. */
static uint16_t f32_to_f16_small(uint32_t x)
{
	uint32_t exp = x >> 23;
	uint32_t mant, shift, h, rem, half;

	if (exp < 102) /* below 2^-25: rounds to zero */
		return 0;
	/* value = mant * 2^(exp - 150); in units of 2^-24: mant >> (126 - exp) */
	mant = (x & 0x7fffffu) | 0x800000u;
	shift = 126 - exp; /* 14..24 */
	h = mant >> shift;
	rem = mant & ((1u << shift) - 1);
	half = 1u << (shift - 1);
	if (rem > half || (rem == half && (h & 1)))
		h++; /* may carry into the smallest normal: fine */
	return (uint16_t)h;
}

uint16_t irdm_f32_to_f16(float f)
{
	uint32_t x = f32_bits(f);
	uint16_t sign = (uint16_t)((x >> 16) & 0x8000u);

	x &= 0x7fffffffu;
	if (x > 0x7f800000u) /* NaN: keep it quiet and keep the top payload */
		return sign | 0x7e00u | (uint16_t)((x >> 13) & 0x3ffu);
	if (x >= 0x477ff000u) /* >= 65520 rounds (to even) past 65504: inf */
		return sign | 0x7c00u;
	if (x < 0x38800000u) /* below 2^-14 */
		return sign | f32_to_f16_small(x);
	x -= 112u << 23;               /* rebias 127 -> 15 */
	x += 0xfffu + ((x >> 13) & 1); /* round to nearest, ties to even */
	return sign | (uint16_t)(x >> 13);
}

size_t irdm_elem_size(uint32_t elem)
{
	switch (elem) {
	case IRDM_ELEM_BYTES:
		return 1;
	case IRDM_ELEM_F16:
		return 2;
	case IRDM_ELEM_F32:
	case IRDM_ELEM_U32:
		return 4;
	case IRDM_ELEM_F64:
		return 8;
	default:
		return 0;
	}
}
