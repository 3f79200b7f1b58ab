/* SPDX-License-Identifier: MIT */
/*
 * The static correction, block low-rank over clusters of columns.
 *
 * Why not drop small blocks: S = G - Phi_K Lambda_K^-1 Phi_K^T decays only
 * like the elastic Green's function (1/r), and the truncation leaves an
 * oscillating floor: on test_static_torus's torus the block ratio
 * |S_ab| / sqrt(|S_aa| |S_bb|) is 0.07 on average 1 to 2 cm apart, 0.016 at
 * 3 to 5 cm and still 0.0045 across the torus, so a force error of 1e-3
 * keeps 99.9 % of the blocks.  Nor one global low-rank term: S's
 * eigenvalues fall to 0.3 of the largest only by the 800th.  But the block
 * between two clusters of nearby nodes is a smooth function of both
 * positions: on that torus (2277 columns, clusters of at most 128) a
 * truncated SVD leaves no block off by 8e-4 with ranks of 36 on average,
 * 37 MB in f32 for the upper half against 93 MB dense.
 *
 * The columns are solved a cluster at a time (one factor of K, as
 * static_sparse.c); when cluster b's are known, S(a, b) is complete for
 * every a <= b and is compressed at once: scaled by the diagonal norms so
 * that the truncation bounds each block's ratio, SVD, the shortest rank
 * whose residual leaves every block under tol (bisection on the rank; the
 * residual is formed, so the bound is measured, not estimated).
 */
#include <cblas.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/image.h"
#include "modal/lapack.h"
#include "modal/response.h"
#include "modal/static_clusters.h"

#define SHARE_POWER 2 /* shares(): the tolerance's power of the condition */

/* What the sweep over the column clusters shares. */
struct sweep {
	const struct irdm_modes *m;
	const int64_t *col_dofs;
	struct irdm_corr_clusters *cl;
	double tol;
	size_t nd;      /* 3 n_cols */
	double *P, *Ps; /* nd x K */
	double *strip;  /* nd x 3|b|: S(:, b) */
	double *sd;     /* n_cols: sqrt(|S_cc|), 1 where 0 */
	double **pair;  /* n_pairs: each pair's values until packed */
};

/* ---- clustering: recursive bisection at the median of the longest side */

struct keyed {
	double key;
	uint32_t col;
};

static int by_key(const void *a, const void *b)
{
	const struct keyed *x = a, *y = b;

	return x->key < y->key ? -1 : x->key > y->key ? 1 :
			      x->col < y->col         ? -1 :
							x->col > y->col;
}

static void bisect(const double *pos, uint32_t *cols, size_t n, size_t max, struct keyed *tmp,
		   struct irdm_corr_clusters *cl, size_t *at)
{
	double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
	int ax = 0;

	if (n <= max) {
		memcpy(&cl->members[*at], cols, n * sizeof(uint32_t));
		*at += n;
		cl->start[++cl->n_clusters] = (uint32_t)*at;
		return;
	}
	for (size_t i = 0; i < n; i++)
		for (int x = 0; x < 3; x++) {
			lo[x] = fmin(lo[x], pos[3 * (size_t)cols[i] + (size_t)x]);
			hi[x] = fmax(hi[x], pos[3 * (size_t)cols[i] + (size_t)x]);
		}
	for (int x = 1; x < 3; x++)
		if (hi[x] - lo[x] > hi[ax] - lo[ax])
			ax = x;
	for (size_t i = 0; i < n; i++)
		tmp[i] = (struct keyed){ pos[3 * (size_t)cols[i] + (size_t)ax], cols[i] };
	qsort(tmp, n, sizeof(*tmp), by_key);
	for (size_t i = 0; i < n; i++)
		cols[i] = tmp[i].col;
	bisect(pos, cols, n / 2, max, tmp, cl, at);
	bisect(pos, cols + n / 2, n - n / 2, max, tmp, cl, at);
}

