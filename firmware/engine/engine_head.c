/* SPDX-License-Identifier: MIT */
/*
 * The hybrid representation's head (image section EXACT_HEAD): the
 * response of the modes a modal image drops, over its H = head_samples
 * samples (exact over the first half, tapered over the second), between
 * touchable nodes whose static-correction block was kept.  On top of the
 * kept modes' recursion it adds
 *   u_v[t] += sum_{s=0}^{H-1} D_s(e -> v) f_e[t-s],
 * with D_0 in R[0] (in place of the whole correction block, which is the
 * sum of the D_s) and the older samples summed over the last H - 1 ticks'
 * forces, as the lanes hold them by column (head_lanes.c), or from the
 * ring of ticks while the lanes miss one.  A block stored as its
 * mirror's run (HEAD_PAIRS) is read transposed: its loads permuted, the
 * same sums.  Modal images without a head have H = 0 and never reach
 * either.
 */
#include "engine_priv.h"

/* D_s of kept block k, a block of force column col, into blk (row-major 3x3). */
static void head_block(const struct irdm_engine *e, uint32_t col, long k, uint32_t s, double blk[9])
{
	bool tr;
	size_t base = (irdm_image_head_run(e->img, (size_t)k, &tr) * e->H + s) * 9;

	for (size_t i = 0; i < 9; i++)
		blk[i] = irdm_image_value(e->img, e->img->exact_head, col,
					  base + irdm_head_elem(tr, i));
}

bool irdm_head_r0(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp, double blk[9])
{
	long k = irdm_image_corr_block(e->img, col_force, col_disp);

	if (k < 0)
		return false; /* dropped: the far field alone, instantly */
	head_block(e, col_force, k, 0, blk);
	return true;
}

/* The element each of a block's nine sums loads, upright and transposed:
 * irdm_head_elem() as a table, an indexed load in the sums' loops. */
static const uint8_t block_elem[2][9] = { { 0, 1, 2, 3, 4, 5, 6, 7, 8 },
					  { 0, 3, 6, 1, 4, 7, 2, 5, 8 } };

/*
 * acc[3 i + j] += sum over the ring's ticks of age s in [1, H) of
 * D_s(k_s)[i][j] f_j, one loop per storage type so that the inner loop is
 * loads and multiply-adds only (nine independent sums): a long head is
 * hundreds of samples at every contact node every tick.
 */
#define HEAD_SUM(NAME, TYPE, LOAD) \
	static void NAME(const struct irdm_engine *e, uint32_t col, double acc[9]) \
	{ \
		const TYPE *D = e->img->exact_head; \
		const struct irdm_fir_ring *r = &e->ring; \
		struct irdm_head_cache cache = { .n = 0 }; \
		double a0 = 0, a1 = 0, a2 = 0, a3 = 0, a4 = 0, a5 = 0, a6 = 0, a7 = 0, a8 = 0; \
		uint32_t slot = r->head; /* age 1; older ticks one slot down each */ \
\
		for (uint32_t s = 1; s < e->H; s++) { \
			const struct irdm_force_tick *t = &r->tick[slot]; \
			slot = slot ? slot - 1 : e->H - 1; \
			for (uint32_t n = 0; n < t->n; n++) { \
				long k = irdm_head_cached_block(e, &cache, t->col[n], col); \
				bool tr; \
				if (k < 0) \
					continue; /* a dropped block: no head either */ \
				size_t run = irdm_image_head_run(e->img, (size_t)k, &tr); \
				const TYPE *d = &D[(run * e->H + s) * 9]; \
				const uint8_t *x = block_elem[tr]; \
				double f0 = t->f_n[n][0], f1 = t->f_n[n][1], f2 = t->f_n[n][2]; \
				a0 += LOAD(d[x[0]]) * f0, a1 += LOAD(d[x[1]]) * f1; \
				a2 += LOAD(d[x[2]]) * f2, a3 += LOAD(d[x[3]]) * f0; \
				a4 += LOAD(d[x[4]]) * f1, a5 += LOAD(d[x[5]]) * f2; \
				a6 += LOAD(d[x[6]]) * f0, a7 += LOAD(d[x[7]]) * f1; \
				a8 += LOAD(d[x[8]]) * f2; \
			} \
		} \
		acc[0] = a0, acc[1] = a1, acc[2] = a2, acc[3] = a3, acc[4] = a4; \
		acc[5] = a5, acc[6] = a6, acc[7] = a7, acc[8] = a8; \
	}

#define LOAD_F(x) ((double)(x))
#define LOAD_H(x) ((double)irdm_f16_to_f32(x))
HEAD_SUM(head_sum_f64, double, LOAD_F)
HEAD_SUM(head_sum_f32, float, LOAD_F)
HEAD_SUM(head_sum_f16, uint16_t, LOAD_H)

void irdm_head_ring_sum(const struct irdm_engine *e, uint32_t col, double u[3])
{
	double acc[9];

	switch (e->img->meta->precision) {
	case IRDM_ELEM_F64:
		head_sum_f64(e, col, acc);
		break;
	case IRDM_ELEM_F32:
		head_sum_f32(e, col, acc);
		break;
	default:
		head_sum_f16(e, col, acc);
		break;
	}
	for (int i = 0; i < 3; i++)
		u[i] += acc[3 * i] + acc[3 * i + 1] + acc[3 * i + 2];
}

/*
 * acc[3 i + j] += sum over a run's samples of D_s[i][j] f_j: nine sums
 * side by side, in the order of the ages (x: block_elem[transposed]).
 */
