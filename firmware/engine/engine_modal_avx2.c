/* SPDX-License-Identifier: MIT */
/*
 * The modes' recursion, a column's kept-modes displacement and their part
 * of an R[0] block (engine_modal.c) four modes at a time with AVX2, on the
 * processors that have it (irdm_wide_usable(), checked at init).  Every
 * product and sum is the portable loop's, in its order, and none is
 * fused: the two paths give the same bits (test_engine), so a machine
 * without AVX2 runs the same forces.
 *
 * The state is laid out (q, q') per mode, two modes to a vector; the
 * force's generalised component g comes four modes to a vector (the shapes
 * are [col][axis][Kp]) and is spread to (g_k, g_k, g_k+1, g_k+1) for each
 * half of the group.
 */
#include "engine_priv.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>

#define WIDE __attribute__((target("avx2")))
#define WIDE_INLINE inline __attribute__((always_inline, target("avx2")))

/* x where |x| is not below the flush level (NaN kept, as flush_tiny()) */
static WIDE_INLINE __m256d flush4(__m256d x)
{
	const __m256d level = _mm256_set1_pd(MODE_STATE_FLUSH);
	const __m256d sign = _mm256_set1_pd(-0.0);
	__m256d keep = _mm256_cmp_pd(_mm256_andnot_pd(sign, x), level, _CMP_NLT_UQ);

	return _mm256_and_pd(x, keep);
}

/* Two modes' step: x = flush(y + b g), then y = aq q + av q'. */
static WIDE_INLINE void step2(double *x, double *y, const struct mode_coef *c, __m256d gg)
{
	__m256d s = flush4(_mm256_add_pd(_mm256_loadu_pd(y),
					 _mm256_mul_pd(_mm256_loadu_pd(c->b), gg)));
	__m256d q = _mm256_permute_pd(s, 0x0); /* q_k q_k q_k+1 q_k+1 */
	__m256d v = _mm256_permute_pd(s, 0xf); /* q'_k q'_k q'_k+1 q'_k+1 */

	_mm256_storeu_pd(x, s);
	_mm256_storeu_pd(y, _mm256_add_pd(_mm256_mul_pd(_mm256_loadu_pd(c->aq), q),
					  _mm256_mul_pd(_mm256_loadu_pd(c->av), v)));
}

WIDE void irdm_modal_recur_wide(struct irdm_engine *e, const struct irdm_force_tick *f)
{
	const uint32_t Kp = e->Kp, nf = f->n;
	const double *p[IRDM_MAX_FORCE_NODES];
	__m256d fx[IRDM_MAX_FORCE_NODES], fy[IRDM_MAX_FORCE_NODES], fz[IRDM_MAX_FORCE_NODES];

	for (uint32_t n = 0; n < nf; n++) {
		p[n] = &e->phi[(size_t)f->col[n] * 3 * Kp];
		fx[n] = _mm256_set1_pd(f->f_n[n][0]);
		fy[n] = _mm256_set1_pd(f->f_n[n][1]);
		fz[n] = _mm256_set1_pd(f->f_n[n][2]);
	}
	for (uint32_t k = 0; k < Kp; k += MODE_LANES) {
		__m256d g = _mm256_setzero_pd();

		for (uint32_t n = 0; n < nf; n++) {
			__m256d t = _mm256_add_pd(_mm256_mul_pd(_mm256_loadu_pd(p[n] + k), fx[n]),
						  _mm256_mul_pd(_mm256_loadu_pd(p[n] + Kp + k), fy[n]));
			t = _mm256_add_pd(t, _mm256_mul_pd(_mm256_loadu_pd(p[n] + 2 * (size_t)Kp + k),
							   fz[n]));
			g = _mm256_add_pd(g, t);
		}
		step2(&e->x[2 * k], &e->y[2 * k], &e->coef[k / 2],
		      _mm256_permute4x64_pd(g, 0x50)); /* g0 g0 g1 g1 */
		step2(&e->x[2 * k + 4], &e->y[2 * k + 4], &e->coef[k / 2 + 1],
		      _mm256_permute4x64_pd(g, 0xfa)); /* g2 g2 g3 g3 */
	}
}