static int make_clusters(const double *pos, size_t n_cols, size_t max,
			 struct irdm_corr_clusters *cl)
{
	uint32_t *cols = malloc(n_cols * sizeof(uint32_t));
	struct keyed *tmp = malloc(n_cols * sizeof(*tmp));
	size_t at = 0;
	int ret = IRDM_ENOMEM;

	cl->start = calloc(n_cols + 1, sizeof(uint32_t));
	cl->members = malloc(n_cols * sizeof(uint32_t));
	cl->col_pos = malloc(n_cols * sizeof(uint32_t));
	if (!cols || !tmp || !cl->start || !cl->members || !cl->col_pos)
		goto out_free;
	for (size_t c = 0; c < n_cols; c++)
		cols[c] = (uint32_t)c;
	bisect(pos, cols, n_cols, max, tmp, cl, &at);
	for (size_t i = 0; i < n_cols; i++)
		cl->col_pos[cl->members[i]] = (uint32_t)i;
	cl->n_pairs = cl->n_clusters * (cl->n_clusters + 1) / 2;
	ret = IRDM_OK;
out_free:
	free(cols);
	free(tmp);
	return ret;
}

static size_t pair_index(size_t n_clusters, size_t a, size_t b)
{
	return irdm_upper_index(n_clusters, a, b);
}

static size_t cl_size(const struct irdm_corr_clusters *cl, size_t a)
{
	return cl->start[a + 1] - cl->start[a];
}

/* ---- one column cluster: S(:, b) */

/* strip[d][3i + y] = S at DoF d for a unit force on member i's axis y. */
static int solve_strip(struct sweep *s, struct irdm_compliance *comp, const double *given,
		       const size_t *load_of, size_t b, double *X, int64_t *in, size_t *slot,
		       char *err, size_t errlen)
{
	const struct irdm_corr_clusters *cl = s->cl;
	size_t n = s->m->n, K = s->m->n_modes, nb = 3 * cl_size(cl, b), n_in = 0;
	const uint32_t *mem = &cl->members[cl->start[b]];
	double *Psb = NULL;
	int ret;

	for (size_t j = 0; j < nb; j++) {
		int64_t d = s->col_dofs[3 * (size_t)mem[j / 3] + j % 3];
		slot[j] = d < 0 ? SIZE_MAX : n_in;
		if (d >= 0)
			in[n_in++] = d;
	}
	if (n_in && given) {
		for (size_t j = 0; j < nb; j++)
			if (slot[j] != SIZE_MAX)
				memcpy(&X[slot[j] * n],
				       &given[load_of[3 * (size_t)mem[j / 3] + j % 3] * n],
				       n * sizeof(double));
	} else if (n_in) {
		ret = irdm_compliance_columns(comp, in, n_in, X, err, errlen);
		if (ret)
			return ret;
	}
	for (size_t d = 0; d < s->nd; d++)
		for (size_t j = 0; j < nb; j++)
			s->strip[d * nb + j] = s->col_dofs[d] < 0 || slot[j] == SIZE_MAX ? 0.0 :
											   X[slot[j] * n + (size_t)s->col_dofs[d]];
	if (!K)
		return IRDM_OK;
	Psb = malloc(nb * K * sizeof(double));
	if (!Psb)
		return IRDM_ENOMEM;
	for (size_t j = 0; j < nb; j++)
		memcpy(&Psb[j * K], &s->Ps[(3 * (size_t)mem[j / 3] + j % 3) * K], K * sizeof(double));
	/* the kept modes' part: strip -= P Ps_b^T */
	cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, (int)s->nd, (int)nb, (int)K, -1.0,
		    s->P, (int)K, Psb, (int)K, 1.0, s->strip, (int)nb);
	free(Psb);
	return IRDM_OK;
}

