/* SPDX-License-Identifier: MIT */
/*
 * The FIR history term (fir_sum.c) with AVX2 and FMA, for the processors
 * that have them (checked once at engine init, never in the tick):
 *   U~_v = sum_{s=1}^{T-1} w[s] sum_e R[s](e -> v) f_e[t-s].
 *
 * Instead of forming R f for every block (three dot products, then a
 * reduction), each row keeps nine accumulators, one per block element:
 *   A_v[3i + j] += R[s](e -> v)[i][j] * w[s] f_e[j]
 * and folds them once at the end, u_v[i] = A[3i] + A[3i+1] + A[3i+2].
 * A block's nine elements are contiguous, so they load as two vectors of
 * four and one scalar, multiplied by the weighted force laid out in the
 * same pattern, (f0 f1 f2 f0)(f1 f2 f0 f1)(f2), which is formed once per
 * ring entry and shared by every row: three fused multiply-adds a block
 * where the portable path needs a dozen operations and two shuffles.
 * Up to three rows share one pass over the ring (a triangle's vertices:
 * nine vector and three scalar accumulators stay in registers).
 *
 * The sum runs in double as in fir_sum.c (docs/architecture.md, "Numerical
 * hazards"); its rounding differs from the portable path's in the last
 * bits (a different order, fused products), and it is the same on every
 * run of one machine, so a replay still reproduces a controller log.
 */
#include <stdbool.h>
#include <string.h>

#include "engine_priv.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include "wide_block.h"

/*
 * One pass over the ring for n_rows (1..3, a constant at each call site,
 * as prec is) rows.  Ages run newest first: age s is the slot s - 1
 * before the head.
 */
static WIDE_INLINE void wide_pass(const struct irdm_engine *e, uint32_t prec, uint32_t n_rows,
				  const uint32_t *rows, double (*u)[3])
{
	const void *fir = e->img->fir;
	const struct irdm_fir_ring *r = &e->ring;
	uint32_t slot = r->head, T = e->T;
	/* one variable a row, not an array: the compiler keeps them in
	 * registers (an array it indexes in a loop lives in memory, and every
	 * fused multiply-add then waits on a store) */
	struct row_acc a0, a1, a2;

	a0.a0 = a0.a1 = a1.a0 = a1.a1 = a2.a0 = a2.a1 = _mm256_setzero_pd();
	a0.a2 = a1.a2 = a2.a2 = 0;
	for (uint32_t s = 1; s < T; s++) {
		const struct irdm_force_tick *t = &r->tick[slot];
		double w = e->tail_w[s];
		for (uint32_t n = 0; n < t->n; n++) {
			__m256d p0, p1;
			double p2;
			force_pattern(t->f_n[n], w, &p0, &p1, &p2);
			size_t base = (size_t)t->col[n] * e->n_nodes;
			block_acc(fir, prec, ((base + rows[0]) * T + s) * 9, p0, p1, p2, &a0);
			if (n_rows > 1)
				block_acc(fir, prec, ((base + rows[1]) * T + s) * 9, p0, p1, p2, &a1);
			if (n_rows > 2)
				block_acc(fir, prec, ((base + rows[2]) * T + s) * 9, p0, p1, p2, &a2);
		}
		slot = slot ? slot - 1 : T - 1;
	}
	row_fold(&a0, u[0]);
	if (n_rows > 1)
		row_fold(&a1, u[1]);
	if (n_rows > 2)
		row_fold(&a2, u[2]);
}

/* The passes for one precision: three rows a pass, the last with what is left. */
static WIDE_INLINE void wide_rows(const struct irdm_engine *e, uint32_t prec, uint32_t n,
				  const uint32_t *rows, double (*u)[3])
{
	for (uint32_t v = 0; v < n; v += 3) {
		switch (n - v) {
		case 1:
			wide_pass(e, prec, 1, rows + v, u + v);
			break;
		case 2:
			wide_pass(e, prec, 2, rows + v, u + v);
			break;
		default:
			wide_pass(e, prec, 3, rows + v, u + v);
			break;
		}
	}
}

static WIDE void wide_f64(const struct irdm_engine *e, uint32_t n, const uint32_t *rows,
			  double (*u)[3])
{
	wide_rows(e, IRDM_ELEM_F64, n, rows, u);
}

static WIDE void wide_f32(const struct irdm_engine *e, uint32_t n, const uint32_t *rows,
			  double (*u)[3])
{
	wide_rows(e, IRDM_ELEM_F32, n, rows, u);
}

static WIDE void wide_f16(const struct irdm_engine *e, uint32_t n, const uint32_t *rows,
			  double (*u)[3])
{
	wide_rows(e, IRDM_ELEM_F16, n, rows, u);
}

void irdm_fir_sum_wide(const struct irdm_engine *e, uint32_t n, const uint32_t *rows,
		       double (*u)[3])
{
	switch (e->img->meta->precision) {
	case IRDM_ELEM_F64:
		wide_f64(e, n, rows, u);
		break;
	case IRDM_ELEM_F32:
		wide_f32(e, n, rows, u);
		break;
	default: /* the image checks admit f64, f32, f16 */
		wide_f16(e, n, rows, u);
		break;
	}
}

#else /* no AVX2 path on this target: the portable sum is used */

void irdm_fir_sum_wide(const struct irdm_engine *e, uint32_t n, const uint32_t *rows,
		       double (*u)[3])
{
	(void)e, (void)n, (void)rows, (void)u;
}

#endif
