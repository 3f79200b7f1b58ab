/* SPDX-License-Identifier: MIT */
/*
 * Modal history: the exact state recursion of every mode,
 *   x_k[t+1] = A_k x_k[t] + b_k g_k[t],   g_k = sum_e phi_e,k . f_e,
 *   u_v[t]   = sum_k phi_v,k x_k,q[t+1] + sum_e D(v <- e) f_e,
 * split into the free part (no force this tick: sum_k phi_v,k (A_k x_k)_q)
 * and R[0] (sum_k phi_v,k phi_e,k^T b_k,q + D).  Infinite memory at
 * O(modes) per tick; double precision throughout (float history sums
 * lose to cancellation: docs/architecture.md, "Numerical hazards").
 * y = A x is made as soon as x is (irdm_modal_apply()): between ticks it
 * gives the free response the proxy's surface is read from, and the tick
 * starts from it.  A column's free displacement is remembered until the
 * state changes: the proxy and the contacts' history term ask for the
 * same nodes.
 */
#include <string.h>

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

/* y = A x for mode k: the free evolution of the state x just set. */
static void evolve(struct irdm_engine *e, const struct irdm_mode *m, uint32_t k)
{
	double q = e->x[2 * k], v = e->x[2 * k + 1];

	e->y[2 * k] = m[k].a[0] * q + m[k].a[1] * v;
	e->y[2 * k + 1] = m[k].a[2] * q + m[k].a[3] * v;
}

static struct free_memo *memo_of(const struct irdm_engine *e, uint32_t col)
{
	/* a memo: the engine's state is the caller's to change, never here */
	return (struct free_memo *)&e->free_memo[col % FREE_MEMO];
}

static bool memo_get(const struct irdm_engine *e, uint32_t col, double u[3])
{
	const struct free_memo *mm = memo_of(e, col);

	if (mm->stamp != e->tick + 1 || mm->col != col)
		return false;
	memcpy(u, mm->u, sizeof(mm->u));
	return true;
}

static void memo_put(const struct irdm_engine *e, uint32_t col, const double u[3])
{
	struct free_memo *mm = memo_of(e, col);

	mm->stamp = e->tick + 1;
	mm->col = col;
	memcpy(mm->u, u, sizeof(mm->u));
}

/* The kept modes' part of the free displacement at col. */
static void modes_free_disp(const struct irdm_engine *e, uint32_t col, double u[3])
{
	const uint32_t K = e->K;
	const double *p0 = &e->phi[(size_t)col * 3 * K], *p1 = p0 + K, *p2 = p1 + K;
	const double *y = e->y;
	double s0 = 0, s1 = 0, s2 = 0;

	/* three sums side by side, each in the order of k */
	for (uint32_t k = 0; k < K; k++) {
		double yk = y[2 * k];

		s0 += p0[k] * yk;
		s1 += p1[k] * yk;
		s2 += p2[k] * yk;
	}
	u[0] = s0;
	u[1] = s1;
	u[2] = s2;
}

void irdm_modal_free_disp(const struct irdm_engine *e, uint32_t col, double u[3])
{
	irdm_modal_free_disps(e, 1, &col, (double(*)[3])u);
}

/* n <= IRDM_MAX_FORCE_NODES distinct columns.  Those the memo lacks are
 * summed together: a head's columns share one pass over its history. */
void irdm_modal_free_disps(const struct irdm_engine *e, uint32_t n, const uint32_t *cols,
			   double (*u)[3])
{
	uint32_t miss[IRDM_MAX_FORCE_NODES], mc[IRDM_MAX_FORCE_NODES], n_miss = 0;
	double um[IRDM_MAX_FORCE_NODES][3];

	for (uint32_t v = 0; v < n; v++) {
		if (memo_get(e, cols[v], u[v]))
			continue;
		modes_free_disp(e, cols[v], um[n_miss]);
		mc[n_miss] = cols[v];
		miss[n_miss++] = v;
	}
	if (e->H && n_miss)
		irdm_head_free_disps(e, n_miss, mc, um);
	for (uint32_t i = 0; i < n_miss; i++) {
		memcpy(u[miss[i]], um[i], sizeof(um[i]));
		memo_put(e, mc[i], um[i]);
	}
}

void irdm_modal_r0(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp, double blk[9])
{
	const struct irdm_mode *m = e->img->modes;
	const uint32_t K = e->K;
	const double *pd = &e->phi[(size_t)col_disp * 3 * K];
	const double *pf = &e->phi[(size_t)col_force * 3 * K];
	double s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, s5 = 0, s6 = 0, s7 = 0, s8 = 0;

	/* the static correction: kept block (zero where dropped) + far field;
	 * a hybrid image's kept blocks take the head's first sample instead
	 * (the head's samples sum to the whole block, far field included) */
	if (!e->H || !irdm_head_r0(e, col_force, col_disp, blk))
		irdm_image_corr_value(e->img, col_force, col_disp, blk);
	/* the nine sums side by side (a site change computes up to nine
	 * blocks in one tick), each in the order of k */
	for (uint32_t k = 0; k < K; k++) {
		double b = m[k].b[0];
		double d0 = pd[k], d1 = pd[K + k], d2 = pd[2 * (size_t)K + k];
		double f0 = pf[k], f1 = pf[K + k], f2 = pf[2 * (size_t)K + k];

		s0 += d0 * f0 * b, s1 += d0 * f1 * b, s2 += d0 * f2 * b;
		s3 += d1 * f0 * b, s4 += d1 * f1 * b, s5 += d1 * f2 * b;
		s6 += d2 * f0 * b, s7 += d2 * f1 * b, s8 += d2 * f2 * b;
	}
	blk[0] += s0, blk[1] += s1, blk[2] += s2;
	blk[3] += s3, blk[4] += s4, blk[5] += s5;
	blk[6] += s6, blk[7] += s7, blk[8] += s8;
}

void irdm_modal_apply(struct irdm_engine *e, const struct irdm_force_tick *f)
{
	const struct irdm_mode *m = e->img->modes;
	const uint32_t K = e->K, nf = f->n;
	const double *p[IRDM_MAX_FORCE_NODES];

	for (uint32_t n = 0; n < nf; n++)
		p[n] = &e->phi[(size_t)f->col[n] * 3 * K];
	for (uint32_t k = 0; k < K; k++) {
		double g = 0;
		for (uint32_t n = 0; n < nf; n++)
			g += p[n][k] * f->f_n[n][0] + p[n][K + k] * f->f_n[n][1] + p[n][2 * (size_t)K + k] * f->f_n[n][2];
		e->x[2 * k] = flush_tiny(e->y[2 * k] + m[k].b[0] * g);
		e->x[2 * k + 1] = flush_tiny(e->y[2 * k + 1] + m[k].b[1] * g);
		evolve(e, m, k);
	}
	if (e->H)
		irdm_head_apply(e, f);
}
