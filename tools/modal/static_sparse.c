/* SPDX-License-Identifier: MIT */
/*
 * Block-sparse static correction.  The residual compliance of the dropped
 * (high) modes, S = G - Phi_K Lambda_K^-1 Phi_K^T, is local: it decays with
 * the distance between the two nodes, so most of the n_cols^2 blocks are
 * noise next to the diagonal.  Columns are solved in batches with one
 * factor (irdm_compliance_columns), the modal part is one GEMM per batch,
 * and each pair (r <= c) is judged once, when the later of the two is
 * solved and both diagonal blocks are known; the kept blocks are mirrored
 * at the end.  Nothing of size n_cols^2 is ever held.
 */
#include <cblas.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "modal/response.h"
#include "modal/static_sparse.h"

/* Columns per batch: 3 x 64 right-hand sides keep CHOLMOD's supernodal
 * solve in BLAS 3 while X stays a few tens of MB on 10^4 DoFs. */
#define BATCH_COLS 64

/* Kept blocks of the lower triangle (r <= c), in order of c, then r. */
struct lower {
	uint32_t *col, *row;
	double *blk;
	size_t n, cap;
};

/* One batch of columns [c0, c1) and what judging it needs. */
struct batch {
	const struct irdm_modes *m;
	const int64_t *col_dofs;
	size_t c0, c1;
	const double *X;    /* n x n_in compliance columns */
	const size_t *slot; /* 3 (c - c0) + j -> column of X, or SIZE_MAX */
	const double *mod;  /* 3 c1 x 3 (c1 - c0): modal compliance */
	double *diag_norm;  /* n_cols: |S_cc|, filled batch by batch */
};

static int lower_push(struct lower *l, size_t c, size_t r, const double b[9])
{
	if (l->n == l->cap) {
		size_t cap = l->cap ? 2 * l->cap : 4096;
		uint32_t *col = realloc(l->col, cap * sizeof(*col));
		if (col)
			l->col = col;
		uint32_t *row = realloc(l->row, cap * sizeof(*row));
		if (row)
			l->row = row;
		double *blk = realloc(l->blk, cap * 9 * sizeof(*blk));
		if (blk)
			l->blk = blk;
		if (!col || !row || !blk)
			return IRDM_ENOMEM;
		l->cap = cap;
	}
	l->col[l->n] = (uint32_t)c;
	l->row[l->n] = (uint32_t)r;
	memcpy(&l->blk[9 * l->n], b, 9 * sizeof(double));
	l->n++;
	return IRDM_OK;
}

static void lower_free(struct lower *l)
{
	free(l->col);
	free(l->row);
	free(l->blk);
}

int irdm_corr_modal_basis(const struct irdm_modes *m, const int64_t *col_dofs, size_t n_cols,
			  double **P, double **Ps)
{
	size_t K = m->n_modes, n = m->n;

	*P = malloc(3 * n_cols * (K ? K : 1) * sizeof(double));
	*Ps = malloc(3 * n_cols * (K ? K : 1) * sizeof(double));
	if (!*P || !*Ps)
		return IRDM_ENOMEM;
	for (size_t d = 0; d < 3 * n_cols; d++)
		for (size_t k = 0; k < K; k++) {
			double v = col_dofs[d] < 0 ? 0.0 : m->phi[k * n + (size_t)col_dofs[d]];
			(*P)[d * K + k] = v;
			(*Ps)[d * K + k] = v / m->omega2[k];
		}
	return IRDM_OK;
}

/* Block (force at column c, displacement at column r) of S. */
static void block(const struct batch *bt, size_t c, size_t r, double out[9])
{
	size_t n = bt->m->n, nb = 3 * (bt->c1 - bt->c0);

	for (size_t i = 0; i < 3; i++)
		for (size_t j = 0; j < 3; j++) {
			int64_t ri = bt->col_dofs[3 * r + i];
			size_t s = bt->slot[3 * (c - bt->c0) + j];
			out[3 * i + j] = ri < 0 || s == SIZE_MAX ? 0.0 :
								   bt->X[s * n + (size_t)ri] -
									   bt->mod[(3 * r + i) * nb + 3 * (c - bt->c0) + j];
		}
}