/* A = S(a, b), 3|a| x 3|b| column-major (LAPACK's), from the strip. */
static void gather(const struct sweep *s, size_t a, size_t b, double *A)
{
	const struct irdm_corr_clusters *cl = s->cl;
	size_t ma = 3 * cl_size(cl, a), nb = 3 * cl_size(cl, b);
	const uint32_t *mem = &cl->members[cl->start[a]];

	for (size_t i = 0; i < ma; i++) {
		const double *row = &s->strip[(3 * (size_t)mem[i / 3] + i % 3) * nb];
		for (size_t j = 0; j < nb; j++)
			A[i + j * ma] = row[j];
	}
}

/* The 3x3 block norms of E (column-major, ld m) into nrm ((m/3) x (n/3),
 * column-major); return the largest of nrm / w when w is given. */
static double block_norms(const double *E, size_t m, size_t n, const double *w, double *nrm)
{
	double worst = 0;

	for (size_t j = 0; j < n; j += 3)
		for (size_t i = 0; i < m; i += 3) {
			double ss = 0;
			for (size_t x = 0; x < 3; x++)
				for (size_t y = 0; y < 3; y++)
					ss += E[i + x + (j + y) * m] * E[i + x + (j + y) * m];
			size_t k = i / 3 + (j / 3) * (m / 3);
			if (nrm)
				nrm[k] = sqrt(ss);
			worst = fmax(worst, w ? sqrt(ss) / w[k] : sqrt(ss));
		}
	return worst;
}

/* The SVD of the scaled block, its workspace and each block's share of
 * the tolerance. */
struct svd {
	size_t m, n, r;
	double *As, *s, *u, *vt, *E, *Us;
	double *w; /* (m/3) x (n/3) */
};

static int svd_of(struct svd *v)
{
	int m = (int)v->m, n = (int)v->n, r = (int)v->r, lwork = -1, info = 0;
	int *iwork = malloc(8 * v->r * sizeof(int));
	double wq = 0, *work = NULL, *A = malloc(v->m * v->n * sizeof(double));
	int ret = IRDM_ENOMEM;

	if (!iwork || !A)
		goto out_free;
	memcpy(A, v->As, v->m * v->n * sizeof(double));
	dgesdd_("S", &m, &n, A, &m, v->s, v->u, &m, v->vt, &r, &wq, &lwork, iwork, &info);
	lwork = (int)wq;
	work = malloc((size_t)lwork * sizeof(double));
	if (!work)
		goto out_free;
	dgesdd_("S", &m, &n, A, &m, v->s, v->u, &m, v->vt, &r, work, &lwork, iwork, &info);
	ret = info ? IRDM_ENUMERIC : IRDM_OK;
out_free:
	free(iwork);
	free(work);
	free(A);
	return ret;
}

/* The largest scaled block error left by rank k, over its share w (1:
 * the plain block error). */
static double residual(struct svd *v, size_t k, bool weighted)
{
	memcpy(v->E, v->As, v->m * v->n * sizeof(double));
	for (size_t t = 0; t < k; t++)
		for (size_t i = 0; i < v->m; i++)
			v->Us[i + t * v->m] = v->u[i + t * v->m] * v->s[t];
	if (k)
		cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (int)v->m, (int)v->n, (int)k,
			    -1.0, v->Us, (int)v->m, v->vt, (int)v->r, 1.0, v->E, (int)v->m);
	return block_norms(v->E, v->m, v->n, weighted ? v->w : NULL, NULL);
}

/*
 * Each block's share of the tolerance: ((1 - rho) / (1 + rho))^2 for a
 * block of ratio rho.  Two contacts whose coupling has ratio rho solve a
 * system of condition (1 + rho) / (1 - rho), which multiplies the block's
 * error into the force, and three close contacts worse: on
 * test_static_torus's torus, at tol 8e-4, a step at three nodes 3.3 mm
 * apart across two clusters was off by 1.5e-3 with the plain bound, 8.7e-4
 * with the first power (every block within 1.4e-4: a gain of 6) and
 * 4.7e-4 with the square, for 3.5 % more values.
 */
