/* SPDX-License-Identifier: MIT */
/*
 * The storage scales of an f16 image (image section COLUMN_SCALE): one
 * power of two per force column, chosen so that the column's largest
 * magnitude sits near the top of binary16's range.  Raw binary16 holds
 * nothing below 6e-8, and a stiff object's compliances are 1e-9 m/N.
 */
#ifndef IRDM_TOOLS_COL_SCALE_H
#define IRDM_TOOLS_COL_SCALE_H

#include <stddef.h>
#include <stdint.h>

/* Largest stored magnitude a scale aims at: 2^14, a factor 4 below the
 * largest finite binary16 (65504), so that rounding up never overflows. */
#define IRDM_COL_SCALE_TOP 14

/*
 * mx[c] = max(mx[c], |x_i|) over column c's elements of x: [start[c] per,
 * start[c + 1] per), or [c per, (c + 1) per) if start is NULL.
 */
void irdm_col_absmax(const double *x, size_t n_cols, const uint32_t *start, size_t per,
		     double *mx);

/* The power of two s with mx / s in [2^(TOP-1), 2^TOP); 1 if mx is 0 or
 * not finite, clamped to binary32's normal range. */
float irdm_col_scale_for(double mx);

/*
 * x stored in precision elem, column c's elements (laid out as for
 * irdm_col_absmax()) divided by scale[c]; x replaced by what was stored
 * times the scale (exact: a power of two), the values the firmware will
 * read.  Return: the array (malloc), NULL if out of memory.
 */
void *irdm_store_scaled(double *x, size_t n_cols, const uint32_t *start, size_t per,
			const float *scale, uint32_t elem, size_t *bytes);

#endif /* IRDM_TOOLS_COL_SCALE_H */