static double frob(const double b[9])
{
	double s = 0;

	for (int i = 0; i < 9; i++)
		s += b[i] * b[i];
	return sqrt(s);
}

/* S is symmetric: its diagonal blocks too, exactly (R[0] is then). */
static void symmetrise(double b[9])
{
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < i; j++)
			b[3 * i + j] = b[3 * j + i] = 0.5 * (b[3 * i + j] + b[3 * j + i]);
}

/* Judge every pair (c in the batch, r <= c); keep the diagonal always. */
static int judge_batch(const struct batch *bt, double tol, struct lower *l, double *max_rel)
{
	double b[9];

	for (size_t c = bt->c0; c < bt->c1; c++) {
		block(bt, c, c, b);
		bt->diag_norm[c] = frob(b);
	}
	for (size_t c = bt->c0; c < bt->c1; c++)
		for (size_t r = 0; r <= c; r++) {
			double scale = sqrt(bt->diag_norm[c] * bt->diag_norm[r]), nrm;
			block(bt, c, r, b);
			if (r == c)
				symmetrise(b);
			nrm = frob(b);
			if (r != c && (nrm == 0 || nrm < tol * scale)) {
				if (scale > 0 && nrm / scale > *max_rel)
					*max_rel = nrm / scale;
				continue;
			}
			if (lower_push(l, c, r, b))
				return IRDM_ENOMEM;
		}
	return IRDM_OK;
}

/* The free DoFs of columns [c0, c1) into in[], their X column into slot[]. */
static size_t batch_inputs(const int64_t *col_dofs, size_t c0, size_t c1, int64_t *in,
			   size_t *slot)
{
	size_t n_in = 0;

	for (size_t d = 3 * c0; d < 3 * c1; d++) {
		slot[d - 3 * c0] = col_dofs[d] < 0 ? SIZE_MAX : n_in;
		if (col_dofs[d] >= 0)
			in[n_in++] = col_dofs[d];
	}
	return n_in;
}

/* Lower triangle -> both triangles, by column, rows increasing: column c
 * holds its own (r <= c) first, then the mirrors (c' > c, transposed). */
static int mirror(const struct lower *l, struct irdm_corr_sparse *s)
{
	size_t nc = s->n_cols, *fill = calloc(nc ? nc : 1, sizeof(size_t));

	s->n_blocks = 2 * l->n - nc;
	s->start = calloc(nc + 1 + s->n_blocks, sizeof(uint32_t));
	s->blocks = malloc(s->n_blocks * 9 * sizeof(double));
	if (!fill || !s->start || !s->blocks) {
		free(fill);
		return IRDM_ENOMEM;
	}
	for (size_t k = 0; k < l->n; k++) {
		s->start[l->col[k] + 1]++;
		if (l->row[k] != l->col[k])
			s->start[l->row[k] + 1]++;
	}
	for (size_t c = 0; c < nc; c++)
		s->start[c + 1] += s->start[c];
	s->rows = s->start + nc + 1;
	for (size_t k = 0; k < l->n; k++) { /* own blocks, in order */
		size_t c = l->col[k], at = s->start[c] + fill[c]++;
		s->rows[at] = l->row[k];
		memcpy(&s->blocks[9 * at], &l->blk[9 * k], 9 * sizeof(double));
	}
	for (size_t k = 0; k < l->n; k++) { /* mirrors: c' increasing */
		size_t r = l->row[k], at;
		if (r == l->col[k])
			continue;
		at = s->start[r] + fill[r]++;
		s->rows[at] = l->col[k];
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++)
				s->blocks[9 * at + 3 * i + j] = l->blk[9 * k + 3 * j + i];
	}
	free(fill);
	return IRDM_OK;
}

