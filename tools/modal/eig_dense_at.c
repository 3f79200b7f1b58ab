/* SPDX-License-Identifier: MIT */
/*
 * Every mode of a lumped-mass model, densely, each at chosen DoFs only
 * (the rest made whole on demand), split by the model's symmetries.
 *
 * With M = D lumped, A = D^-1/2 K D^-1/2.  Each character of the
 * symmetry group (modal/symmetry.h) has its block B^T A B, solved by
 * dsyevd's steps (dsytrd, dstedc; dormtr later, for the rows asked for
 * and for the vectors made whole): the blocks' eigenvalues together are
 * A's, a block's vector y is B y in A's.  Without symmetry there is one
 * block, B = I.  The blocks of 1/2^g the size cost about 1/4^g of the
 * whole in time and 1/2^g in memory.
 */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "modal/eig_dense_priv.h"
#include "modal/lapack.h"
#include "modal/modal.h"
#include "modal/symmetry.h"

#define MAX_PARTS (1 << IRDM_SYM_MAX_GENS)
/* Out of memory, apart from LAPACK's infos (negative: a bad argument). */
#define EIG_NOMEM INT_MIN

/* One character's block: its basis, dsytrd's Householder vectors (lower
 * triangle) and scalar factors, the tridiagonal's eigenvectors. */
struct eig_part {
	int n;
	double *a, *tau, *z;
	struct irdm_sym_class basis;
};

struct irdm_eig_rest {
	int n;
	unsigned n_parts;
	struct eig_part part[MAX_PARTS];
	double *dsqrt;     /* the lumped mass's square root */
	unsigned *part_of; /* n: each mode's block */
	int *local_of;     /* n: its index in the block's solve */
};

void irdm_eig_rest_free(struct irdm_eig_rest *r)
{
	if (!r)
		return;
	for (unsigned p = 0; p < r->n_parts; p++) {
		free(r->part[p].a);
		free(r->part[p].tau);
		free(r->part[p].z);
		irdm_sym_class_free(&r->part[p].basis);
	}
	free(r->dsqrt);
	free(r->part_of);
	free(r->local_of);
	free(r);
}

/* C <- op(Q) C, C n x k; trans "N" or "T".  0, EIG_NOMEM, or info. */
static int apply_q(const struct eig_part *p, const char *trans, double *c, int k)
{
	double q = 0, *work;
	int lwork = -1, info = 0, n = p->n;

	if (k == 0 || n == 0)
		return 0;
	dormtr_("L", "L", trans, &n, &k, p->a, &n, p->tau, c, &n, &q, &lwork, &info);
	lwork = irdm_eig_work_size(q);
	work = lwork > 0 ? malloc((size_t)lwork * sizeof(double)) : NULL;
	if (!work)
		return EIG_NOMEM;
	dormtr_("L", "L", trans, &n, &k, p->a, &n, p->tau, c, &n, work, &lwork, &info);
	free(work);
	return info;
}

/* out's columns j whose mode lies in block pi, made whole (unscaled). */
static int fill_part(const struct irdm_eig_rest *r, unsigned pi, const size_t *z_cols, size_t k,
		     double *out)
{
	const struct eig_part *p = &r->part[pi];
	size_t n = (size_t)r->n, np = (size_t)p->n, cnt = 0, j, c;
	double *y;
	int ret;

	for (j = 0; j < k; j++)
		cnt += r->part_of[z_cols[j]] == pi;
	if (!cnt)
		return 0;
	y = malloc(np * cnt * sizeof(double));
	if (!y)
		return EIG_NOMEM;
	for (j = 0, c = 0; j < k; j++)
		if (r->part_of[z_cols[j]] == pi)
			memcpy(&y[c++ * np], &p->z[(size_t)r->local_of[z_cols[j]] * np], np * sizeof(double));
	ret = apply_q(p, "N", y, (int)cnt);
	for (j = 0, c = 0; j < k && !ret; j++) {
		if (r->part_of[z_cols[j]] != pi)
			continue;
		for (size_t q = 0; q < np; q++)
			for (size_t t = p->basis.start[q]; t < p->basis.start[q + 1]; t++)
				out[j * n + (size_t)p->basis.dof[t]] += p->basis.val[t] * y[c * np + q];
		c++;
	}
	free(y);
	return ret;
}

