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
#include <cpuid.h>
#include <immintrin.h>

#define WIDE __attribute__((target("avx2,fma,f16c")))
#define WIDE_INLINE inline __attribute__((always_inline, target("avx2,fma,f16c")))

/*
 * AVX2, FMA and F16C from CPUID, and the YMM state enabled by the kernel
 * (OSXSAVE, then XCR0's SSE and AVX bits).  By hand rather than with
 * __builtin_cpu_supports(): clang 14 does not know "f16c" there.
 */
bool irdm_fir_wide_usable(void)
{
	unsigned a, b, c, d, xcr0_lo, xcr0_hi;

	if (!__get_cpuid(1, &a, &b, &c, &d))
		return false;
	bool fma = c & (1u << 12), osxsave = c & (1u << 27), avx = c & (1u << 28),
	     f16c = c & (1u << 29);
	if (!(fma && osxsave && avx && f16c))
		return false;
	__asm__ volatile("xgetbv" : "=a"(xcr0_lo), "=d"(xcr0_hi) : "c"(0));
	if ((xcr0_lo & 6) != 6)
		return false;
	if (!__get_cpuid_count(7, 0, &a, &b, &c, &d))
		return false;
	return b & (1u << 5);                   /* AVX2 */
}

/* Four elements from i on, as doubles (f16: IEEE binary16, converted
 * exactly, as irdm_f16_to_f32() does). */
static WIDE_INLINE __m256d load4(const void *fir, uint32_t prec, size_t i)
{
	switch (prec) {
	case IRDM_ELEM_F64:
		return _mm256_loadu_pd((const double *)fir + i);
	case IRDM_ELEM_F32:
		return _mm256_cvtps_pd(_mm_loadu_ps((const float *)fir + i));
	default: {
		uint64_t h;
		memcpy(&h, (const uint16_t *)fir + i, sizeof(h));
		return _mm256_cvtps_pd(_mm_cvtph_ps(_mm_cvtsi64_si128((long long)h)));
	}
	}
}

static WIDE_INLINE double load1(const void *fir, uint32_t prec, size_t i)
{
	switch (prec) {
	case IRDM_ELEM_F64:
		return ((const double *)fir)[i];
	case IRDM_ELEM_F32:
		return ((const float *)fir)[i];
	default: {
		uint16_t h;
		memcpy(&h, (const uint16_t *)fir + i, sizeof(h));
		return _mm_cvtss_f32(_mm_cvtph_ps(_mm_cvtsi32_si128(h)));
	}
	}
}

struct row_acc {
	__m256d a0, a1;     /* elements 0..3, 4..7 */
	double a2;          /* element 8 */
};

/* acc += R (9 elements at i) times the weighted force pattern p0 p1 p2 */
static WIDE_INLINE void block_acc(const void *fir, uint32_t prec, size_t i, __m256d p0,
				  __m256d p1, double p2, struct row_acc *acc)
{
	acc->a0 = _mm256_fmadd_pd(load4(fir, prec, i), p0, acc->a0);
	acc->a1 = _mm256_fmadd_pd(load4(fir, prec, i + 4), p1, acc->a1);
	acc->a2 = __builtin_fma(load1(fir, prec, i + 8), p2, acc->a2);
}

/* u[i] = A[3i] + A[3i+1] + A[3i+2] */
static WIDE_INLINE void row_fold(const struct row_acc *acc, double u[3])
{
	double a[9];

	_mm256_storeu_pd(a, acc->a0);
	_mm256_storeu_pd(a + 4, acc->a1);
	a[8] = acc->a2;
	for (int i = 0; i < 3; i++)
		u[i] = a[3 * i] + a[3 * i + 1] + a[3 * i + 2];
}

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
			const double *f = t->f_n[n];
			__m256d p0 = _mm256_set_pd(w * f[0], w * f[2], w * f[1], w * f[0]);
			__m256d p1 = _mm256_set_pd(w * f[1], w * f[0], w * f[2], w * f[1]);
			double p2 = w * f[2];
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
	default:                    /* the image checks admit f64, f32, f16 */
		wide_f16(e, n, rows, u);
		break;
	}
}

#else /* no AVX2 path on this target: the portable sum is used */

bool irdm_fir_wide_usable(void)
{
	return false;
}

void irdm_fir_sum_wide(const struct irdm_engine *e, uint32_t n, const uint32_t *rows,
		       double (*u)[3])
{
	(void)e, (void)n, (void)rows, (void)u;
}

#endif
