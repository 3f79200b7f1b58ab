/* SPDX-License-Identifier: MIT */
/*
 * AVX2 + FMA building blocks of the history sums (fir_sum_avx2.c for FIR
 * images, engine_head_avx2.c for a hybrid image's head), for the
 * processors that have them (irdm_wide_usable(), checked at init).
 * A 3x3 block's nine elements load as two vectors of four and one scalar
 * and multiply the force laid out in the same pattern, (f0 f1 f2 f0)
 * (f1 f2 f0 f1)(f2), into nine accumulators folded once at the end.
 * Private to firmware/engine; include only under the x86-64 GNU C guard.
 */
#ifndef IRDM_ENGINE_WIDE_BLOCK_H
#define IRDM_ENGINE_WIDE_BLOCK_H

#include <stdint.h>
#include <string.h>

#include <immintrin.h>

#include "irdm/image_format.h"

#define WIDE __attribute__((target("avx2,fma,f16c")))
#define WIDE_INLINE inline __attribute__((always_inline, target("avx2,fma,f16c")))

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
	__m256d a0, a1; /* elements 0..3, 4..7 */
	double a2;      /* element 8 */
};

/* acc += R (9 elements at i) times the weighted force pattern p0 p1 p2 */
static WIDE_INLINE void block_acc(const void *fir, uint32_t prec, size_t i, __m256d p0,
				  __m256d p1, double p2, struct row_acc *acc)
{
	acc->a0 = _mm256_fmadd_pd(load4(fir, prec, i), p0, acc->a0);
	acc->a1 = _mm256_fmadd_pd(load4(fir, prec, i + 4), p1, acc->a1);
	acc->a2 = __builtin_fma(load1(fir, prec, i + 8), p2, acc->a2);
}

/*
 * The same for a block stored transposed (a hybrid image's HEAD_PAIRS):
 * its first eight elements loaded in the order 0 3 6 1 4 7 2 5, so that
 * the sums are those of the block upright.
 */
static WIDE_INLINE void block_acc_t(const void *fir, uint32_t prec, size_t i, __m256d p0,
				    __m256d p1, double p2, struct row_acc *acc)
{
	__m256d t0, t1;
	__m256 v;

	switch (prec) {
	case IRDM_ELEM_F64: {
		const double *d = (const double *)fir + i;
		t0 = _mm256_setr_pd(d[0], d[3], d[6], d[1]);
		t1 = _mm256_setr_pd(d[4], d[7], d[2], d[5]);
		break;
	}
	case IRDM_ELEM_F32:
		v = _mm256_loadu_ps((const float *)fir + i);
		goto permute;
	default:
		v = _mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)((const uint16_t *)fir + i)));
permute:
		v = _mm256_permutevar8x32_ps(v, _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5));
		t0 = _mm256_cvtps_pd(_mm256_castps256_ps128(v));
		t1 = _mm256_cvtps_pd(_mm256_extractf128_ps(v, 1));
		break;
	}
	acc->a0 = _mm256_fmadd_pd(t0, p0, acc->a0);
	acc->a1 = _mm256_fmadd_pd(t1, p1, acc->a1);
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

/* The force f laid out in a block's pattern: (f0 f1 f2 f0)(f1 f2 f0 f1)(f2). */
static WIDE_INLINE void force_pattern(const double f[3], double w, __m256d *p0, __m256d *p1,
				      double *p2)
{
	*p0 = _mm256_setr_pd(w * f[0], w * f[1], w * f[2], w * f[0]);
	*p1 = _mm256_setr_pd(w * f[1], w * f[2], w * f[0], w * f[1]);
	*p2 = w * f[2];
}

#endif /* IRDM_ENGINE_WIDE_BLOCK_H */