int irdm_eig_rest_fill(const struct irdm_eig_rest *r, const size_t *z_cols, size_t k, double *out)
{
	size_t n = (size_t)r->n;
	int ret = 0;

	memset(out, 0, n * k * sizeof(double));
	for (unsigned p = 0; p < r->n_parts && !ret; p++)
		ret = fill_part(r, p, z_cols, k, out);
	if (ret)
		return ret == EIG_NOMEM ? IRDM_ENOMEM : IRDM_ENUMERIC;
	for (size_t j = 0; j < k; j++)
		for (size_t i = 0; i < n; i++)
			out[j * n + i] /= r->dsqrt[i];
	return IRDM_OK;
}

/*
 * Block pi's modes at the rows at[] that have a vector in it:
 * (Q^T E)^T Z, times the basis entry, scaled by M^-1/2 (global_of:
 * each of the block's modes' index in phi).
 */
static int rows_part(const struct irdm_eig_rest *r, unsigned pi, const int64_t *at, size_t n_at,
		     const size_t *global_of, double *phi)
{
	const struct eig_part *p = &r->part[pi];
	size_t n = (size_t)r->n, np = (size_t)p->n, t = 0;
	int ti, ni = p->n, ret = EIG_NOMEM;
	double one = 1.0, zero = 0.0;
	size_t *sel, w = np * (n_at ? n_at : 1) + 1;
	double *c, *y;

	if (!np)
		return 0; /* a character no DoF has: no modes */
	sel = malloc((n_at ? n_at : 1) * sizeof(size_t));
	c = calloc(w, sizeof(double));
	y = malloc(w * sizeof(double));
	if (!sel || !c || !y)
		goto out;
	for (size_t i = 0; i < n_at; i++)
		if (p->basis.local[at[i]] >= 0) {
			c[t * np + (size_t)p->basis.local[at[i]]] = 1.0;
			sel[t++] = i;
		}
	ti = (int)t;
	ret = apply_q(p, "T", c, ti);
	if (ret || !t || !np)
		goto out;
	dgemm_("T", "N", &ti, &ni, &ni, &one, c, &ni, p->z, &ni, &zero, y, &ti);
	for (size_t l = 0; l < np; l++)
		for (size_t j = 0; j < t; j++) {
			size_t d = (size_t)at[sel[j]];
			phi[global_of[l] * n + d] = p->basis.at_val[d] * y[l * t + j] / r->dsqrt[d];
		}
out:
	free(sel);
	free(c);
	free(y);
	return ret;
}

/*
 * Block p's eigenvalues into w (ascending) and its tridiagonal's vectors
 * into p->z, by way of scratch (at least n_p^2: dstedc's own n_p^2
 * workspace is given back before p->z is taken).  0, EIG_NOMEM, or
 * LAPACK's info; *step the LAPACK step that failed.
 */
static int solve_part(const struct irdm_fem *fem, const double *dsqrt, struct eig_part *p,
		      double *w, double *scratch, const char **step)
{
	int n = p->n, lwork = -1, liwork = -1, info = 0;
	double *e, *work = NULL;
	int *iwork = NULL;

	if (!n)
		return 0; /* a character no DoF has: no modes */
	e = malloc(((size_t)n + 1) * sizeof(double));
	p->a = malloc(((size_t)n * (size_t)n + 1) * sizeof(double));
	p->tau = malloc(((size_t)n + 1) * sizeof(double));
	if (!e || !p->a || !p->tau)
		goto out_nomem;
	irdm_sym_block(&p->basis, &fem->K, dsqrt, p->a);
	if (irdm_eig_workspace(p->a, n, w, e, p->tau, scratch, false, &work, &lwork, &iwork, &liwork))
		goto out_nomem;
	*step = "dsytrd";
	dsytrd_("L", &n, p->a, &n, w, e, p->tau, work, &lwork, &info);
	if (!info) {
		*step = "dstedc";
		dstedc_("I", &n, w, e, scratch, &n, work, &lwork, iwork, &liwork, &info);
	}
	free(work);
	work = NULL;
	if (!info) {
		p->z = malloc(((size_t)n * (size_t)n + 1) * sizeof(double));
		if (!p->z)
			goto out_nomem;
		memcpy(p->z, scratch, (size_t)n * (size_t)n * sizeof(double));
	}
	free(e);
	free(iwork);
	return info;
out_nomem:
	free(e);
	free(work);
	free(iwork);
	return EIG_NOMEM;
}

