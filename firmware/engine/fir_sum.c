/* SPDX-License-Identifier: MIT */
/*
 * The FIR history term at several rows in one pass over the ring:
 *   U~_v = sum_{s=1}^{T-1} w[s] sum_e R[s](e -> v) f_e[t-s]
 * for every row v a tick needs (a triangle contact: its three vertices).
 * Each ring entry's force is read once and the rows' blocks at that age
 * read together, instead of one pass a row: one pass for up to four rows
 * (a triangle, two nodes), one more for each further four.
 *
 * Two rows share each step as the two lanes of a double vector (SSE2 on
 * x86-64; the compiler's generic vector code elsewhere); an odd last row
 * fills both lanes of its pair.  The element precision is fixed per image,
 * so each precision has its own loop, the switch hoisted out of it.
 *
 * Processors with AVX2 and FMA take fir_sum_avx2.c's path instead (chosen
 * at engine init); this one is the portable path and the reference for it.
 *
 * Bit-identical to one scalar pass a row: every accumulator gets its terms
 * in the same order (age, then ring entry), each term formed as
 * w * ((R_i0 f_0 + R_i1 f_1) + R_i2 f_2), and vector lanes round as
 * scalars do (no fused multiply-add without -march).
 */
#include <stdbool.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "irdm/precision.h"

#include "engine_priv.h"

#define ALWAYS_INLINE inline __attribute__((always_inline))

typedef double v2d __attribute__((vector_size(16)));
typedef float v2f __attribute__((vector_size(8)));
typedef float v4f __attribute__((vector_size(16)));

/* Elements k and k + 1 of one block, as doubles. */
static ALWAYS_INLINE v2d load2(const void *fir, uint32_t prec, size_t k)
{
	const uint8_t *p = fir;
	v2d d;
	v2f f;

	switch (prec) {
	case IRDM_ELEM_F64:
		memcpy(&d, p + k * 8, sizeof(d));
		return d;
	case IRDM_ELEM_F32:
		memcpy(&f, p + k * 4, sizeof(f));
		return __builtin_convertvector(f, v2d);
	default:
		return (v2d){ irdm_elem_get(fir, prec, k), irdm_elem_get(fir, prec, k + 1) };
	}
}

/* Elements k, k + 1 of the blocks at a and b: (a_k, b_k), (a_k+1, b_k+1). */
static ALWAYS_INLINE void load_two(const void *fir, uint32_t prec, size_t a, size_t b, size_t k,
				   v2d out[2])
{
	v2d x = load2(fir, prec, a + k), y = load2(fir, prec, b + k);

	out[0] = __builtin_shufflevector(x, y, 0, 2);
	out[1] = __builtin_shufflevector(x, y, 1, 3);
}

/*
 * f32 elements k..k+3 of the blocks at a and b as four lane pairs: the
 * floats interleaved first, then converted two at a time (converting
 * first and interleaving the doubles costs three instructions an element).
 */
static ALWAYS_INLINE void load_four_f32(const void *fir, size_t a, size_t b, size_t k,
					v2d out[4])
{
	const float *pa = (const float *)fir + a + k, *pb = (const float *)fir + b + k;
#ifdef __SSE2__
	/* gcc 12 turns the generic form below back into one scalar
	 * conversion an element; the intrinsics keep it packed */
	__m128 x = _mm_loadu_ps(pa), y = _mm_loadu_ps(pb);
	__m128 lo = _mm_unpacklo_ps(x, y), hi = _mm_unpackhi_ps(x, y);

	out[0] = _mm_cvtps_pd(lo);
	out[1] = _mm_cvtps_pd(_mm_movehl_ps(lo, lo));
	out[2] = _mm_cvtps_pd(hi);
	out[3] = _mm_cvtps_pd(_mm_movehl_ps(hi, hi));
#else
	v4f x, y, lo, hi;

	memcpy(&x, pa, sizeof(x));
	memcpy(&y, pb, sizeof(y));
	lo = __builtin_shufflevector(x, y, 0, 4, 1, 5);
	hi = __builtin_shufflevector(x, y, 2, 6, 3, 7);
	out[0] = __builtin_convertvector(__builtin_shufflevector(lo, lo, 0, 1), v2d);
	out[1] = __builtin_convertvector(__builtin_shufflevector(lo, lo, 2, 3), v2d);
	out[2] = __builtin_convertvector(__builtin_shufflevector(hi, hi, 0, 1), v2d);
	out[3] = __builtin_convertvector(__builtin_shufflevector(hi, hi, 2, 3), v2d);
#endif
}

/* The 9 elements of the blocks at a and b, lane 0 from a, lane 1 from b;
 * written out, since -O2 does not unroll the loops. */
