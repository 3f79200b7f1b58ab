/* SPDX-License-Identifier: MIT */
/*
 * The static correction's block low-rank part (STATIC_CORR_CLUSTERS,
 * image_format.h) on the displayed columns: a force at column c (cluster b,
 * member j) displaces every cluster a by S(a, b)[:, 3j..3j+2] f.  A pair is
 * stored once, for (min, max), so S(a, b) with a > b is the stored
 * matrix transposed: the strides (dense) or the factors U, V (low-rank)
 * swap roles; a self pair (a, a) holds its upper triangle only.  Every
 * pair of the force's cluster is read, O(3 n_cols) per dense pair and
 * O(rank (3 + 3|a|)) per low-rank one.
 */
#include "worker_priv.h"

/* Where S(a, b) sits in the values, seen from the displaced cluster a. */
struct pair_view {
	size_t o;                      /* element of values[] it starts at */
	uint32_t rank;                 /* IRDM_CORR_PAIR_DENSE or the rank */
	size_t row_stride, col_stride; /* dense: S(a, b)[r][c] at o + r rs + c cs */
	size_t disp_off, force_off;    /* low-rank: S(a, b) = D F^T, D [3|a|][rank] */
};

static void view_pair(const struct irdm_image *img, uint32_t a, uint32_t b,
		      struct pair_view *v)
{
	const struct irdm_corr_pair *q = irdm_image_corr_pair(img, a, b);
	const uint32_t *st = img->corr_cl_start;
	size_t na = 3 * (size_t)(st[a + 1] - st[a]), nb = 3 * (size_t)(st[b + 1] - st[b]);
	bool stored = a <= b; /* else S(a, b) is pair (b, a) transposed */

	v->o = (size_t)q->offset;
	v->rank = q->rank;
	v->row_stride = stored ? nb : 1;
	v->col_stride = stored ? 1 : na;
	/* stored pair (p, q): U [3|p|][rank] first, then V [3|q|][rank] */
	v->disp_off = stored ? v->o : v->o + nb * q->rank;
	v->force_off = stored ? v->o + na * q->rank : v->o;
}

/* Entry (r, c) of a self pair of n rows: its upper triangle, row by row. */
static size_t tri_index(size_t n, size_t r, size_t c)
{
	return r < c ? irdm_upper_index(n, r, c) : irdm_upper_index(n, c, r);
}

/* u[3 i + x] += S(a, a)[3 i + x][3j..3j+2] fe, over cluster a's members i. */
static void self_pair(const struct irdm_deform_worker *w, size_t o, const uint32_t *members,
		      size_t n_members, size_t j, const double *fe, double *pos)
{
	const void *S = w->img->corr_cl_values;
	size_t n = 3 * n_members;

	for (size_t i = 0; i < n_members; i++) {
		double *u = pos + 3 * (size_t)w->img->columns[members[i]];
		for (size_t x = 0; x < 3; x++) {
			size_t r = 3 * i + x;
			u[x] += irdm_elem_get(S, w->prec, o + tri_index(n, r, 3 * j)) * fe[0] +
				irdm_elem_get(S, w->prec, o + tri_index(n, r, 3 * j + 1)) * fe[1] +
				irdm_elem_get(S, w->prec, o + tri_index(n, r, 3 * j + 2)) * fe[2];
		}
	}
}

/* u[3 i + x] += S(a, b)[3 i + x][3j..3j+2] fe, over cluster a's members i. */
static void dense_pair(const struct irdm_deform_worker *w, const struct pair_view *v,
		       const uint32_t *members, size_t n_members, size_t j, const double *fe,
		       double *pos)
{
	const void *S = w->img->corr_cl_values;

	for (size_t i = 0; i < n_members; i++) {
		double *u = pos + 3 * (size_t)w->img->columns[members[i]];
		for (size_t x = 0; x < 3; x++) {
			size_t b = v->o + (3 * i + x) * v->row_stride + 3 * j * v->col_stride;
			u[x] += irdm_elem_get(S, w->prec, b) * fe[0] +
				irdm_elem_get(S, w->prec, b + v->col_stride) * fe[1] +
				irdm_elem_get(S, w->prec, b + 2 * v->col_stride) * fe[2];
		}
	}
}

/* g = F[3j..3j+2]^T fe (rank values), then u += D g: never the 3|a| x 3
 * block itself. */
static void lowrank_pair(const struct irdm_deform_worker *w, const struct pair_view *v,
			 const uint32_t *members, size_t n_members, size_t j, const double *fe,
			 double *pos)
{
	const void *S = w->img->corr_cl_values;
	size_t r = v->rank, fo = v->force_off + 3 * j * r;
	double *g = w->cl_g;

	for (size_t t = 0; t < r; t++)
		g[t] = irdm_elem_get(S, w->prec, fo + t) * fe[0] +
		       irdm_elem_get(S, w->prec, fo + r + t) * fe[1] +
		       irdm_elem_get(S, w->prec, fo + 2 * r + t) * fe[2];
	for (size_t i = 0; i < n_members; i++) {
		double *u = pos + 3 * (size_t)w->img->columns[members[i]];
		for (size_t x = 0; x < 3; x++) {
			size_t d = v->disp_off + (3 * i + x) * r;
			double s = 0;
			for (size_t t = 0; t < r; t++)
				s += irdm_elem_get(S, w->prec, d + t) * g[t];
			u[x] += s;
		}
	}
}

void deform_clusters(const struct irdm_deform_worker *w, const struct irdm_force_tick *f,
		     double *pos)
{
	const struct irdm_image *img = w->img;
	const uint32_t *st = img->corr_cl_start, *members = img->corr_cl_members;
	uint32_t nC = img->corr_clusters->n_clusters;

	for (uint32_t e = 0; e < f->n; e++) {
		uint32_t j, b = irdm_image_corr_cluster(img, f->col[e], &j);
		for (uint32_t a = 0; a < nC; a++) {
			struct pair_view v;
			view_pair(img, a, b, &v);
			if (a == b)
				self_pair(w, v.o, members + st[a], st[a + 1] - st[a], j, f->f_n[e],
					  pos);
			else if (v.rank == IRDM_CORR_PAIR_DENSE)
				dense_pair(w, &v, members + st[a], st[a + 1] - st[a], j,
					   f->f_n[e], pos);
			else
				lowrank_pair(w, &v, members + st[a], st[a + 1] - st[a], j,
					     f->f_n[e], pos);
		}
	}
}