/* The blocks' sizes squared, summed (n^2 before they are known). */
static double eig_sum_sq(const struct irdm_eig_rest *r)
{
	double sum = 0;

	if (!r->n_parts)
		return (double)r->n * (double)r->n;
	for (unsigned p = 0; p < r->n_parts; p++)
		sum += (double)r->part[p].n * (double)r->part[p].n;
	return sum;
}

double irdm_eig_dense_at_bytes(size_t n, double sum_sq)
{
	/* phi (n x n), then each block's matrix and its tridiagonal's
	 * vectors (dstedc's workspace, of the block's size, in place of
	 * the vectors while it runs) */
	return 8.0 * ((double)n * (double)n + 2.0 * sum_sq);
}

struct eig_entry {
	double w;
	unsigned part;
	int local;
};

static int entry_cmp(const void *pa, const void *pb)
{
	const struct eig_entry *a = pa, *b = pb;

	if (a->w != b->w)
		return a->w < b->w ? -1 : 1;
	if (a->part != b->part)
		return a->part < b->part ? -1 : 1;
	return (a->local > b->local) - (a->local < b->local);
}

/* The blocks' eigenvalues in one ascending w2; each mode's block and
 * index in it; global[pi][l]: mode l of block pi's index in w2. */
static int merge(struct irdm_eig_rest *r, const double *wl, double *w2, size_t **global)
{
	size_t n = (size_t)r->n, k = 0, off = 0;
	struct eig_entry *all = malloc((n ? n : 1) * sizeof(*all));

	if (!all)
		return EIG_NOMEM;
	for (unsigned p = 0; p < r->n_parts; off += (size_t)r->part[p++].n)
		for (int l = 0; l < r->part[p].n; l++)
			all[k++] = (struct eig_entry){ wl[off + (size_t)l], p, l };
	qsort(all, n, sizeof(*all), entry_cmp);
	for (k = 0; k < n; k++) {
		w2[k] = all[k].w;
		r->part_of[k] = all[k].part;
		r->local_of[k] = all[k].local;
		global[all[k].part][all[k].local] = k;
	}
	free(all);
	return 0;
}

static void progress_part(irdm_progress_fn progress, void *ctx, const struct irdm_eig_rest *r,
			  unsigned done)
{
	double total = 0, sofar = 0;

	if (!progress)
		return;
	for (unsigned p = 0; p < r->n_parts; p++) {
		double c = (double)r->part[p].n;
		total += c * c * c;
		if (p < done)
			sofar += c * c * c;
	}
	progress(ctx, "dense eigensolve: tridiagonal", total > 0 ? 0.95 * sofar / total : 0.95);
}

/* The blocks solved, merged, and phi's rows at[] filled (NaN elsewhere). */
static int solve_parts(const struct irdm_fem *fem, struct irdm_eig_rest *r, const int64_t *at,
		       size_t n_at, irdm_progress_fn progress, void *ctx, double *w2, double *phi,
		       const char **step)
{
	size_t n = (size_t)r->n, off = 0;
	size_t *global[MAX_PARTS] = { NULL };
	double *wl = malloc((n ? n : 1) * sizeof(double));
	int info = wl ? 0 : EIG_NOMEM;

	for (unsigned p = 0; p < r->n_parts && !info; off += (size_t)r->part[p++].n) {
		info = solve_part(fem, r->dsqrt, &r->part[p], wl + off, phi, step);
		progress_part(progress, ctx, r, p + 1);
	}
	for (unsigned p = 0; p < r->n_parts && !info; p++) {
		global[p] = malloc(((size_t)r->part[p].n + 1) * sizeof(size_t));
		if (!global[p])
			info = EIG_NOMEM;
	}
	if (!info)
		info = merge(r, wl, w2, global);
	if (!info) {
		for (size_t i = 0; i < n * n; i++)
			phi[i] = NAN;
		for (size_t k = 0; k < n; k++)
			for (size_t i = 0; i < n_at; i++)
				phi[k * n + (size_t)at[i]] = 0;
		*step = "dormtr";
		for (unsigned p = 0; p < r->n_parts && !info; p++)
			info = rows_part(r, p, at, n_at, global[p], phi);
	}
	for (unsigned p = 0; p < r->n_parts; p++)
		free(global[p]);
	free(wl);
	return info;
}