static ALWAYS_INLINE void load_pair(const void *fir, uint32_t prec, size_t a, size_t b,
				    v2d out[9])
{
	if (prec == IRDM_ELEM_F32) {
		load_four_f32(fir, a, b, 0, out);
		load_four_f32(fir, a, b, 4, out + 4);
	} else {
		load_two(fir, prec, a, b, 0, out);
		load_two(fir, prec, a, b, 2, out + 2);
		load_two(fir, prec, a, b, 4, out + 4);
		load_two(fir, prec, a, b, 6, out + 6);
	}
	out[8] = (v2d){ irdm_elem_get(fir, prec, a + 8), irdm_elem_get(fir, prec, b + 8) };
}

/* acc += w * (R f) in both lanes. */
static ALWAYS_INLINE void pair_acc(const v2d r[9], const double f[3], v2d w, v2d acc[3])
{
	v2d f0 = { f[0], f[0] }, f1 = { f[1], f[1] }, f2 = { f[2], f[2] };

	acc[0] += w * ((r[0] * f0 + r[1] * f1) + r[2] * f2);
	acc[1] += w * ((r[3] * f0 + r[4] * f1) + r[5] * f2);
	acc[2] += w * ((r[6] * f0 + r[7] * f1) + r[8] * f2);
}

/*
 * One pass over the ring for one or two row pairs (two_pairs a constant at
 * each call site, as prec is): the accumulators stay in registers.  Ages
 * run newest first: age s is the slot s - 1 before the head.
 */
static ALWAYS_INLINE void sum_pass(const struct irdm_engine *e, uint32_t prec, bool two_pairs,
				   const uint32_t rows[4], double (*u)[3])
{
	const void *fir = e->img->fir;
	const struct irdm_fir_ring *r = &e->ring;
	uint32_t slot = r->head, T = e->T;
	v2d a[3] = { { 0, 0 }, { 0, 0 }, { 0, 0 } }, b[3] = { { 0, 0 }, { 0, 0 }, { 0, 0 } };

	for (uint32_t s = 1; s < T; s++) {
		const struct irdm_force_tick *t = &r->tick[slot];
		v2d w = { e->tail_w[s], e->tail_w[s] };
		for (uint32_t n = 0; n < t->n; n++) {
			size_t pair0 = (size_t)t->col[n] * e->n_nodes;
			v2d blk[9];
			load_pair(fir, prec, ((pair0 + rows[0]) * T + s) * 9,
				  ((pair0 + rows[1]) * T + s) * 9, blk);
			pair_acc(blk, t->f_n[n], w, a);
			if (!two_pairs)
				continue;
			load_pair(fir, prec, ((pair0 + rows[2]) * T + s) * 9,
				  ((pair0 + rows[3]) * T + s) * 9, blk);
			pair_acc(blk, t->f_n[n], w, b);
		}
		slot = slot ? slot - 1 : T - 1;
	}
	for (int i = 0; i < 3; i++) {
		u[0][i] = a[i][0];
		u[1][i] = a[i][1];
		u[2][i] = b[i][0];
		u[3][i] = b[i][1];
	}
}

#define SUM_PASSES(name, prec) \
	static void name(const struct irdm_engine *e, uint32_t n_pairs, const uint32_t *rows, \
			 double(*u)[3]) \
	{ \
		for (uint32_t p = 0; p < n_pairs; p += 2) { \
			if (n_pairs - p >= 2) \
				sum_pass(e, prec, true, rows + 2 * p, u + 2 * p); \
			else \
				sum_pass(e, prec, false, rows + 2 * p, u + 2 * p); \
		} \
	}

SUM_PASSES(sum_f64, IRDM_ELEM_F64)
SUM_PASSES(sum_f32, IRDM_ELEM_F32)
SUM_PASSES(sum_f16, IRDM_ELEM_F16)

void irdm_fir_free_disps(const struct irdm_engine *e, uint32_t n, const uint32_t *cols,
			 double (*u)[3])
{
	/* padded to whole passes of two pairs; an odd last row fills both
	 * lanes of its pair */
	uint32_t rows[IRDM_MAX_FORCE_NODES + 4], n_pairs = (n + 1) / 2;
	double acc[IRDM_MAX_FORCE_NODES + 4][3];

	for (uint32_t v = 0; v < n; v++)
		rows[v] = e->img->columns[cols[v]];
	if (e->fir_wide) {
		irdm_fir_sum_wide(e, n, rows, u);
		return;
	}
	for (uint32_t v = n; v < 4 * ((n + 3) / 4); v++)
		rows[v] = n ? rows[n - 1] : 0;
	switch (e->img->meta->precision) {
	case IRDM_ELEM_F64:
		sum_f64(e, n_pairs, rows, acc);
		break;
	case IRDM_ELEM_F32:
		sum_f32(e, n_pairs, rows, acc);
		break;
	default: /* the image checks admit f64, f32, f16 */
		sum_f16(e, n_pairs, rows, acc);
		break;
	}
	memcpy(u, acc, (size_t)n * sizeof(acc[0]));
}