int irdm_static_correction_sparse(const struct irdm_fem *fem, const struct irdm_modes *m,
				  bool floating, const int64_t *col_dofs, size_t n_cols,
				  double tol, irdm_progress_fn progress, void *ctx,
				  struct irdm_corr_sparse *out, char *err, size_t errlen)
{
	size_t n = m->n, K = m->n_modes, B = BATCH_COLS < n_cols ? BATCH_COLS : n_cols;
	struct irdm_compliance *comp = NULL;
	struct lower low = { 0 };
	double *P = NULL, *Ps = NULL, *X = malloc(n * 3 * (B ? B : 1) * sizeof(double));
	double *mod = malloc(3 * n_cols * 3 * (B ? B : 1) * sizeof(double));
	double *diag_norm = calloc(n_cols ? n_cols : 1, sizeof(double));
	int64_t *in = malloc(3 * (B ? B : 1) * sizeof(int64_t));
	size_t *slot = malloc(3 * (B ? B : 1) * sizeof(size_t));
	size_t n_loads = 0, n_done = 0;
	const double *given;
	int ret;

	memset(out, 0, sizeof(*out));
	out->n_cols = n_cols;
	if (!X || !mod || !diag_norm || !in || !slot || irdm_corr_modal_basis(m, col_dofs, n_cols, &P, &Ps))
		goto out_nomem;
	/* the slepc path solved every column's loads over the MPI ranks with
	 * its factor of K (grounded): taken in order, batch after batch */
	for (size_t c = 0; c < 3 * n_cols; c++)
		n_loads += col_dofs[c] >= 0;
	given = m->compliance && m->n_compliance == n_loads ? m->compliance : NULL;
	ret = given ? IRDM_OK : irdm_compliance_open(fem, m, floating, IRDM_COMPLIANCE_PINNED, &comp, err, errlen);
	if (ret)
		goto out_free;
	for (size_t c0 = 0; c0 < n_cols; c0 += B) {
		size_t c1 = c0 + B < n_cols ? c0 + B : n_cols, nb = 3 * (c1 - c0);
		size_t n_in = batch_inputs(col_dofs, c0, c1, in, slot);
		struct batch bt = { m, col_dofs, c0, c1, X, slot, mod, diag_norm };

		if (n_in && given) {
			memcpy(X, &given[n_done * n], n * n_in * sizeof(double));
		} else if (n_in) {
			ret = irdm_compliance_columns(comp, in, n_in, X, err, errlen);
			if (ret)
				goto out_free;
		}
		n_done += n_in;
		if (K)
			cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, (int)(3 * c1), (int)nb,
				    (int)K, 1.0, P, (int)K, &Ps[3 * c0 * K], (int)K, 0.0, mod,
				    (int)nb);
		else
			memset(mod, 0, 3 * c1 * nb * sizeof(double));
		if (judge_batch(&bt, tol, &low, &out->max_dropped_rel))
			goto out_nomem;
		if (progress)
			progress(ctx, "static correction", (double)c1 / (double)n_cols);
	}
	if (2 * low.n - n_cols > UINT32_MAX) {
		snprintf(err, errlen, "static correction: %zu blocks kept, more than the image's index holds; raise static_correction_tol",
			 2 * low.n - n_cols);
		ret = IRDM_EINVAL;
		goto out_free;
	}
	ret = mirror(&low, out);
	if (ret)
		goto out_nomem;
	goto out_free;
out_nomem:
	snprintf(err, errlen, "static correction: out of memory");
	ret = IRDM_ENOMEM;
out_free:
	if (ret)
		irdm_corr_sparse_free(out);
	irdm_compliance_close(comp);
	lower_free(&low);
	free(P);
	free(Ps);
	free(X);
	free(mod);
	free(diag_norm);
	free(in);
	free(slot);
	return ret;
}

long irdm_corr_sparse_find(const struct irdm_corr_sparse *s, size_t c, uint32_t r)
{
	uint32_t lo = s->start[c], hi = s->start[c + 1];

	while (lo < hi) {
		uint32_t mid = lo + (hi - lo) / 2;

		if (s->rows[mid] < r)
			lo = mid + 1;
		else
			hi = mid;
	}
	return lo < s->start[c + 1] && s->rows[lo] == r ? (long)lo : -1;
}

void irdm_corr_sparse_free(struct irdm_corr_sparse *s)
{
	free(s->start);
	free(s->blocks);
	memset(s, 0, sizeof(*s));
}
