/* SPDX-License-Identifier: MIT */
/*
 * A per-tick upper bound on |u| of every touchable node for the free
 * response irdm_engine_node_disp() returns, so that a closest-point query
 * can prune its BVH to the device's neighbourhood instead of growing every
 * box by a fixed worst case.
 *
 * Modal: u_v = sum_k phi_v,k yq_k, so |u_v| <= sum_k |phi_v,k| |yq_k|
 * <= sum_k phimax_k |yq_k| with phimax_k = max over columns of the norm of
 * the node's 3-vector phi_v,k (precomputed at init).
 * FIR: u_v = sum_s w[s] sum_e R[s](e -> v) f_e, and |R f| <= ||R||_F |f|,
 * so |u_v| <= sum_s w[s] rmax[s] sum_e |f_e| with rmax[s] = max over force
 * columns and touchable rows of the Frobenius norm of R[s] (init).
 *
 * Both sums add only non-negative terms; the sums they bound may round
 * the other way by at most (terms) * eps relative, hence BOUND_ROUND.
 */
#include <math.h>

#include "engine_priv.h"

/* Covers rounding of both sides for up to ~1e5 terms (eps 2.2e-16). */
#define BOUND_ROUND (1 + 1e-10)

static void modal_bound_init(const struct irdm_engine *e, double *w)
{
	for (uint32_t k = 0; k < e->K; k++) {
		double mx = 0;

		for (uint32_t c = 0; c < e->n_cols; c++) {
			const double *p = &e->phi[(size_t)c * 3 * e->Kp];
			double x = p[k], y = p[e->Kp + k], z = p[2 * (size_t)e->Kp + k];

			mx = fmax(mx, sqrt(x * x + y * y + z * z));
		}
		w[k] = mx;
	}
}

/* Frobenius norm of the 3x3 block of R[s] from force column cf to row. */
static double fir_block_norm(const struct irdm_engine *e, uint32_t cf, uint32_t row, uint32_t s)
{
	const struct irdm_image *img = e->img;
	size_t o = (((size_t)cf * e->n_nodes + row) * e->T + s) * 9;
	double ss = 0;

	for (size_t i = 0; i < 9; i++) {
		double r = irdm_image_value(img, img->fir, cf, o + i);

		ss += r * r;
	}
	return sqrt(ss);
}

static void fir_bound_init(const struct irdm_engine *e, double *w)
{
	for (uint32_t s = 0; s < e->T; s++) {
		double mx = 0;

		for (uint32_t cf = 0; cf < e->n_cols; cf++)
			for (uint32_t cd = 0; cd < e->n_cols; cd++)
				mx = fmax(mx, fir_block_norm(e, cf, e->img->columns[cd], s));
		w[s] = mx;
	}
}

void irdm_bound_init(const struct irdm_engine *e, double *w)
{
	if (e->K)
		modal_bound_init(e, w);
	else if (e->T)
		fir_bound_init(e, w);
}

static double modal_bound(const struct irdm_engine *e)
{
	double b = 0;

	for (uint32_t k = 0; k < e->K; k++) {
		/* the free evolution irdm_engine_node_disp() reads: A x */
		b += e->bound_w[k] * fabs(e->y[2 * k]);
	}
	return b;
}

static double fir_bound(const struct irdm_engine *e)
{
	const struct irdm_fir_ring *r = &e->ring;
	double b = 0;

	for (uint32_t s = 1; s < e->T; s++) {
		/* the slot irdm_fir_free_disp() reads for age s */
		const struct irdm_force_tick *t = &r->tick[(r->head + e->T + 1 - s) % e->T];
		double f = 0;

		/* the ring's forces are in their columns' storage scale */
		for (uint32_t n = 0; n < t->n; n++)
			f += irdm_v3_norm(t->f_n[n]) / irdm_image_col_scale(e->img, t->col[n]);
		b += e->tail_w[s] * e->bound_w[s] * f;
	}
	return b;
}

double irdm_engine_disp_bound(const struct irdm_engine *e)
{
	double b = e->K ? modal_bound(e) : e->T ? fir_bound(e) :
						  0;

	if (e->H) /* a hybrid image's head over the last H - 1 ticks' forces */
		b += irdm_head_bound(e, e->head_bound_w);

	return b * BOUND_ROUND;
}
