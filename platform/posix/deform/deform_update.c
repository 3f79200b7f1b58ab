/* SPDX-License-Identifier: MIT */
/*
 * Displacements of every image node from a snapshot (object frame), into
 * pos (3 n_nodes): modal u = Phi y + static correction, or the FIR sum.
 */
#include <cblas.h>

#include "worker_priv.h"

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
 * Residual compliance of the dropped modes, stored between columns only and
 * only where it matters: column c's kept blocks map a force at c to the
 * displacement of the columns in its row list.
 */
static void static_correction(const struct irdm_deform_worker *w,
			      const struct irdm_force_tick *f, double *pos)
{
	const struct irdm_image *img = w->img;
	const void *S = img->corr_blocks;

	for (uint32_t e = 0; e < f->n; e++) {
		const double *fe = f->f_n[e];
		uint32_t c = f->col[e];
		for (uint32_t k = img->corr_start[c]; k < img->corr_start[c + 1]; k++) {
			double *u = pos + 3 * (size_t)img->columns[img->corr_rows[k]];
			size_t base = (size_t)k * 9;
			for (size_t i = 0; i < 3; i++)
				u[i] += irdm_image_value(img, S, c, base + 3 * i) * fe[0] +
					irdm_image_value(img, S, c, base + 3 * i + 1) * fe[1] +
					irdm_image_value(img, S, c, base + 3 * i + 2) * fe[2];
		}
	}
}

/*
 * The correction's far field, U diag(lambda) U^T over the touchable DoFs:
 * the force nodes' weights g = diag(lambda) U_e^T f_e summed first
 * (O(rank) per node), then u_c += U_c g for every column (O(n_cols rank)).
 */
static void far_field(const struct irdm_deform_worker *w, const struct irdm_force_tick *f,
		      double *pos)
{
	const struct irdm_image *img = w->img;
	size_t r = img->corr_rank, nc = w->n_cols;
	const void *U = img->corr_u;
	double *g = w->far_g;

	if (!f->n)
		return;
	for (size_t k = 0; k < r; k++)
		g[k] = 0;
	for (uint32_t e = 0; e < f->n; e++) {
		size_t b = 3 * (size_t)f->col[e] * r;
		const double *fe = f->f_n[e];
		for (size_t k = 0; k < r; k++)
			g[k] += irdm_elem_get(img->corr_lambda, w->prec, k) *
				(irdm_elem_get(U, w->prec, b + k) * fe[0] +
				 irdm_elem_get(U, w->prec, b + r + k) * fe[1] +
				 irdm_elem_get(U, w->prec, b + 2 * r + k) * fe[2]);
	}
	for (size_t c = 0; c < nc; c++) {
		double *u = pos + 3 * (size_t)img->columns[c];
		for (size_t i = 0; i < 3; i++) {
			size_t b = (3 * c + i) * r;
			double s = 0;
			for (size_t k = 0; k < r; k++)
				s += irdm_elem_get(U, w->prec, b + k) * g[k];
			u[i] += s;
		}
	}
}

void deform_modal_product(struct irdm_deform_worker *w, double *pos)
{
	int n3 = 3 * (int)w->n_nodes, K = (int)w->n_modes;

	if (w->shapes_f64) {
		cblas_dgemv(CblasRowMajor, CblasNoTrans, n3, K, 1.0, w->shapes, K, w->y, 1,
			    0.0, pos, 1);
		return;
	}
	/* f32/f16 images: half the bytes to stream, well within display accuracy */
	cblas_sgemv(CblasRowMajor, CblasNoTrans, n3, K, 1.0f, w->shapes, K, w->y, 1, 0.0f,
		    w->uf, 1);
	for (int i = 0; i < n3; i++)
		pos[i] = w->uf[i];
}

/* y_k = q_k[t+1], the first component of each mode's state, in the
 * matrix's type */
static void modal_y(struct irdm_deform_worker *w, const double *x)
{
	uint32_t K = w->n_modes;

	if (w->shapes_f64) {
		double *y = w->y;
		for (uint32_t k = 0; k < K; k++)
			y[k] = x[2 * k];
	} else {
		float *y = w->y;
		for (uint32_t k = 0; k < K; k++)
			y[k] = (float)x[2 * k];
	}
}

void deform_modal(struct irdm_deform_worker *w, struct deform_snap *s, double *pos)
{
	modal_y(w, deform_payload(w->d, s));
	deform_modal_product(w, pos);
	sanitize(&s->f, w->n_cols);
	if (w->img->corr_start)
		static_correction(w, &s->f, pos);
	if (w->img->corr_rank)
		far_field(w, &s->f, pos);
	if (w->img->corr_clusters)
		deform_clusters(w, &s->f, pos);
}

/*
 * u_r = sum_{s < T} sum_e R[s](col_e -> r) f_e[t - s], row by row: for one
 * row and column the blocks of successive s are contiguous ([col][row][s]),
 * so each force node is a forward stream; the history itself stays in L1.
 * The history is the engine's ring, whose forces are in their columns'
 * storage scale (COLUMN_SCALE): the taps are read as stored, as the
 * engine's sums read them, and R' f' = R f.
 */
static void fir_row(const struct irdm_deform_worker *w, const struct irdm_force_tick *h,
		    uint32_t n_hist, uint32_t r, double *u)
{
	const void *R = w->img->fir;
	uint32_t prec = w->prec;
	size_t T = w->T, nn = w->n_nodes;
	double a0 = 0, a1 = 0, a2 = 0;

	for (uint32_t s = 0; s < n_hist; s++) {
		for (uint32_t e = 0; e < h[s].n; e++) {
			const double *f = h[s].f_n[e];
			size_t b = (((size_t)h[s].col[e] * nn + r) * T + s) * 9;
			a0 += irdm_elem_get(R, prec, b + 0) * f[0] +
			      irdm_elem_get(R, prec, b + 1) * f[1] +
			      irdm_elem_get(R, prec, b + 2) * f[2];
			a1 += irdm_elem_get(R, prec, b + 3) * f[0] +
			      irdm_elem_get(R, prec, b + 4) * f[1] +
			      irdm_elem_get(R, prec, b + 5) * f[2];
			a2 += irdm_elem_get(R, prec, b + 6) * f[0] +
			      irdm_elem_get(R, prec, b + 7) * f[1] +
			      irdm_elem_get(R, prec, b + 8) * f[2];
		}
	}
	u[0] = a0;
	u[1] = a1;
	u[2] = a2;
}

void deform_fir(struct irdm_deform_worker *w, struct deform_snap *s, double *pos)
{
	struct irdm_force_tick *h = deform_payload(w->d, s);

	for (uint32_t i = 0; i < s->n_hist; i++)
		sanitize(&h[i], w->n_cols);
	for (uint32_t r = 0; r < w->n_nodes; r++)
		fir_row(w, h, s->n_hist, r, pos + 3 * (size_t)r);
}