/*
 * r's blocks: sym's characters (NULL or no generator: one, the whole).
 * Bases that do not add up to every DoF (not a group, which
 * irdm_sym_find() rules out) fall back to the whole.  0 or EIG_NOMEM.
 */
static int parts_init(struct irdm_eig_rest *r, const struct irdm_fem *fem,
		      const struct irdm_sym *sym)
{
	struct irdm_sym none = { .n = fem->K.n };
	const struct irdm_sym *s = sym && sym->n_gens ? sym : &none;
	struct irdm_sym_class cls[MAX_PARTS];
	size_t total = 0;
	unsigned n_cls = 1u << s->n_gens;

	if (irdm_sym_classes(s, cls))
		return EIG_NOMEM;
	for (unsigned p = 0; p < n_cls; p++)
		total += cls[p].n;
	if (total != fem->K.n) {
		for (unsigned p = 0; p < n_cls; p++)
			irdm_sym_class_free(&cls[p]);
		return s == &none ? EIG_NOMEM : parts_init(r, fem, NULL);
	}
	r->n_parts = n_cls;
	for (unsigned p = 0; p < r->n_parts; p++) {
		r->part[p].basis = cls[p];
		r->part[p].n = (int)cls[p].n;
	}
	irdm_eig_mass_sqrt(&fem->M, r->dsqrt);
	return 0;
}

/*
 * Every eigenpair of a lumped-mass model, each vector only at the n_at
 * free DoFs at[] (NaN elsewhere, in phi: n x n); *rest makes chosen
 * vectors whole (irdm_eig_rest_fill).  A consistent mass: every vector
 * whole and *rest NULL (its L^-T mixes the rows).  sym: the model's
 * symmetries (NULL: none).  Progress (NULL: none) after each block.
 */
int irdm_eig_dense_at(const struct irdm_fem *fem, const struct irdm_sym *sym, const int64_t *at,
		      size_t n_at, irdm_progress_fn progress, void *ctx, double *w2, double *phi,
		      struct irdm_eig_rest **rest, char *err, size_t errlen)
{
	size_t n = fem->K.n;
	struct irdm_eig_rest *r = NULL;
	const char *step = "dsytrd";
	int info;

	*rest = NULL;
	if (!irdm_eig_mass_is_diagonal(&fem->M))
		return irdm_eig_dense(fem, fem->K.n, w2, phi, err, errlen);
	r = calloc(1, sizeof(*r));
	if (!r)
		goto out_nomem;
	r->n = (int)n;
	r->dsqrt = malloc((n ? n : 1) * sizeof(double));
	r->part_of = malloc((n ? n : 1) * sizeof(unsigned));
	r->local_of = malloc((n ? n : 1) * sizeof(int));
	if (!r->dsqrt || !r->part_of || !r->local_of || parts_init(r, fem, sym))
		goto out_nomem;
	info = solve_parts(fem, r, at, n_at, progress, ctx, w2, phi, &step);
	if (info == EIG_NOMEM)
		goto out_nomem;
	if (info) {
		snprintf(err, errlen, "dense eigensolver: %s failed (info %d)", step, info);
		irdm_eig_rest_free(r);
		return IRDM_ENUMERIC;
	}
	if (progress)
		progress(ctx, "dense eigensolve: its eigenvectors", 1.0);
	*rest = r;
	return IRDM_OK;

out_nomem:
	snprintf(err, errlen, "dense eigensolver: out of memory for n = %zu (needs %.1f GiB)", n,
		 irdm_eig_dense_at_bytes(n, r ? eig_sum_sq(r) : (double)n * (double)n) / (1 << 30));
	irdm_eig_rest_free(r);
	return IRDM_ENOMEM;
}

unsigned irdm_eig_rest_blocks(const struct irdm_eig_rest *r)
{
	return r ? r->n_parts : 1;
}
