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
 *
 * Both per-tick loops over the modes are written for four modes side by
 * side (MODE_LANES; the arrays padded to Kp with zero modes), and
 * engine_modal_avx2.c runs them four at a time where the processor has
 * AVX2: the recursion is mode by mode, the displacement and R[0] sums four
 * partial sums (lane j the modes k = j mod 4, in the order of k) folded
 * as (s0 + s2) + (s1 + s3), the order a vector's halves fold in.  The
 * two paths give the same bits (test_engine).
 */
#include <string.h>

#include "engine_priv.h"

static double flush_tiny(double x)
{
	return fabs(x) < MODE_STATE_FLUSH ? 0.0 : x;
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

/* The kept modes' part of the free displacement at col: per axis four
 * partial sums, folded as a vector's halves fold. */
static void modes_free_disp(const struct irdm_engine *e, uint32_t col, double u[3])
{
	if (e->modal_wide) {
		irdm_modal_disp_wide(e, col, u);
		return;
	}
	const uint32_t Kp = e->Kp;
	const double *p = &e->phi[(size_t)col * 3 * Kp];
	const double *y = e->y;
	double s[3][MODE_LANES] = { { 0 } };

	for (uint32_t k = 0; k < Kp; k += MODE_LANES)
		for (uint32_t j = 0; j < MODE_LANES; j++) {
			double yk = y[2 * (k + j)];

			for (uint32_t a = 0; a < 3; a++)
				s[a][j] += p[a * (size_t)Kp + k + j] * yk;
		}
	for (uint32_t a = 0; a < 3; a++)
		u[a] = (s[a][0] + s[a][2]) + (s[a][1] + s[a][3]);
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

/* The kept modes' part of R[0] from col_force to col_disp: per element
 * sum_k phi_d,k phi_f,k b_k,q, four partial sums folded as a vector's
 * halves fold. */
static void modes_r0(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp,
		     double s[9])
{
	if (e->modal_wide) {
		irdm_modal_r0_wide(e, col_force, col_disp, s);
		return;
	}
	const uint32_t Kp = e->Kp;
	const double *pd = &e->phi[(size_t)col_disp * 3 * Kp];
	const double *pf = &e->phi[(size_t)col_force * 3 * Kp];
	double acc[9][MODE_LANES] = { { 0 } };

	for (uint32_t k = 0; k < Kp; k += MODE_LANES)
		for (uint32_t j = 0; j < MODE_LANES; j++) {
			uint32_t i = k + j;
			double b = e->coef[i / 2].b[2 * (i % 2)];

			for (uint32_t r = 0; r < 3; r++)
				for (uint32_t c = 0; c < 3; c++)
					acc[3 * r + c][j] += pd[r * (size_t)Kp + i] *
							     pf[c * (size_t)Kp + i] * b;
		}
	for (uint32_t n = 0; n < 9; n++)
		s[n] = (acc[n][0] + acc[n][2]) + (acc[n][1] + acc[n][3]);
}

void irdm_modal_r0(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp, double blk[9])
{
	double s[9];

	/* the static correction: kept block (zero where dropped) + far field;
	 * a hybrid image's kept blocks take the head's first sample instead
	 * (the head's samples sum to the whole block, far field included) */
	if (!e->H || !irdm_head_r0(e, col_force, col_disp, blk))
		irdm_image_corr_value(e->img, col_force, col_disp, blk);
	modes_r0(e, col_force, col_disp, s);
	for (uint32_t n = 0; n < 9; n++)
		blk[n] += s[n];
}

/* The modes' recursion for this tick's forces f, mode by mode:
 *   g = sum over force nodes of ((phi_x f_x + phi_y f_y) + phi_z f_z),
 *   x = y + b g (flushed), y = (a00 q + a01 q', a10 q + a11 q'). */
static void recur(struct irdm_engine *e, const struct irdm_force_tick *f)
{
	const uint32_t Kp = e->Kp, nf = f->n;
	const double *p[IRDM_MAX_FORCE_NODES];

	for (uint32_t n = 0; n < nf; n++)
		p[n] = &e->phi[(size_t)f->col[n] * 3 * Kp];
	for (uint32_t k = 0; k < Kp; k++) {
		const struct mode_coef *c = &e->coef[k / 2];
		const uint32_t i = 2 * (k % 2);
		double g = 0;

		for (uint32_t n = 0; n < nf; n++)
			g += p[n][k] * f->f_n[n][0] + p[n][Kp + k] * f->f_n[n][1] +
			     p[n][2 * (size_t)Kp + k] * f->f_n[n][2];
		double q = flush_tiny(e->y[2 * k] + c->b[i] * g);
		double v = flush_tiny(e->y[2 * k + 1] + c->b[i + 1] * g);
		e->x[2 * k] = q;
		e->x[2 * k + 1] = v;
		e->y[2 * k] = c->aq[i] * q + c->av[i] * v;
		e->y[2 * k + 1] = c->aq[i + 1] * q + c->av[i + 1] * v;
	}
}

void irdm_modal_apply(struct irdm_engine *e, const struct irdm_force_tick *f)
{
	if (e->modal_wide)
		irdm_modal_recur_wide(e, f);
	else
		recur(e, f);
	if (e->H)
		irdm_head_apply(e, f);
}
