/* SPDX-License-Identifier: MIT */
/*
 * Writes into the force history ring that an FIR image's sum and a hybrid
 * image's head read (engine_fir.c, engine_head.c and their wide paths).
 *
 * An image with column scales (COLUMN_SCALE) stores force column c's
 * values divided by scale[c], a power of two; the ring holds each force
 * times its column's scale instead, so that the sums read the stored
 * values as they are: sum R'[s] f' = sum R[s] f, their loops unchanged.
 * The ring is working memory in double, where the product is exact.
 */
#include "engine_priv.h"

void irdm_ring_put(const struct irdm_engine *e, struct irdm_force_tick *slot,
		   const struct irdm_force_tick *f)
{
	*slot = *f;
	if (!e->img->col_scale)
		return;
	for (uint32_t n = 0; n < f->n; n++) {
		double s = irdm_image_col_scale(e->img, f->col[n]);
		for (int j = 0; j < 3; j++)
			slot->f_n[n][j] *= s;
	}
}
