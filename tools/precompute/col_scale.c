/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>

#include "image/elem_store.h"
#include "irdm/precision.h"
#include "precompute/col_scale.h"

static size_t first(const uint32_t *start, size_t c, size_t per)
{
	return (start ? start[c] : c) * per;
}

void irdm_col_absmax(const double *x, size_t n_cols, const uint32_t *start, size_t per,
		     double *mx)
{
	for (size_t c = 0; c < n_cols; c++)
		for (size_t i = first(start, c, per); i < first(start, c + 1, per); i++)
			mx[c] = fmax(mx[c], fabs(x[i]));
}

float irdm_col_scale_for(double mx)
{
	int e;

	if (!(mx > 0) || !isfinite(mx))
		return 1.0f;
	(void)frexp(mx, &e); /* mx <= 2^e < 2 mx */
	e -= IRDM_COL_SCALE_TOP;
	if (e < -126)
		e = -126;
	if (e > 127)
		e = 127;
	return ldexpf(1.0f, e);
}

void *irdm_store_scaled(double *x, size_t n_cols, const uint32_t *start, size_t per,
			const float *scale, uint32_t elem, size_t *bytes)
{
	size_t n = first(start, n_cols, per), es = irdm_elem_size(elem);
	void *out = malloc(n * es > 0 ? n * es : 1);

	*bytes = n * es;
	if (!out)
		return NULL;
	for (size_t c = 0; c < n_cols; c++) {
		double s = scale[c];
		for (size_t i = first(start, c, per); i < first(start, c + 1, per); i++)
			x[i] = irdm_elem_put(out, elem, i, x[i] / s) * s;
	}
	return out;
}
