/* SPDX-License-Identifier: MIT */
/* Columns' responses to themselves from the modes (col_resp.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy/col_resp.h"
#include "irdm/error.h"
#include "modal/lapack.h"

#define BATCH_VALUES (1 << 22) /* a batch's outer products: at most this many doubles */
#define BATCH_MAX 64
#define CUT 1e-12 /* a sample below this of its mode's peak does not count */

void irdm_col_resp_free(struct irdm_col_resp *r)
{
	for (size_t k = 0; k < IRDM_COL_RESP_MAX_X; k++)
		free(r->x[k]);
	free(r->perm);
	free(r->alive);
	free(r->o);
	memset(r, 0, sizeof(*r));
}

int irdm_col_resp_init(struct irdm_col_resp *r, const struct irdm_modes *m, size_t n, size_t n_x)
{
	size_t nm = m->n_modes ? m->n_modes : 1;
	size_t b = BATCH_VALUES / (9 * nm);

	memset(r, 0, sizeof(*r));
	r->m = m;
	r->n = n;
	r->n_x = n_x < IRDM_COL_RESP_MAX_X ? n_x : IRDM_COL_RESP_MAX_X;
	r->batch = b < 1 ? 1 : (b > BATCH_MAX ? BATCH_MAX : b);
	for (size_t k = 0; k < r->n_x; k++)
		r->x[k] = malloc(nm * n * sizeof(double));
	r->perm = malloc(nm * sizeof(size_t));
	r->alive = malloc(nm * sizeof(size_t));
	r->o = malloc(r->batch * 9 * nm * sizeof(double));
	if (!r->x[0] || (r->n_x > 1 && !r->x[1]) || !r->perm || !r->alive || !r->o) {
		irdm_col_resp_free(r);
		return IRDM_ENOMEM;
	}
	return IRDM_OK;
}

size_t irdm_col_resp_alive_len(const double *x, size_t n)
{
	double peak = 0;
	size_t len = 0;

	for (size_t s = 0; s < n; s++)
		peak = fmax(peak, fabs(x[s]));
	for (size_t s = 0; s < n; s++)
		if (fabs(x[s]) > CUT * peak)
			len = s + 1;
	return len;
}

/* A mode and how many of its samples count. */
struct mode_len {
	size_t len, d;
};

/* Longest first, ties in mode order: the sums' order is the same on any
 * qsort. */
static int longest_first(const void *a, const void *b)
{
	const struct mode_len *x = a, *y = b;

	if (x->len != y->len)
		return (x->len < y->len) - (x->len > y->len);
	return (x->d > y->d) - (x->d < y->d);
}

int irdm_col_resp_ready(struct irdm_col_resp *r)
{
	size_t nm = r->m->n_modes, n = r->n;
	struct mode_len *ml = malloc((nm ? nm : 1) * sizeof(*ml));

	if (!ml)
		return IRDM_ENOMEM;
	for (size_t d = 0; d < nm; d++) {
		ml[d] = (struct mode_len){ .len = 0, .d = d };
		for (size_t k = 0; k < r->n_x; k++) {
			size_t l = irdm_col_resp_alive_len(&r->x[k][d * n], n);
			ml[d].len = l > ml[d].len ? l : ml[d].len;
		}
	}
	qsort(ml, nm, sizeof(*ml), longest_first);
	for (size_t i = 0; i < nm; i++) {
		r->perm[i] = ml[i].d;
		r->alive[i] = ml[i].len;
	}
	free(ml);
	for (size_t k = 0; k < r->n_x; k++) {
		double *y = malloc((nm ? nm : 1) * n * sizeof(double));
		if (!y)
			return IRDM_ENOMEM;
		for (size_t i = 0; i < nm; i++)
			memcpy(&y[i * n], &r->x[k][r->perm[i] * n], n * sizeof(double));
		free(r->x[k]);
		r->x[k] = y;
	}
	return IRDM_OK;
}

/* The outer products of the batch, in perm's order: o[(9 c + q) nm + i]. */
static void outer(const struct irdm_col_resp *r, const int64_t *col_dofs, size_t c0, size_t nb)
{
	const struct irdm_modes *m = r->m;
	size_t nm = m->n_modes;

	for (size_t c = 0; c < nb; c++) {
		const int64_t *dofs = &col_dofs[3 * (c0 + c)];

		for (size_t i = 0; i < nm; i++) {
			size_t d = r->perm[i];
			double p[3];

			for (int a = 0; a < 3; a++)
				p[a] = dofs[a] < 0 ? 0.0 : m->phi[d * m->n + (size_t)dofs[a]];
			for (int a = 0; a < 3; a++)
				for (int b = 0; b < 3; b++)
					r->o[(9 * c + (size_t)(3 * a + b)) * nm + i] = p[a] * p[b];
		}
	}
}

void irdm_col_resp_run(struct irdm_col_resp *r, const int64_t *col_dofs, size_t c0, size_t nb,
		       double *const *out)
{
	size_t nm = r->m->n_modes, n = r->n;
	const double one = 1, zero = 0;

	outer(r, col_dofs, c0, nb);
	/* stretches [s0, s1): 0-3, 4-15, 16-63, ... times 4, the modes alive
	 * past s0 (a prefix of perm) */
	for (size_t s0 = 0, s1 = 4; s0 < n; s0 = s1, s1 *= 4) {
		size_t end = s1 < n ? s1 : n, K = 0;
		int len = (int)(end - s0), cols = (int)(9 * nb), ld = (int)n, ldo = (int)nm;

		while (K < nm && r->alive[K] > s0)
			K++;
		for (size_t k = 0; k < r->n_x; k++) {
			int inner = (int)K;

			if (!K) {
				for (size_t q = 0; q < 9 * nb; q++)
					memset(&out[k][q * n + s0], 0, (end - s0) * sizeof(double));
				continue;
			}
			/* column-major: out (n x 9 nb) rows s0..end = x (n x K) o (K x 9 nb) */
			dgemm_("N", "N", &len, &cols, &inner, &one, &r->x[k][s0], &ld, r->o, &ldo,
			       &zero, &out[k][s0], &ld);
		}
	}
}

void irdm_col_resp_column(const double *out, size_t c, size_t n, double *R)
{
	const double *rt = &out[9 * c * n];

	for (size_t s = 0; s < n; s++)
		for (size_t q = 0; q < 9; q++)
			R[9 * s + q] = rt[q * n + s];
}