/* (a0 + a2) + (a1 + a3) */
static WIDE_INLINE double fold(__m256d a)
{
	__m128d h = _mm_add_pd(_mm256_castpd256_pd128(a), _mm256_extractf128_pd(a, 1));

	return _mm_cvtsd_f64(_mm_add_sd(h, _mm_unpackhi_pd(h, h)));
}

WIDE void irdm_modal_disp_wide(const struct irdm_engine *e, uint32_t col, double u[3])
{
	const uint32_t Kp = e->Kp;
	const double *p = &e->phi[(size_t)col * 3 * Kp];
	__m256d s0 = _mm256_setzero_pd(), s1 = s0, s2 = s0;

	for (uint32_t k = 0; k < Kp; k += MODE_LANES) {
		/* q of modes k..k+3 from (q, q') pairs */
		__m256d lo = _mm256_loadu_pd(&e->y[2 * k]), hi = _mm256_loadu_pd(&e->y[2 * k + 4]);
		__m256d q = _mm256_permute4x64_pd(_mm256_unpacklo_pd(lo, hi), 0xd8);

		s0 = _mm256_add_pd(s0, _mm256_mul_pd(_mm256_loadu_pd(p + k), q));
		s1 = _mm256_add_pd(s1, _mm256_mul_pd(_mm256_loadu_pd(p + Kp + k), q));
		s2 = _mm256_add_pd(s2, _mm256_mul_pd(_mm256_loadu_pd(p + 2 * (size_t)Kp + k), q));
	}
	u[0] = fold(s0);
	u[1] = fold(s1);
	u[2] = fold(s2);
}

WIDE void irdm_modal_r0_wide(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp,
			     double s[9])
{
	const uint32_t Kp = e->Kp;
	const double *pd = &e->phi[(size_t)col_disp * 3 * Kp];
	const double *pf = &e->phi[(size_t)col_force * 3 * Kp];
	__m256d acc[9];

	for (int n = 0; n < 9; n++)
		acc[n] = _mm256_setzero_pd();
	for (uint32_t k = 0; k < Kp; k += MODE_LANES) {
		/* b_k,q of modes k..k+3 from the pairs' (b_q, b_q') */
		__m256d b = _mm256_permute4x64_pd(_mm256_unpacklo_pd(_mm256_loadu_pd(e->coef[k / 2].b),
								     _mm256_loadu_pd(e->coef[k / 2 + 1].b)),
						  0xd8);
		__m256d d[3], f[3];

		for (int r = 0; r < 3; r++) {
			d[r] = _mm256_loadu_pd(pd + r * (size_t)Kp + k);
			f[r] = _mm256_loadu_pd(pf + r * (size_t)Kp + k);
		}
		for (int r = 0; r < 3; r++)
			for (int c = 0; c < 3; c++)
				acc[3 * r + c] = _mm256_add_pd(acc[3 * r + c],
							       _mm256_mul_pd(_mm256_mul_pd(d[r], f[c]), b));
	}
	for (int n = 0; n < 9; n++)
		s[n] = fold(acc[n]);
}

#else /* no AVX2 path on this target: modal_wide is never set */

void irdm_modal_recur_wide(struct irdm_engine *e, const struct irdm_force_tick *f)
{
	(void)e;
	(void)f;
}

void irdm_modal_disp_wide(const struct irdm_engine *e, uint32_t col, double u[3])
{
	(void)e;
	(void)col;
	u[0] = u[1] = u[2] = 0;
}

void irdm_modal_r0_wide(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp,
			double s[9])
{
	(void)e;
	(void)col_force;
	(void)col_disp;
	for (int n = 0; n < 9; n++)
		s[n] = 0;
}

#endif