static void shares(struct svd *v)
{
	block_norms(v->As, v->m, v->n, NULL, v->w);
	for (size_t k = 0; k < (v->m / 3) * (v->n / 3); k++) {
		double rho = fmin(v->w[k], 0.99);
		v->w[k] = pow((1 - rho) / (1 + rho), SHARE_POWER);
	}
}

/* The dense pair, row-major; a self pair (m = n) its symmetric part's
 * upper triangle, row by row. */
static double *store_dense(const double *A, size_t m, size_t n, bool self)
{
	double *p = malloc((self ? m * (m + 1) / 2 : m * n) * sizeof(double));
	size_t k = 0;

	if (!p)
		return NULL;
	for (size_t i = 0; i < m; i++)
		for (size_t j = self ? i : 0; j < n; j++)
			p[k++] = self ? 0.5 * (A[i + j * m] + A[j + i * m]) : A[i + j * m];
	return p;
}

/* U then V, row-major, unscaled, sqrt(sigma) on each side. */
static double *store_lowrank(const struct svd *v, size_t k, const double *da, const double *db)
{
	double *p = malloc((v->m + v->n) * (k ? k : 1) * sizeof(double));

	if (!p)
		return NULL;
	for (size_t t = 0; t < k; t++) {
		double h = sqrt(v->s[t]);
		for (size_t i = 0; i < v->m; i++)
			p[i * k + t] = da[i] * v->u[i + t * v->m] * h;
		for (size_t j = 0; j < v->n; j++)
			p[(v->m + j) * k + t] = db[j] * v->vt[t + j * v->r] * h;
	}
	return p;
}

/* Pair (a, b), a < b: the shortest rank that keeps every block under tol. */
static int compress(struct sweep *s, size_t a, size_t b, const double *A)
{
	struct irdm_corr_clusters *cl = s->cl;
	size_t m = 3 * cl_size(cl, a), n = 3 * cl_size(cl, b), r = m < n ? m : n;
	size_t q = pair_index(cl->n_clusters, a, b), lo = 0, hi = r;
	struct svd v = { m, n, r, malloc(m * n * sizeof(double)), malloc(r * sizeof(double)),
			 malloc(m * r * sizeof(double)), malloc(r * n * sizeof(double)),
			 malloc(m * n * sizeof(double)), malloc(m * r * sizeof(double)),
			 malloc((m / 3) * (n / 3) * sizeof(double)) };
	double *da = malloc(m * sizeof(double)), *db = malloc(n * sizeof(double));
	int ret = IRDM_ENOMEM;

	if (!v.As || !v.s || !v.u || !v.vt || !v.E || !v.Us || !v.w || !da || !db)
		goto out_free;
	for (size_t i = 0; i < m; i++)
		da[i] = s->sd[cl->members[cl->start[a] + i / 3]];
	for (size_t j = 0; j < n; j++)
		db[j] = s->sd[cl->members[cl->start[b] + j / 3]];
	for (size_t j = 0; j < n; j++)
		for (size_t i = 0; i < m; i++)
			v.As[i + j * m] = A[i + j * m] / (da[i] * db[j]);
	shares(&v);
	ret = svd_of(&v);
	if (ret)
		goto out_free;
	while (lo < hi) {
		size_t mid = lo + (hi - lo) / 2;
		if (residual(&v, mid, true) <= s->tol)
			hi = mid;
		else
			lo = mid + 1;
	}
	ret = IRDM_ENOMEM;
	if (lo * (m + n) >= m * n) {
		cl->rank[q] = IRDM_CORR_PAIR_DENSE;
		s->pair[q] = store_dense(A, m, n, false);
		cl->n_dense++;
	} else {
		cl->rank[q] = (uint32_t)lo;
		cl->max_err = fmax(cl->max_err, residual(&v, lo, false));
		cl->max_rank = lo > cl->max_rank ? lo : cl->max_rank;
		s->pair[q] = store_lowrank(&v, lo, da, db);
	}
	ret = s->pair[q] ? IRDM_OK : IRDM_ENOMEM;
out_free:
	free(v.As);
	free(v.s);
	free(v.u);
	free(v.vt);
	free(v.E);
	free(v.Us);
	free(v.w);
	free(da);
	free(db);
	return ret;
}

