/* SPDX-License-Identifier: MIT */
#include <stdlib.h>
#include <string.h>

#include "image/image_response.h"

int64_t irdm_image_node_of(const struct irdm_image *img, uint32_t mesh_node)
{
	for (uint32_t r = 0; r < img->meta->n_nodes; r++)
		if (img->nodes[r].mesh_node == mesh_node)
			return r;
	return -1;
}

int64_t irdm_image_col_of(const struct irdm_image *img, uint32_t image_node)
{
	for (uint32_t c = 0; c < img->meta->n_cols; c++)
		if (img->columns[c] == image_node)
			return c;
	return -1;
}

static void fir_response(const struct irdm_image *img, uint32_t col, uint32_t row,
			 size_t n, double *out)
{
	const struct irdm_meta *m = img->meta;
	size_t T = m->fir_length, base = ((size_t)col * m->n_nodes + row) * T * 9;

	memset(out, 0, n * 9 * sizeof(double));
	for (size_t s = 0; s < n && s < T; s++)
		for (int e = 0; e < 9; e++)
			out[9 * s + (size_t)e] = irdm_image_value(img, img->fir, col, base + 9 * s + (size_t)e);
}

static int modal_response(const struct irdm_image *img, uint32_t col, uint32_t row,
			  size_t n, double *out)
{
	const struct irdm_meta *m = img->meta;
	size_t K = m->n_modes, crow = img->columns[col];
	double *pr = malloc(3 * K * sizeof(double)), *pc = malloc(3 * K * sizeof(double));

	if (!pr || !pc) {
		free(pr);
		free(pc);
		return IRDM_ENOMEM;
	}
	for (size_t i = 0; i < 3; i++)
		for (size_t k = 0; k < K; k++) {
			pr[i * K + k] = irdm_elem_get(img->mode_shapes, m->precision, ((size_t)row * 3 + i) * K + k);
			pc[i * K + k] = irdm_elem_get(img->mode_shapes, m->precision, (crow * 3 + i) * K + k);
		}
	memset(out, 0, n * 9 * sizeof(double));
	for (size_t k = 0; k < K; k++) {
		const struct irdm_mode *md = &img->modes[k];
		double x0 = md->b[0], x1 = md->b[1];
		for (size_t s = 0; s < n; s++) {
			for (int i = 0; i < 3; i++)
				for (int j = 0; j < 3; j++)
					out[9 * s + 3 * (size_t)i + (size_t)j] += pr[(size_t)i * K + k] * pc[(size_t)j * K + k] * x0;
			double y0 = md->a[0] * x0 + md->a[1] * x1;
			x1 = md->a[2] * x0 + md->a[3] * x1;
			x0 = y0;
		}
	}
	/* the static correction is stored between columns only: the kept block
	 * plus the far field; a hybrid image spreads a kept block (far field
	 * included) over its head's samples */
	int64_t rc = img->corr_start && n > 0 ? irdm_image_col_of(img, row) : -1;
	long blk = rc >= 0 && img->exact_head ? irdm_image_corr_block(img, col, (uint32_t)rc) : -1;
	size_t H = m->head_samples;
	bool tr = false;
	size_t run = blk >= 0 ? irdm_image_head_run(img, (size_t)blk, &tr) : 0;
	for (size_t s = 0; blk >= 0 && s < H && s < n; s++)
		for (size_t e = 0; e < 9; e++)
			out[9 * s + e] += irdm_image_value(img, img->exact_head, col,
							   (run * H + s) * 9 + irdm_head_elem(tr, e));
	if (rc >= 0 && blk < 0) {
		double s[9];
		irdm_image_corr_value(img, col, (uint32_t)rc, s);
		for (int e = 0; e < 9; e++)
			out[e] += s[e];
	}
	free(pr);
	free(pc);
	return IRDM_OK;
}

int irdm_image_response(const struct irdm_image *img, uint32_t col, uint32_t row,
			size_t n_samples, double *out)
{
	if (img->meta->representation == IRDM_REPR_FIR) {
		fir_response(img, col, row, n_samples, out);
		return 0;
	}
	return modal_response(img, col, row, n_samples, out);
}