#define RUN_SUM(NAME, TYPE, LOAD) \
	static void NAME(const TYPE *d, const uint8_t *x, const struct head_run *r, \
			 double acc[9]) \
	{ \
		const double *f = r->f; \
		double a0 = acc[0], a1 = acc[1], a2 = acc[2], a3 = acc[3], a4 = acc[4]; \
		double a5 = acc[5], a6 = acc[6], a7 = acc[7], a8 = acc[8]; \
\
		d += (size_t)r->s * 9; \
		for (uint32_t i = 0; i < r->n; i++, d += 9, f += HEAD_SAMPLE) { \
			double f0 = f[0], f1 = f[1], f2 = f[2]; \
			a0 += LOAD(d[x[0]]) * f0, a1 += LOAD(d[x[1]]) * f1; \
			a2 += LOAD(d[x[2]]) * f2, a3 += LOAD(d[x[3]]) * f0; \
			a4 += LOAD(d[x[4]]) * f1, a5 += LOAD(d[x[5]]) * f2; \
			a6 += LOAD(d[x[6]]) * f0, a7 += LOAD(d[x[7]]) * f1; \
			a8 += LOAD(d[x[8]]) * f2; \
		} \
		acc[0] = a0, acc[1] = a1, acc[2] = a2, acc[3] = a3, acc[4] = a4; \
		acc[5] = a5, acc[6] = a6, acc[7] = a7, acc[8] = a8; \
	}

RUN_SUM(run_sum_f64, double, LOAD_F)
RUN_SUM(run_sum_f32, float, LOAD_F)
RUN_SUM(run_sum_f16, uint16_t, LOAD_H)

/* The lanes' sum at one column: each lane whose block to col was kept. */
static void lane_sum(const struct irdm_engine *e, uint32_t n_spans, const struct head_span *sp,
		     uint32_t col, double u[3])
{
	uint32_t prec = e->img->meta->precision;
	double acc[9] = { 0 };

	for (uint32_t l = 0; l < n_spans; l++) {
		long k = irdm_image_corr_block(e->img, sp[l].col, col);
		bool tr;
		if (k < 0)
			continue; /* a dropped block: no head either */
		size_t base = irdm_image_head_run(e->img, (size_t)k, &tr) * e->H * 9;
		const uint8_t *x = block_elem[tr];
		for (uint32_t r = 0; r < sp[l].n_runs; r++) {
			if (prec == IRDM_ELEM_F64)
				run_sum_f64((const double *)e->img->exact_head + base, x, &sp[l].run[r],
					    acc);
			else if (prec == IRDM_ELEM_F32)
				run_sum_f32((const float *)e->img->exact_head + base, x, &sp[l].run[r],
					    acc);
			else
				run_sum_f16((const uint16_t *)e->img->exact_head + base, x,
					    &sp[l].run[r], acc);
		}
	}
	for (int i = 0; i < 3; i++)
		u[i] += acc[3 * i] + acc[3 * i + 1] + acc[3 * i + 2];
}

void irdm_head_free_disps(const struct irdm_engine *e, uint32_t n, const uint32_t *cols,
			  double (*u)[3])
{
	struct head_span sp[HEAD_LANES];
	int n_spans = irdm_head_spans(e, sp);

	if (n_spans < 0) {
		for (uint32_t v = 0; v < n; v++) {
			if (e->head_wide)
				irdm_head_ring_sum_wide(e, cols[v], u[v]);
			else
				irdm_head_ring_sum(e, cols[v], u[v]);
		}
		return;
	}
	if (e->head_wide) {
		irdm_head_lane_sums_wide(e, (uint32_t)n_spans, sp, n, cols, u);
		return;
	}
	for (uint32_t v = 0; v < n; v++)
		lane_sum(e, (uint32_t)n_spans, sp, cols[v], u[v]);
}

void irdm_head_apply(struct irdm_engine *e, const struct irdm_force_tick *f)
{
	struct irdm_fir_ring *r = &e->ring;

	if (e->H < 2)
		return;
	r->head = (r->head + 1) % e->H;
	irdm_ring_put(e, &r->tick[r->head], f);
	/* the lanes hold the ring's values: scaled as the stored columns */
	irdm_head_lanes_apply(e, &r->tick[r->head]);
	/* the tick's force norms, once: the displacement bound reads them
	 * every tick for every age */
	double sum = 0;
	for (uint32_t n = 0; n < f->n; n++)
		sum += irdm_v3_norm(f->f_n[n]);
	e->head_norm[r->head] = sum;
}

void irdm_head_bound_init(const struct irdm_engine *e, double *w)
{
	const struct irdm_image *img = e->img;
	uint32_t n_blocks = img->corr_start[e->n_cols];

	for (uint32_t s = 0; s < e->H; s++) {
		double mx = 0;
		for (uint32_t k = 0, c = 0; k < n_blocks; k++) {
			double blk[9], ss = 0;
			while (k >= img->corr_start[c + 1])
				c++;
			head_block(e, c, k, s, blk);
			for (int i = 0; i < 9; i++)
				ss += blk[i] * blk[i];
			mx = fmax(mx, sqrt(ss));
		}
		w[s] = mx;
	}
}

double irdm_head_bound(const struct irdm_engine *e, const double *w)
{
	uint32_t slot = e->ring.head; /* age 1; older ticks one slot down each */
	double b = 0;

	for (uint32_t s = 1; s < e->H; s++) {
		b += w[s] * e->head_norm[slot];
		slot = slot ? slot - 1 : e->H - 1;
	}
	return b;
}