/* Every pair (a, b), a <= b, once cluster b's columns are known. */
static int pairs_of(struct sweep *s, size_t b)
{
	struct irdm_corr_clusters *cl = s->cl;
	size_t nb = 3 * cl_size(cl, b), mb = 0;
	double *A;
	int ret = IRDM_OK;

	for (size_t a = 0; a <= b; a++)
		mb = 3 * cl_size(cl, a) > mb ? 3 * cl_size(cl, a) : mb;
	A = malloc(mb * nb * sizeof(double));
	if (!A)
		return IRDM_ENOMEM;
	/* the diagonal norms of b first: every pair's scale needs them */
	gather(s, b, b, A);
	for (size_t i = 0; i < nb; i += 3) {
		double ss = 0;
		for (size_t x = 0; x < 3; x++)
			for (size_t y = 0; y < 3; y++) {
				double e = 0.5 * (A[i + x + (i + y) * nb] + A[i + y + (i + x) * nb]);
				ss += e * e;
			}
		s->sd[cl->members[cl->start[b] + i / 3]] = ss > 0 ? sqrt(sqrt(ss)) : 1.0;
	}
	cl->rank[pair_index(cl->n_clusters, b, b)] = IRDM_CORR_PAIR_DENSE;
	s->pair[pair_index(cl->n_clusters, b, b)] = store_dense(A, nb, nb, true);
	cl->n_dense++;
	if (!s->pair[pair_index(cl->n_clusters, b, b)])
		ret = IRDM_ENOMEM;
	for (size_t a = 0; a < b && !ret; a++) {
		gather(s, a, b, A);
		ret = compress(s, a, b, A);
	}
	free(A);
	return ret;
}

/* The pairs' values one after the other, in table order. */
static int pack(struct sweep *s)
{
	struct irdm_corr_clusters *cl = s->cl;
	size_t q = 0, at = 0;

	for (size_t a = 0; a < cl->n_clusters; a++)
		for (size_t b = a; b < cl->n_clusters; b++, q++) {
			size_t m = 3 * cl_size(cl, a), n = 3 * cl_size(cl, b);
			cl->offset[q] = at;
			at += a == b                              ? m * (m + 1) / 2 :
			      cl->rank[q] == IRDM_CORR_PAIR_DENSE ? m * n :
								    cl->rank[q] * (m + n);
		}
	cl->n_values = at;
	cl->values = malloc((at ? at : 1) * sizeof(double));
	if (!cl->values)
		return IRDM_ENOMEM;
	for (q = 0; q < cl->n_pairs; q++) {
		size_t next = q + 1 < cl->n_pairs ? cl->offset[q + 1] : at;
		memcpy(&cl->values[cl->offset[q]], s->pair[q], (next - cl->offset[q]) * sizeof(double));
		free(s->pair[q]);
		s->pair[q] = NULL;
	}
	return IRDM_OK;
}

/* The diagonal blocks, zero: the STATIC_CORR index the image needs. */
static int diagonal_kept(size_t n_cols, struct irdm_corr_sparse *kept)
{
	memset(kept, 0, sizeof(*kept));
	kept->n_cols = n_cols;
	kept->n_blocks = n_cols;
	kept->start = calloc(2 * n_cols + 1, sizeof(uint32_t));
	kept->blocks = calloc(9 * (n_cols ? n_cols : 1), sizeof(double));
	if (!kept->start || !kept->blocks)
		return IRDM_ENOMEM;
	kept->rows = kept->start + n_cols + 1;
	for (size_t c = 0; c < n_cols; c++) {
		kept->start[c + 1] = (uint32_t)(c + 1);
		kept->rows[c] = (uint32_t)c;
	}
	return IRDM_OK;
}

