/* SPDX-License-Identifier: MIT */
/* Symmetric CSC matrices: building from triplets, products, dense copies. */
#include <stdlib.h>
#include <string.h>

#include "fem/csc_build.h"

void irdm_csc_free(struct irdm_csc *a)
{
	free(a->colptr);
	free(a->rowind);
	free(a->val);
	memset(a, 0, sizeof(*a));
}

void irdm_csc_matvec(const struct irdm_csc *a, const double *x, double *y)
{
	for (size_t i = 0; i < a->n; i++)
		y[i] = 0.0;
	for (size_t j = 0; j < a->n; j++) {
		double xj = x[j];
		for (int64_t p = a->colptr[j]; p < a->colptr[j + 1]; p++)
			y[a->rowind[p]] += a->val[p] * xj;
	}
}

double *irdm_csc_to_dense(const struct irdm_csc *a)
{
	double *d = calloc(a->n * a->n, sizeof(*d));

	if (!d)
		return NULL;
	for (size_t j = 0; j < a->n; j++)
		for (int64_t p = a->colptr[j]; p < a->colptr[j + 1]; p++)
			d[j * a->n + (size_t)a->rowind[p]] = a->val[p];
	return d;
}

static int cmp_row(const void *pa, const void *pb)
{
	const struct irdm_triplet *a = pa, *b = pb;

	if (a->col != b->col)
		return a->col < b->col ? -1 : 1;
	return (a->row > b->row) - (a->row < b->row);
}

/*
 * Sort the triplets by (column, row), sum duplicates, and compress.  The
 * triplet array is consumed (reordered).
 */
int irdm_csc_from_triplets(size_t n, struct irdm_triplet *t, size_t nt,
			   struct irdm_csc *a)
{
	size_t nnz = 0;

	memset(a, 0, sizeof(*a));
	qsort(t, nt, sizeof(*t), cmp_row);
	for (size_t i = 0; i < nt; i++)
		if (i == 0 || t[i].row != t[i - 1].row || t[i].col != t[i - 1].col)
			nnz++;
	a->n = n;
	a->colptr = calloc(n + 1, sizeof(*a->colptr));
	a->rowind = malloc((nnz ? nnz : 1) * sizeof(*a->rowind));
	a->val = malloc((nnz ? nnz : 1) * sizeof(*a->val));
	if (!a->colptr || !a->rowind || !a->val) {
		irdm_csc_free(a);
		return IRDM_ENOMEM;
	}
	size_t k = (size_t)-1;
	for (size_t i = 0; i < nt; i++) {
		if (i == 0 || t[i].row != t[i - 1].row || t[i].col != t[i - 1].col) {
			k++;
			a->rowind[k] = t[i].row;
			a->val[k] = 0.0;
			a->colptr[t[i].col + 1]++;
		}
		a->val[k] += t[i].val;
	}
	for (size_t j = 0; j < n; j++)
		a->colptr[j + 1] += a->colptr[j];
	a->nnz = nnz;
	return 0;
}
