/* SPDX-License-Identifier: MIT */
/*
 * A hybrid image's head sum (engine_head.c) with AVX2 and FMA, on the
 * processors that have them (irdm_wide_usable(), checked at init):
 *   acc(col) = sum_{s=1}^{H-1} sum_e D_s(e -> col) f_e[t-s],
 * each block by three fused multiply-adds (wide_block.h), two sets of
 * accumulators over alternate samples so that consecutive multiply-adds do
 * not wait on each other.  Same sum, different rounding than the portable
 * loop (a different order, fused products): 1e-14 apart (test_engine).
 */
#include <stdbool.h>

#include "engine_priv.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include "wide_block.h"

/* The blocks of one ring tick (age s) into acc. */
static WIDE_INLINE void tick_acc(const struct irdm_engine *e, uint32_t prec, const void *D,
				 const struct irdm_force_tick *t, uint32_t s, uint32_t col,
				 struct irdm_head_cache *cache, struct row_acc *acc)
{
	for (uint32_t n = 0; n < t->n; n++) {
		long k = irdm_head_cached_block(e, cache, t->col[n], col);
		__m256d p0, p1;
		double p2;
		if (k < 0)
			continue; /* a dropped block: no head either */
		force_pattern(t->f_n[n], 1.0, &p0, &p1, &p2);
		block_acc(D, prec, ((size_t)k * e->H + s) * 9, p0, p1, p2, acc);
	}
}

static WIDE_INLINE void head_wide(const struct irdm_engine *e, uint32_t prec, uint32_t col,
				  double u[3])
{
	const void *D = e->img->exact_head;
	const struct irdm_fir_ring *r = &e->ring;
	struct irdm_head_cache cache = { .n = 0 };
	/* two named sets (an indexed pair lives in memory, and every fused
	 * multiply-add then waits on a store) */
	struct row_acc a, b;
	uint32_t slot = r->head, s = 1; /* age 1; older ticks one slot down each */

	a.a0 = a.a1 = b.a0 = b.a1 = _mm256_setzero_pd();
	a.a2 = b.a2 = 0;
	for (; s + 1 < e->H; s += 2) {
		tick_acc(e, prec, D, &r->tick[slot], s, col, &cache, &a);
		slot = slot ? slot - 1 : e->H - 1;
		tick_acc(e, prec, D, &r->tick[slot], s + 1, col, &cache, &b);
		slot = slot ? slot - 1 : e->H - 1;
	}
	if (s < e->H)
		tick_acc(e, prec, D, &r->tick[slot], s, col, &cache, &a);
	a.a0 = _mm256_add_pd(a.a0, b.a0);
	a.a1 = _mm256_add_pd(a.a1, b.a1);
	a.a2 += b.a2;
	double v[3];
	row_fold(&a, v);
	for (int i = 0; i < 3; i++)
		u[i] += v[i];
}

static WIDE void head_f64(const struct irdm_engine *e, uint32_t col, double u[3])
{
	head_wide(e, IRDM_ELEM_F64, col, u);
}

static WIDE void head_f32(const struct irdm_engine *e, uint32_t col, double u[3])
{
	head_wide(e, IRDM_ELEM_F32, col, u);
}

static WIDE void head_f16(const struct irdm_engine *e, uint32_t col, double u[3])
{
	head_wide(e, IRDM_ELEM_F16, col, u);
}

void irdm_head_sum_wide(const struct irdm_engine *e, uint32_t col, double u[3])
{
	switch (e->img->meta->precision) {
	case IRDM_ELEM_F64:
		head_f64(e, col, u);
		break;
	case IRDM_ELEM_F32:
		head_f32(e, col, u);
		break;
	default: /* the image checks admit f64, f32, f16 */
		head_f16(e, col, u);
		break;
	}
}

#else /* no AVX2 path on this target: the portable sum is used */

void irdm_head_sum_wide(const struct irdm_engine *e, uint32_t col, double u[3])
{
	(void)e, (void)col, (void)u;
}

#endif
