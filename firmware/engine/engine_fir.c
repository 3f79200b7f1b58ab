/* SPDX-License-Identifier: MIT */
/*
 * FIR history: a ring of the last T ticks' forces and the history term
 *   U~_v[t] = sum_{s=1}^{T-1} w[s] sum_e R[s](e -> v) f_e[t-s]
 * summed in double (float sums lose 1e-3 of the static force to
 * cancellation; docs/architecture.md, "Numerical hazards").  w[s] = r^s
 * damps the tail of images whose truncated recursion is unstable (r = 1
 * otherwise): it moves every pole of the recursion by the factor r.
 * An image with column scales (COLUMN_SCALE) has its ring in scaled
 * forces (force_ring.c).
 */
#include <string.h>

#include "engine_priv.h"

static size_t fir_index(const struct irdm_engine *e, uint32_t col, uint32_t row, uint32_t s)
{
	return (((size_t)col * e->n_nodes + row) * e->T + s) * 9;
}

/* The free response of the coming tick at column col (fir_sum.c). */
void irdm_fir_free_disp(const struct irdm_engine *e, uint32_t col, double u[3])
{
	double acc[1][3];

	irdm_fir_free_disps(e, 1, &col, acc);
	memcpy(u, acc[0], sizeof(acc[0]));
}

void irdm_fir_r0(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp, double blk[9])
{
	size_t o = fir_index(e, col_force, e->img->columns[col_disp], 0);

	for (int k = 0; k < 9; k++)
		blk[k] = irdm_image_value(e->img, e->img->fir, col_force, o + (size_t)k);
}

void irdm_fir_apply(struct irdm_engine *e, const struct irdm_force_tick *f)
{
	struct irdm_fir_ring *r = &e->ring;

	r->head = (r->head + 1) % e->T;
	irdm_ring_put(e, &r->tick[r->head], f);
}