static int sweep_all(struct sweep *s, const struct irdm_fem *fem, bool floating,
		     irdm_progress_fn progress, void *ctx, char *err, size_t errlen)
{
	const struct irdm_modes *m = s->m;
	struct irdm_corr_clusters *cl = s->cl;
	size_t n = m->n, big = 0, n_loads = 0;
	struct irdm_compliance *comp = NULL;
	size_t *load_of = malloc(s->nd * sizeof(size_t)), *slot = NULL;
	int64_t *in = NULL;
	double *X = NULL;
	const double *given;
	int ret = IRDM_ENOMEM;

	for (size_t a = 0; a < cl->n_clusters; a++)
		big = 3 * cl_size(cl, a) > big ? 3 * cl_size(cl, a) : big;
	X = malloc(n * big * sizeof(double));
	s->strip = malloc(s->nd * big * sizeof(double));
	in = malloc(big * sizeof(int64_t));
	slot = malloc(big * sizeof(size_t));
	if (!load_of || !X || !s->strip || !in || !slot)
		goto out_free;
	for (size_t d = 0; d < s->nd; d++)
		load_of[d] = s->col_dofs[d] >= 0 ? n_loads++ : SIZE_MAX;
	/* the slepc path solved every column's loads with its factor */
	given = m->compliance && m->n_compliance == n_loads ? m->compliance : NULL;
	ret = given ? IRDM_OK : irdm_compliance_open(fem, m, floating, IRDM_COMPLIANCE_PINNED, &comp, err, errlen);
	for (size_t b = 0; b < cl->n_clusters && !ret; b++) {
		ret = solve_strip(s, comp, given, load_of, b, X, in, slot, err, errlen);
		if (!ret)
			ret = pairs_of(s, b);
		if (ret == IRDM_ENUMERIC && !err[0])
			snprintf(err, errlen, "static correction clusters: SVD failed");
		if (!ret && progress)
			progress(ctx, "static correction (clusters)", (b + 1.0) / (double)cl->n_clusters);
	}
out_free:
	irdm_compliance_close(comp);
	free(load_of);
	free(X);
	free(in);
	free(slot);
	free(s->strip);
	s->strip = NULL;
	return ret;
}

