/* SPDX-License-Identifier: MIT */
/*
 * Modal history: the exact state recursion of every mode,
 *   x_k[t+1] = A_k x_k[t] + b_k g_k[t],   g_k = sum_e phi_e,k . f_e,
 *   u_v[t]   = sum_k phi_v,k x_k,q[t+1] + sum_e D(v <- e) f_e,
 * split into the free part (no force this tick: sum_k phi_v,k (A_k x_k)_q)
 * and R[0] (sum_k phi_v,k phi_e,k^T b_k,q + D).  Infinite memory at
 * O(modes) per tick; double precision throughout (float history sums
 * lose to cancellation: docs/architecture.md, "Numerical hazards").
 */
#include "engine_priv.h"

/*
 * A mode let go decays geometrically (|A_k| < 1) through the subnormal
 * range, where a multiply-add on a subnormal operand can cost a hundred
 * cycles on x86 (microcode assist); a released cuboid handed 10^6
 * subnormal displacements to the contact query in 600 s.
 * A state below 1e-200 (metres, metres per second) is no physics any
 * more: it is set to zero, where it stays until a force excites the mode.
 */
#define STATE_FLUSH 1e-200

static double flush_tiny(double x)
{
	return fabs(x) < STATE_FLUSH ? 0.0 : x;
}

void irdm_modal_begin_tick(struct irdm_engine *e)
{
	const struct irdm_mode *m = e->img->modes;

	for (uint32_t k = 0; k < e->K; k++) {
		double q = e->x[2 * k], v = e->x[2 * k + 1];
		e->y[2 * k] = m[k].a[0] * q + m[k].a[1] * v;
		e->y[2 * k + 1] = m[k].a[2] * q + m[k].a[3] * v;
	}
}

void irdm_modal_free_disp(const struct irdm_engine *e, uint32_t col, double u[3])
{
	const double *phi = &e->phi[(size_t)col * 3 * e->K];

	for (int i = 0; i < 3; i++) {
		const double *p = &phi[(size_t)i * e->K];
		double s = 0;
		for (uint32_t k = 0; k < e->K; k++)
			s += p[k] * e->y[2 * k];
		u[i] = s;
	}
	if (e->H)
		irdm_head_free_disp(e, col, u);
}

void irdm_modal_r0(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp, double blk[9])
{
	const struct irdm_mode *m = e->img->modes;
	const double *pd = &e->phi[(size_t)col_disp * 3 * e->K];
	const double *pf = &e->phi[(size_t)col_force * 3 * e->K];

	/* the static correction: kept block (zero where dropped) + far field;
	 * a hybrid image's kept blocks take the head's first sample instead
	 * (the head's samples sum to the whole block, far field included) */
	if (!e->H || !irdm_head_r0(e, col_force, col_disp, blk))
		irdm_image_corr_value(e->img, col_force, col_disp, blk);
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) {
			double s = 0;
			for (uint32_t k = 0; k < e->K; k++)
				s += pd[(size_t)i * e->K + k] * pf[(size_t)j * e->K + k] * m[k].b[0];
			blk[3 * i + j] += s;
		}
}

void irdm_modal_apply(struct irdm_engine *e, const struct irdm_force_tick *f)
{
	const struct irdm_mode *m = e->img->modes;

	for (uint32_t k = 0; k < e->K; k++) {
		double g = 0;
		for (uint32_t n = 0; n < f->n; n++) {
			const double *p = &e->phi[(size_t)f->col[n] * 3 * e->K];
			g += p[k] * f->f_n[n][0] + p[e->K + k] * f->f_n[n][1]
			     + p[2 * (size_t)e->K + k] * f->f_n[n][2];
		}
		e->x[2 * k] = flush_tiny(e->y[2 * k] + m[k].b[0] * g);
		e->x[2 * k + 1] = flush_tiny(e->y[2 * k + 1] + m[k].b[1] * g);
	}
	if (e->H)
		irdm_head_apply(e, f);
}
