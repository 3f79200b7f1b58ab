/* SPDX-License-Identifier: MIT */
/*
 * A hybrid image's head sum (engine_head.c) with AVX2 and FMA, on the
 * processors that have them (irdm_wide_usable(), checked at init):
 *   acc(col) = sum_{s=1}^{H-1} sum_e D_s(e -> col) f_e[t-s],
 * each block by three fused multiply-adds (wide_block.h), two sets of
 * accumulators over alternate samples so that consecutive multiply-adds do
 * not wait on each other.  A block stored as its mirror's run (HEAD_PAIRS)
 * loads transposed (block_acc_t()).  Same sum, different rounding than the
 * portable loop (a different order, fused products): 1e-14 apart
 * (test_engine).
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
		bool tr;
		if (k < 0)
			continue; /* a dropped block: no head either */
		size_t i = (irdm_image_head_run(e->img, (size_t)k, &tr) * e->H + s) * 9;
		force_pattern(t->f_n[n], 1.0, &p0, &p1, &p2);
		if (tr)
			block_acc_t(D, prec, i, p0, p1, p2, acc);
		else
			block_acc(D, prec, i, p0, p1, p2, acc);
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

static WIDE void ring_f64(const struct irdm_engine *e, uint32_t col, double u[3])
{
	head_wide(e, IRDM_ELEM_F64, col, u);
}

static WIDE void ring_f32(const struct irdm_engine *e, uint32_t col, double u[3])
{
	head_wide(e, IRDM_ELEM_F32, col, u);
}

static WIDE void ring_f16(const struct irdm_engine *e, uint32_t col, double u[3])
{
	head_wide(e, IRDM_ELEM_F16, col, u);
}

void irdm_head_ring_sum_wide(const struct irdm_engine *e, uint32_t col, double u[3])
{
	switch (e->img->meta->precision) {
	case IRDM_ELEM_F64:
		ring_f64(e, col, u);
		break;
	case IRDM_ELEM_F32:
		ring_f32(e, col, u);
		break;
	default: /* the image checks admit f64, f32, f16 */
		ring_f16(e, col, u);
		break;
	}
}

static inline size_t elem_bytes(uint32_t prec)
{
	switch (prec) {
	case IRDM_ELEM_F64:
		return 8;
	case IRDM_ELEM_F32:
		return 4;
	default:
		return 2;
	}
}

static WIDE_INLINE void fold_add(const struct row_acc *a, double u[3])
{
	double v[3];

	row_fold(a, v);
	for (int i = 0; i < 3; i++)
		u[i] += v[i];
}

/* Block d of one row, upright or transposed (tr: the same every sample). */
static WIDE_INLINE void row_block(const void *d, bool tr, uint32_t prec, size_t i, __m256d p0,
				  __m256d p1, double p2, struct row_acc *a)
{
	if (tr)
		block_acc_t(d, prec, i, p0, p1, p2, a);
	else
		block_acc(d, prec, i, p0, p1, p2, a);
}

/*
 * One run of a lane against the blocks d[0 .. n_rows - 1] (n_rows a
 * constant at each call site, as prec is; tr[r]: d[r] read transposed): a
 * sample's force loads once for every row.
 */
static WIDE_INLINE void run_acc(uint32_t prec, uint32_t n_rows, const void *const *d,
				const bool *tr, const struct head_run *run, struct row_acc *a0,
				struct row_acc *a1, struct row_acc *a2)
{
	const double *f = run->f;
	size_t i = (size_t)run->s * 9;

	for (uint32_t j = 0; j < run->n; j++, i += 9, f += HEAD_SAMPLE) {
		__m256d p0 = _mm256_loadu_pd(f), p1 = _mm256_loadu_pd(f + 4);
		double p2 = f[2];
		row_block(d[0], tr[0], prec, i, p0, p1, p2, a0);
		if (n_rows > 1)
			row_block(d[1], tr[1], prec, i, p0, p1, p2, a1);
		if (n_rows > 2)
			row_block(d[2], tr[2], prec, i, p0, p1, p2, a2);
	}
}

/*
 * The lanes' sums at n_rows columns in one pass.  A block dropped for one
 * of them reads zeros, which leave its sums as they were: each column's
 * sums take the same steps in the same order as when it is summed alone.
 */