int irdm_static_correction_clusters(const struct irdm_fem *fem, const struct irdm_modes *m,
				    bool floating, const int64_t *col_dofs, const double *col_pos_m,
				    size_t n_cols, size_t cluster_nodes, double tol,
				    irdm_progress_fn progress, void *ctx,
				    struct irdm_corr_sparse *kept, struct irdm_corr_clusters *out,
				    char *err, size_t errlen)
{
	struct sweep s = { m, col_dofs, out, tol, 3 * n_cols, NULL, NULL, NULL, NULL, NULL };
	int ret;

	memset(out, 0, sizeof(*out));
	memset(kept, 0, sizeof(*kept));
	err[0] = '\0';
	out->n_cols = n_cols;
	if (cluster_nodes < IRDM_STATIC_CORR_CLUSTER_MIN || cluster_nodes > IRDM_STATIC_CORR_CLUSTER_MAX ||
	    !n_cols) {
		snprintf(err, errlen, "static correction clusters: %zu nodes per cluster is not in %d..%d",
			 cluster_nodes, IRDM_STATIC_CORR_CLUSTER_MIN, IRDM_STATIC_CORR_CLUSTER_MAX);
		return IRDM_EINVAL;
	}
	ret = make_clusters(col_pos_m, n_cols, cluster_nodes, out);
	if (ret)
		goto out_nomem;
	if (out->n_clusters > IRDM_CORR_CLUSTERS_MAX) {
		snprintf(err, errlen, "static correction clusters: %zu clusters, more than the image's %u; raise static_correction_cluster",
			 out->n_clusters, IRDM_CORR_CLUSTERS_MAX);
		ret = IRDM_EINVAL;
		goto out_free;
	}
	out->rank = calloc(out->n_pairs, sizeof(uint32_t));
	out->offset = calloc(out->n_pairs, sizeof(uint64_t));
	s.pair = calloc(out->n_pairs, sizeof(double *));
	s.sd = malloc(n_cols * sizeof(double));
	if (!out->rank || !out->offset || !s.pair || !s.sd ||
	    irdm_corr_modal_basis(m, col_dofs, n_cols, &s.P, &s.Ps))
		goto out_nomem;
	/* one BLAS thread: the pairs' SVDs and GEMMs are a few hundred wide,
	 * where a second thread only spins (on the 2520-column torus this
	 * stage took 11.6 s wall with one thread or two, and the whole
	 * precompute 48 s of CPU with two) */
	int saved = irdm_blas_serial_begin();
	ret = sweep_all(&s, fem, floating, progress, ctx, err, errlen);
	irdm_blas_serial_end(saved);
	if (ret == IRDM_ENOMEM)
		goto out_nomem;
	if (!ret)
		ret = pack(&s);
	if (!ret)
		ret = diagonal_kept(n_cols, kept);
	if (ret == IRDM_ENOMEM)
		goto out_nomem;
	goto out_free;
out_nomem:
	snprintf(err, errlen, "static correction clusters: out of memory");
	ret = IRDM_ENOMEM;
out_free:
	for (size_t q = 0; s.pair && q < out->n_pairs; q++)
		free(s.pair[q]);
	free(s.pair);
	free(s.sd);
	free(s.P);
	free(s.Ps);
	if (ret) {
		irdm_corr_clusters_free(out);
		irdm_corr_sparse_free(kept);
	}
	return ret;
}

void irdm_corr_clusters_block(const struct irdm_corr_clusters *cl, size_t col_f, size_t col_d,
			      double out[9])
{
	size_t pd = cl->col_pos[col_d], pf = cl->col_pos[col_f], ad = 0, af = 0;

	while (cl->start[ad + 1] <= pd)
		ad++;
	while (cl->start[af + 1] <= pf)
		af++;
	bool swap = ad > af;
	size_t ar = swap ? af : ad, ac = swap ? ad : af;
	size_t lr = (swap ? pf : pd) - cl->start[ar], lc = (swap ? pd : pf) - cl->start[ac];
	size_t q = pair_index(cl->n_clusters, ar, ac), nr = 3 * cl_size(cl, ar);
	size_t ncl = 3 * cl_size(cl, ac), o = cl->offset[q], k = cl->rank[q];

	for (size_t x = 0; x < 3; x++)
		for (size_t y = 0; y < 3; y++) {
			size_t r = 3 * lr + (swap ? y : x), c = 3 * lc + (swap ? x : y);
			double s = 0;
			if (ar == ac) {
				size_t i = r < c ? r : c, j = r < c ? c : r;
				s = cl->values[o + irdm_upper_index(nr, i, j)];
			} else if (k == IRDM_CORR_PAIR_DENSE)
				s = cl->values[o + r * ncl + c];
			else
				for (size_t t = 0; t < k; t++)
					s += cl->values[o + r * k + t] * cl->values[o + nr * k + c * k + t];
			out[3 * x + y] = s;
		}
}

void irdm_corr_clusters_free(struct irdm_corr_clusters *cl)
{
	free(cl->start);
	free(cl->members);
	free(cl->col_pos);
	free(cl->rank);
	free(cl->offset);
	free(cl->values);
	memset(cl, 0, sizeof(*cl));
}
