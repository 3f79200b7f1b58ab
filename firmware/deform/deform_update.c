/* SPDX-License-Identifier: MIT */
/*
 * Displacements of every image node from a snapshot (object frame), into
 * pos (3 n_nodes): modal u = Phi y + static correction, or the FIR sum.
 */
#include <cblas.h>

#include "deform_priv.h"

/* Element i of response data of any precision (the switch is predictable). */
static inline double elem(const void *p, uint32_t prec, size_t i)
{
	switch (prec) {
	case IRDM_ELEM_F64:
		return ((const double *)p)[i];
	case IRDM_ELEM_F32:
		return ((const float *)p)[i];
	default:
		return irdm_f16_to_f32(((const uint16_t *)p)[i]);
	}
}

/* Drop force nodes whose column is out of range: the image has no data for
 * them, and reading it would leave the image. */
static void sanitize(struct irdm_force_tick *f, uint32_t n_cols)
{
	uint32_t k = 0;

	for (uint32_t e = 0; e < f->n; e++) {
		if (f->col[e] >= n_cols)
			continue;
		f->col[k] = f->col[e];
		for (int j = 0; j < 3; j++)
			f->f_n[k][j] = f->f_n[e][j];
		k++;
	}
	f->n = k;
}

/*
 * Residual compliance of the dropped modes, stored between columns only:
 * block (c, c') maps a force at column c to the displacement of column c'.
 */
static void static_correction(const struct irdm_deform *d, const struct irdm_force_tick *f,
			      double *pos)
{
	const struct irdm_image *img = d->img;
	size_t nc = d->n_cols;

	for (uint32_t e = 0; e < f->n; e++) {
		const double *fe = f->f_n[e];
		size_t base = (size_t)f->col[e] * nc * 9;
		for (size_t c2 = 0; c2 < nc; c2++, base += 9) {
			double *u = pos + 3 * (size_t)img->columns[c2];
			for (size_t i = 0; i < 3; i++)
				u[i] += elem(img->static_corr, d->prec, base + 3 * i) * fe[0] +
					elem(img->static_corr, d->prec, base + 3 * i + 1) * fe[1] +
					elem(img->static_corr, d->prec, base + 3 * i + 2) * fe[2];
		}
	}
}

static void modal_gemv(struct irdm_deform *d, const double *x, double *pos)
{
	int n3 = 3 * (int)d->n_nodes, K = (int)d->n_modes;

	/* y_k = q_k[t+1], the first component of each mode's state */
	if (d->shapes_f64) {
		double *y = d->y;
		for (int k = 0; k < K; k++)
			y[k] = x[2 * k];
		cblas_dgemv(CblasRowMajor, CblasNoTrans, n3, K, 1.0, d->shapes, K, y, 1,
			    0.0, pos, 1);
	} else {
		/* f32/f16 images: half the bytes to stream, well within display
		 * accuracy */
		float *y = d->y;
		for (int k = 0; k < K; k++)
			y[k] = (float)x[2 * k];
		cblas_sgemv(CblasRowMajor, CblasNoTrans, n3, K, 1.0f, d->shapes, K, y, 1,
			    0.0f, d->uf, 1);
		for (int i = 0; i < n3; i++)
			pos[i] = d->uf[i];
	}
}

/*
 * One product at init: OpenBLAS sets up its buffers and the shapes come
 * into cache on the first call, which then is not the first frame's cost.
 */
void deform_warmup(struct irdm_deform *d)
{
	struct deform_snap *s = (struct deform_snap *)d->slot[d->front];

	if (d->repr == IRDM_REPR_MODAL)
		modal_gemv(d, deform_payload(d, s), d->frame_pos);
}

void deform_modal(struct irdm_deform *d, struct deform_snap *s, double *pos)
{
	modal_gemv(d, deform_payload(d, s), pos);
	sanitize(&s->f, d->n_cols);
	if (d->img->static_corr)
		static_correction(d, &s->f, pos);
}

/*
 * u_r = sum_{s < T} sum_e R[s](col_e -> r) f_e[t - s], row by row: for one
 * row and column the blocks of successive s are contiguous ([col][row][s]),
 * so each force node is a forward stream; the history itself stays in L1.
 */
static void fir_row(const struct irdm_deform *d, const struct irdm_force_tick *h,
		    uint32_t n_hist, uint32_t r, double *u)
{
	const void *R = d->img->fir;
	size_t T = d->T, nn = d->n_nodes;
	double a0 = 0, a1 = 0, a2 = 0;

	for (uint32_t s = 0; s < n_hist; s++) {
		for (uint32_t e = 0; e < h[s].n; e++) {
			const double *f = h[s].f_n[e];
			size_t b = (((size_t)h[s].col[e] * nn + r) * T + s) * 9;
			a0 += elem(R, d->prec, b + 0) * f[0] + elem(R, d->prec, b + 1) * f[1] +
			      elem(R, d->prec, b + 2) * f[2];
			a1 += elem(R, d->prec, b + 3) * f[0] + elem(R, d->prec, b + 4) * f[1] +
			      elem(R, d->prec, b + 5) * f[2];
			a2 += elem(R, d->prec, b + 6) * f[0] + elem(R, d->prec, b + 7) * f[1] +
			      elem(R, d->prec, b + 8) * f[2];
		}
	}
	u[0] = a0;
	u[1] = a1;
	u[2] = a2;
}

void deform_fir(struct irdm_deform *d, struct deform_snap *s, double *pos)
{
	struct irdm_force_tick *h = deform_payload(d, s);

	for (uint32_t i = 0; i < s->n_hist; i++)
		sanitize(&h[i], d->n_cols);
	for (uint32_t r = 0; r < d->n_nodes; r++)
		fir_row(d, h, s->n_hist, r, pos + 3 * (size_t)r);
}