static WIDE_INLINE void lanes_pass(const struct irdm_engine *e, uint32_t prec, uint32_t n_rows,
				   uint32_t n_spans, const struct head_span *sp,
				   const uint32_t *cols, double (*u)[3])
{
	size_t elem = elem_bytes(prec);
	const char *D = e->img->exact_head;
	/* one variable a row, not an array: they stay in registers */
	struct row_acc a0, a1, a2;

	a0.a0 = a0.a1 = a1.a0 = a1.a1 = a2.a0 = a2.a1 = _mm256_setzero_pd();
	a0.a2 = a1.a2 = a2.a2 = 0;
	for (uint32_t l = 0; l < n_spans; l++) {
		const void *d[3];
		bool kept = false, tr[3] = { false, false, false };
		for (uint32_t r = 0; r < n_rows; r++) {
			long k = irdm_image_corr_block(e->img, sp[l].col, cols[r]);
			d[r] = k < 0 ? e->lanes.zeros :
				       D + irdm_image_head_run(e->img, (size_t)k, &tr[r]) * e->H * 9 * elem;
			kept |= k >= 0;
		}
		if (!kept)
			continue; /* dropped blocks: no head either */
		for (uint32_t r = 0; r < sp[l].n_runs; r++)
			run_acc(prec, n_rows, d, tr, &sp[l].run[r], &a0, &a1, &a2);
	}
	fold_add(&a0, u[0]);
	if (n_rows > 1)
		fold_add(&a1, u[1]);
	if (n_rows > 2)
		fold_add(&a2, u[2]);
}

/* Three columns a pass, the last with what is left. */
static WIDE_INLINE void lanes_wide(const struct irdm_engine *e, uint32_t prec, uint32_t n_spans,
				   const struct head_span *sp, uint32_t n, const uint32_t *cols,
				   double (*u)[3])
{
	for (uint32_t v = 0; v < n; v += 3) {
		switch (n - v) {
		case 1:
			lanes_pass(e, prec, 1, n_spans, sp, cols + v, u + v);
			break;
		case 2:
			lanes_pass(e, prec, 2, n_spans, sp, cols + v, u + v);
			break;
		default:
			lanes_pass(e, prec, 3, n_spans, sp, cols + v, u + v);
			break;
		}
	}
}

static WIDE void lanes_f64(const struct irdm_engine *e, uint32_t n_spans,
			   const struct head_span *sp, uint32_t n, const uint32_t *cols,
			   double (*u)[3])
{
	lanes_wide(e, IRDM_ELEM_F64, n_spans, sp, n, cols, u);
}

static WIDE void lanes_f32(const struct irdm_engine *e, uint32_t n_spans,
			   const struct head_span *sp, uint32_t n, const uint32_t *cols,
			   double (*u)[3])
{
	lanes_wide(e, IRDM_ELEM_F32, n_spans, sp, n, cols, u);
}

static WIDE void lanes_f16(const struct irdm_engine *e, uint32_t n_spans,
			   const struct head_span *sp, uint32_t n, const uint32_t *cols,
			   double (*u)[3])
{
	lanes_wide(e, IRDM_ELEM_F16, n_spans, sp, n, cols, u);
}

void irdm_head_lane_sums_wide(const struct irdm_engine *e, uint32_t n_spans,
			      const struct head_span *sp, uint32_t n, const uint32_t *cols,
			      double (*u)[3])
{
	switch (e->img->meta->precision) {
	case IRDM_ELEM_F64:
		lanes_f64(e, n_spans, sp, n, cols, u);
		break;
	case IRDM_ELEM_F32:
		lanes_f32(e, n_spans, sp, n, cols, u);
		break;
	default: /* the image checks admit f64, f32, f16 */
		lanes_f16(e, n_spans, sp, n, cols, u);
		break;
	}
}

#else /* no AVX2 path on this target: the portable sum is used */

void irdm_head_ring_sum_wide(const struct irdm_engine *e, uint32_t col, double u[3])
{
	(void)e, (void)col, (void)u;
}

void irdm_head_lane_sums_wide(const struct irdm_engine *e, uint32_t n_spans,
			      const struct head_span *sp, uint32_t n, const uint32_t *cols,
			      double (*u)[3])
{
	(void)e, (void)n_spans, (void)sp, (void)n, (void)cols, (void)u;
}

#endif
