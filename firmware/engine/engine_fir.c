/* SPDX-License-Identifier: MIT */
/*
 * FIR history: a ring of the last T ticks' forces and the history term
 *   U~_v[t] = sum_{s=1}^{T-1} w[s] sum_e R[s](e -> v) f_e[t-s]
 * summed in double (float sums lose 1e-3 of the static force to
 * cancellation; docs/architecture.md, "Numerical hazards").  w[s] = r^s
 * damps the tail of images whose truncated recursion is unstable (r = 1
 * otherwise): it moves every pole of the recursion by the factor r.
 */
#include <string.h>

#include "engine_priv.h"

static size_t fir_index(const struct irdm_engine *e, uint32_t col, uint32_t row, uint32_t s)
{
	return (((size_t)col * e->n_nodes + row) * e->T + s) * 9;
}

/*
 * The free response of the coming tick at column col:
 *   sum_{s=1}^{T-1} w[s] sum_e R[s](col_e -> row) f_e[t-s],
 * one pass over the ring; each entry reads one 3x3 block.
 */
void irdm_fir_free_disp(const struct irdm_engine *e, uint32_t col, double u[3])
{
	const struct irdm_image *img = e->img;
	const struct irdm_fir_ring *r = &e->ring;
	uint32_t prec = img->meta->precision, row = img->columns[col];
	double acc[3] = { 0, 0, 0 };

	for (uint32_t s = 1; s < e->T; s++) {
		/* age s is the slot s - 1 before the newest */
		const struct irdm_force_tick *t = &r->tick[(r->head + e->T + 1 - s) % e->T];
		double w = e->tail_w[s];
		for (uint32_t n = 0; n < t->n; n++) {
			const double *f = t->f_n[n];
			size_t o = fir_index(e, t->col[n], row, s);
			/* One row of R[s] against f, then w: 3 multiplies by w
			 * where a per-entry sum needs 9 (the tick's hot loop). */
			for (int i = 0; i < 3; i++) {
				size_t k = o + 3 * (size_t)i;

				acc[i] += w * (irdm_elem_get(img->fir, prec, k) * f[0] +
					       irdm_elem_get(img->fir, prec, k + 1) * f[1] +
					       irdm_elem_get(img->fir, prec, k + 2) * f[2]);
			}
		}
	}
	memcpy(u, acc, sizeof(acc));
}

void irdm_fir_r0(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp, double blk[9])
{
	size_t o = fir_index(e, col_force, e->img->columns[col_disp], 0);

	for (int k = 0; k < 9; k++)
		blk[k] = irdm_elem_get(e->img->fir, e->img->meta->precision, o + (size_t)k);
}

void irdm_fir_apply(struct irdm_engine *e, const struct irdm_force_tick *f)
{
	struct irdm_fir_ring *r = &e->ring;

	r->head = (r->head + 1) % e->T;
	r->tick[r->head] = *f;
}
