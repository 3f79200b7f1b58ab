/* SPDX-License-Identifier: MIT */
/*
 * Finding a model's mirror and half-turn symmetries (symmetry.h): the 47
 * non-identity maps of the cube's group are tried, those with Q^2 = I
 * that carry the model onto itself kept, and of those a largest set that
 * commute taken as generators.  Then each character's basis, and the
 * eigenproblem's block in it.
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/error.h"
#include "modal/symmetry.h"

/* A node maps onto a node within this fraction of the bounding box's
 * diagonal (the weld tolerance of surface meshes). */
#define NODE_TOL 1e-9
/* Lookup cells, in box diagonals: far above NODE_TOL, so a mapped node is
 * in its cell or a neighbour. */
#define CELL 1e-6
/*
 * K and M map onto themselves to this, relative to sqrt(|A_ii A_jj|):
 * mirrored elements are assembled from coordinates that differ in the last
 * bits, and summed in another order (measured: 8.7e-16 on the 4 x 4 x 8
 * cuboid, 2.0e-15 on the paper's, 3.6e-15 at 11,340 nodes).  Dropping what
 * is left of the coupling between characters moves an eigenvalue by about
 * this times the largest, where the dense solve's own rounding is about
 * 1e-16 times it: kept within a thousand times that, and some thirty
 * times what was measured.
 */
#define MATRIX_TOL 1e-13

/* Signed permutation: (Q x)[perm[i]] = sign[i] x[i]. */
struct map3 {
	int perm[3];
	int sign[3];
};

static void map3_mat(const struct map3 *q, int m[3][3])
{
	memset(m, 0, 9 * sizeof(int));
	for (int i = 0; i < 3; i++)
		m[q->perm[i]][i] = q->sign[i];
}

static void mat_mul(int a[3][3], int b[3][3], int c[3][3])
{
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) {
			c[i][j] = 0;
			for (int k = 0; k < 3; k++)
				c[i][j] += a[i][k] * b[k][j];
		}
}

static bool mat_eq(int a[3][3], int b[3][3])
{
	return !memcmp(a, b, 9 * sizeof(int));
}

static bool mat_is_identity(int a[3][3])
{
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
			if (a[i][j] != (i == j))
				return false;
	return true;
}

/* "x -> -x, y -> -y": the axes Q moves. */
static void describe(const struct map3 *q, char *buf, size_t len)
{
	size_t n = 0;

	buf[0] = 0;
	for (int i = 0; i < 3 && n < len; i++)
		if (q->perm[i] != i || q->sign[i] < 0)
			n += (size_t)snprintf(buf + n, len - n, "%s%c -> %s%c", n ? ", " : "", "xyz"[i],
					      q -> sign[i] < 0 ? "-" : "", "xyz"[q->perm[i]]);
}

struct node_key {
	int64_t key[3];
	size_t node;
};

/* The nodes sorted by their cell: a mapped point's node is found in the
 * 27 cells around it. */
struct node_index {
	size_t n;
	struct node_key *sorted;
	double lo[3], cell, tol;
	const double *pos;
};

static int key_cmp(const int64_t *a, const int64_t *b)
{
	for (int i = 0; i < 3; i++)
		if (a[i] != b[i])
			return a[i] < b[i] ? -1 : 1;
	return 0;
}

static int node_key_cmp(const void *pa, const void *pb)
{
	const struct node_key *a = pa, *b = pb;
	int c = key_cmp(a->key, b->key);

	return c ? c : (a->node > b->node) - (a->node < b->node);
}

static int index_init(struct node_index *ix, const double *pos, size_t n)
{
	double hi[3], d2 = 0;

	ix->n = n;
	ix->pos = pos;
	ix->sorted = malloc((n ? n : 1) * sizeof(*ix->sorted));
	if (!ix->sorted)
		return IRDM_ENOMEM;
	for (int i = 0; i < 3; i++)
		ix->lo[i] = hi[i] = n ? pos[i] : 0;
	for (size_t a = 0; a < n; a++)
		for (int i = 0; i < 3; i++) {
			ix->lo[i] = fmin(ix->lo[i], pos[3 * a + (size_t)i]);
			hi[i] = fmax(hi[i], pos[3 * a + (size_t)i]);
		}
	for (int i = 0; i < 3; i++)
		d2 += (hi[i] - ix->lo[i]) * (hi[i] - ix->lo[i]);
	ix->cell = CELL * sqrt(d2);
	ix->tol = NODE_TOL * sqrt(d2);
	if (!(ix->cell > 0))
		return IRDM_EINVAL;
	for (size_t a = 0; a < n; a++) {
		for (int i = 0; i < 3; i++)
			ix->sorted[a].key[i] = (int64_t)floor((pos[3 * a + (size_t)i] - ix->lo[i]) / ix->cell);
		ix->sorted[a].node = a;
	}
	qsort(ix->sorted, n, sizeof(*ix->sorted), node_key_cmp);
	return IRDM_OK;
}

static void index_free(struct node_index *ix)
{
	free(ix->sorted);
}

/* The node at y (within tol), or -1. */
static int64_t index_find(const struct node_index *ix, const double *y)
{
	int64_t k0[3];

	for (int i = 0; i < 3; i++)
		k0[i] = (int64_t)floor((y[i] - ix->lo[i]) / ix->cell);
	for (int p = 0; p < 27; p++) {
		int64_t k[3] = { k0[0] + p % 3 - 1, k0[1] + p / 3 % 3 - 1, k0[2] + p / 9 - 1 };
		size_t lo = 0, hi = ix->n;

		while (lo < hi) { /* the first of the cell's nodes */
			size_t mid = lo + (hi - lo) / 2;
			if (key_cmp(ix->sorted[mid].key, k) < 0)
				lo = mid + 1;
			else
				hi = mid;
		}
		for (; lo < ix->n && !key_cmp(ix->sorted[lo].key, k); lo++) {
			const double *x = &ix->pos[3 * ix->sorted[lo].node];
			double d2 = 0;
			for (int i = 0; i < 3; i++)
				d2 += (x[i] - y[i]) * (x[i] - y[i]);
			if (d2 <= ix->tol * ix->tol)
				return (int64_t)ix->sorted[lo].node;
		}
	}
	return -1;
}

/* Column j's entry at row i, or NAN if it has none. */
static double csc_at(const struct irdm_csc *a, size_t i, size_t j)
{
	int64_t lo = a->colptr[j], hi = a->colptr[j + 1];

	while (lo < hi) {
		int64_t mid = lo + (hi - lo) / 2;
		if (a->rowind[mid] < (int64_t)i)
			lo = mid + 1;
		else
			hi = mid;
	}
	return lo < a->colptr[j + 1] && a->rowind[lo] == (int64_t)i ? a->val[lo] : NAN;
}

/* max |A(Q i, Q j) - s_i s_j A(i, j)| / sqrt(|A_ii A_jj|); INFINITY if a
 * nonzero has no image. */
static double matrix_dev(const struct irdm_csc *a, const int64_t *to, const signed char *sign)
{
	double dev = 0;

	for (size_t j = 0; j < a->n; j++) {
		size_t gj = (size_t)to[j];
		if (a->colptr[j + 1] - a->colptr[j] != a->colptr[gj + 1] - a->colptr[gj])
			return INFINITY;
		for (int64_t p = a->colptr[j]; p < a->colptr[j + 1]; p++) {
			size_t i = (size_t)a->rowind[p];
			double img = csc_at(a, (size_t)to[i], gj);
			double scale = sqrt(fabs(csc_at(a, i, i) * csc_at(a, j, j)));
			if (isnan(img) || !(scale > 0))
				return INFINITY;
			dev = fmax(dev, fabs(img - sign[i] * sign[j] * a->val[p]) / scale);
		}
	}
	return dev;
}

/*
 * Free DoF map of Q, if Q carries the nodes onto nodes and the fixed DoFs
 * onto fixed ones: to[], sign[].  false if not.
 */
static bool dof_map(const struct map3 *q, const struct node_index *ix, const double *c,
		    const struct irdm_fem *fem, int64_t *to, signed char *sign)
{
	const struct irdm_dofmap *map = &fem->map;

	for (size_t a = 0; a < ix->n; a++) {
		double x[3], y[3];
		int64_t b;

		for (int i = 0; i < 3; i++)
			x[i] = ix->pos[3 * a + (size_t)i] - c[i];
		for (int i = 0; i < 3; i++)
			y[q->perm[i]] = c[q->perm[i]] + q->sign[i] * x[i];
		b = index_find(ix, y);
		if (b < 0)
			return false;
		for (int i = 0; i < 3; i++) {
			int64_t d = map->free_of[3 * a + (size_t)i];
			int64_t e = map->free_of[3 * (size_t)b + (size_t)q->perm[i]];
			if ((d < 0) != (e < 0))
				return false;
			if (d >= 0) {
				to[d] = e;
				sign[d] = (signed char)q->sign[i];
			}
		}
	}
	return true;
}

/* All 48 signed permutations, in a fixed order. */
static void map3_nth(int k, struct map3 *q)
{
	static const int perms[6][3] = { { 0, 1, 2 }, { 0, 2, 1 }, { 1, 0, 2 }, { 1, 2, 0 }, { 2, 0, 1 }, { 2, 1, 0 } };

	for (int i = 0; i < 3; i++) {
		q->perm[i] = perms[k / 8][i];
		q->sign[i] = k >> i & 1 ? -1 : 1;
	}
}

static void free_gen(struct irdm_sym *s, unsigned g)
{
	free(s->to[g]);
	free(s->sign[g]);
	s->to[g] = NULL;
	s->sign[g] = NULL;
}

/* Q's DoF map into s as generator g, if Q is a symmetry of the model
 * (*dev: its mismatch); *ok false, and nothing kept, if not. */
static int try_map(const struct map3 *q, const struct node_index *ix, const double *c,
		   const struct irdm_fem *fem, struct irdm_sym *s, unsigned g, bool *ok,
		   double *dev)
{
	size_t n = fem->K.n;

	*ok = false;
	s->to[g] = malloc((n ? n : 1) * sizeof(int64_t));
	s->sign[g] = malloc(n ? n : 1);
	if (!s->to[g] || !s->sign[g]) {
		free_gen(s, g);
		return IRDM_ENOMEM;
	}
	if (dof_map(q, ix, c, fem, s->to[g], s->sign[g])) {
		*dev = fmax(matrix_dev(&fem->K, s->to[g], s->sign[g]),
			    matrix_dev(&fem->M, s->to[g], s->sign[g]));
		*ok = *dev <= MATRIX_TOL;
	}
	if (!*ok)
		free_gen(s, g);
	return IRDM_OK;
}

/*
 * Generators: each candidate an involution, commuting with those taken,
 * outside the group they generate (group[]: its 2^g elements).
 */
static bool candidate(const struct map3 *q, int group[][3][3], unsigned n_gens,
		      const struct map3 *gens)
{
	int m[3][3], sq[3][3];

	map3_mat(q, m);
	mat_mul(m, m, sq);
	if (mat_is_identity(m) || !mat_is_identity(sq))
		return false;
	for (unsigned e = 0; e < 1u << n_gens; e++)
		if (mat_eq(group[e], m))
			return false;
	for (unsigned g = 0; g < n_gens; g++) {
		int h[3][3], ab[3][3], ba[3][3];
		map3_mat(&gens[g], h);
		mat_mul(m, h, ab);
		mat_mul(h, m, ba);
		if (!mat_eq(ab, ba))
			return false;
	}
	return true;
}

/*
 * Is generator g, as mapped on the DoFs, an involution with signs that
 * commutes with the generators before it?  The node tolerance could pair
 * two near-coincident nodes with one; the bases need true orbits.
 */
static bool dof_group_ok(const struct irdm_sym *s, unsigned g)
{
	const int64_t *t = s->to[g];
	const signed char *sg = s->sign[g];

	for (size_t d = 0; d < s->n; d++) {
		if (t[t[d]] != (int64_t)d || sg[d] * sg[t[d]] != 1)
			return false;
		for (unsigned h = 0; h < g; h++) {
			const int64_t *u = s->to[h];
			if (t[u[d]] != u[t[d]] || sg[u[d]] * s->sign[h][d] != s->sign[h][t[d]] * sg[d])
				return false;
		}
	}
	return true;
}

/* The centre of the nodes' bounding box. */
static void box_centre(const struct node_index *ix, double c[3])
{
	double hi[3];

	for (int i = 0; i < 3; i++)
		hi[i] = ix->lo[i];
	for (size_t a = 0; a < ix->n; a++)
		for (int i = 0; i < 3; i++)
			hi[i] = fmax(hi[i], ix->pos[3 * a + (size_t)i]);
	for (int i = 0; i < 3; i++)
		c[i] = 0.5 * (ix->lo[i] + hi[i]);
}

/* q taken as generator s->n_gens: the group doubled, its name added. */
static void add_generator(struct irdm_sym *s, const struct map3 *q, int group[][3][3],
			  struct map3 *gens)
{
	int m[3][3];
	size_t len = strlen(s->what);

	map3_mat(q, m);
	for (unsigned e = 0; e < 1u << s->n_gens; e++)
		mat_mul(group[e], m, group[e + (1u << s->n_gens)]);
	if (len)
		len += (size_t)snprintf(s->what + len, sizeof(s->what) - len, "; ");
	describe(q, s->what + len, sizeof(s->what) - len);
	gens[s->n_gens++] = *q;
}

int irdm_sym_find(const double *pos_m, size_t n_nodes, const struct irdm_fem *fem,
		  struct irdm_sym *s, char *err, size_t errlen)
{
	struct node_index ix = { 0 };
	struct map3 gens[IRDM_SYM_MAX_GENS];
	int group[1 << IRDM_SYM_MAX_GENS][3][3] = { { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } } };
	double c[3];
	int ret;

	memset(s, 0, sizeof(*s));
	s->n = fem->K.n;
	ret = index_init(&ix, pos_m, n_nodes);
	if (ret) {
		index_free(&ix);
		if (ret == IRDM_ENOMEM)
			snprintf(err, errlen, "symmetry: out of memory for %zu nodes", n_nodes);
		return ret == IRDM_ENOMEM ? ret : IRDM_OK; /* a point: nothing to split */
	}
	box_centre(&ix, c);
	for (int k = 0; k < 48 && s->n_gens < IRDM_SYM_MAX_GENS && !ret; k++) {
		struct map3 q;
		double dev = 0;
		bool ok;

		map3_nth(k, &q);
		if (!candidate(&q, group, s->n_gens, gens))
			continue;
		ret = try_map(&q, &ix, c, fem, s, s->n_gens, &ok, &dev);
		if (ret || !ok)
			continue;
		if (dof_group_ok(s, s->n_gens)) {
			s->mismatch = fmax(s->mismatch, dev);
			add_generator(s, &q, group, gens);
		} else {
			free_gen(s, s->n_gens);
		}
	}
	if (ret) {
		snprintf(err, errlen, "symmetry: out of memory for %zu DoFs", s->n);
		irdm_sym_free(s);
	}
	index_free(&ix);
	return ret;
}

void irdm_sym_free(struct irdm_sym *s)
{
	for (unsigned g = 0; g < IRDM_SYM_MAX_GENS; g++) {
		free(s->to[g]);
		free(s->sign[g]);
	}
	memset(s, 0, sizeof(*s));
}

void irdm_sym_class_free(struct irdm_sym_class *c)
{
	free(c->start);
	free(c->dof);
	free(c->val);
	free(c->local);
	free(c->at_val);
	memset(c, 0, sizeof(*c));
}

static int class_alloc(struct irdm_sym_class *c, size_t n)
{
	memset(c, 0, sizeof(*c));
	c->start = malloc((n + 1) * sizeof(size_t));
	c->dof = malloc((n ? n : 1) * sizeof(int64_t));
	c->val = malloc((n ? n : 1) * sizeof(double));
	c->local = malloc((n ? n : 1) * sizeof(int64_t));
	c->at_val = calloc(n ? n : 1, sizeof(double));
	if (!c->start || !c->dof || !c->val || !c->local || !c->at_val)
		return IRDM_ENOMEM;
	c->start[0] = 0;
	for (size_t d = 0; d < n; d++)
		c->local[d] = -1;
	return IRDM_OK;
}

#define ORBIT_MAX (1 << IRDM_SYM_MAX_GENS)

/* Character c of element e: -1 if an odd count of e's generators act as -1. */
static double character(unsigned c, unsigned e)
{
	unsigned odd = 0;

	for (unsigned b = c & e; b; b >>= 1)
		odd ^= b & 1;
	return odd ? -1.0 : 1.0;
}

/* Character c's vector on the orbit of d (img[], sg[] under each element)
 * appended to cls, unless it is zero. */
static void add_vector(struct irdm_sym_class *cls, unsigned c, unsigned n_el, const int64_t *img,
		       const int *sg)
{
	int64_t dof[ORBIT_MAX];
	double val[ORBIT_MAX], norm = 0;
	unsigned n = 0;
	size_t at = cls->start[cls->n];

	for (unsigned e = 0; e < n_el; e++) {
		double v = character(c, e) * sg[e];
		unsigned k = 0;
		while (k < n && dof[k] != img[e])
			k++;
		if (k == n) {
			dof[n] = img[e];
			val[n++] = 0;
		}
		val[k] += v;
	}
	for (unsigned k = 0; k < n; k++)
		norm += val[k] * val[k];
	if (norm < 0.5) /* integer sums: zero, or at least 1 */
		return;
	norm = sqrt(norm);
	for (unsigned k = 0; k < n; k++) {
		if (val[k] == 0)
			continue;
		cls->dof[at] = dof[k];
		cls->val[at] = val[k] / norm;
		cls->local[dof[k]] = (int64_t)cls->n;
		cls->at_val[dof[k]] = val[k] / norm;
		at++;
	}
	cls->start[++cls->n] = at;
}

int irdm_sym_classes(const struct irdm_sym *s, struct irdm_sym_class *cls)
{
	unsigned n_el = 1u << s->n_gens;
	bool *seen = calloc(s->n ? s->n : 1, sizeof(bool));
	int ret = seen ? IRDM_OK : IRDM_ENOMEM;

	memset(cls, 0, n_el * sizeof(*cls)); /* each freeable, allocated or not */

	for (unsigned c = 0; c < n_el && !ret; c++)
		ret = class_alloc(&cls[c], s->n);
	for (size_t d = 0; d < s->n && !ret; d++) {
		int64_t img[ORBIT_MAX];
		int sg[ORBIT_MAX];

		if (seen[d])
			continue;
		for (unsigned e = 0; e < n_el; e++) {
			img[e] = (int64_t)d;
			sg[e] = 1;
			for (unsigned g = 0; g < s->n_gens; g++)
				if (e >> g & 1) {
					sg[e] *= s->sign[g][img[e]];
					img[e] = s->to[g][img[e]];
				}
			seen[img[e]] = true;
		}
		for (unsigned c = 0; c < n_el; c++)
			add_vector(&cls[c], c, n_el, img, sg);
	}
	free(seen);
	if (ret)
		for (unsigned c = 0; c < n_el; c++)
			irdm_sym_class_free(&cls[c]);
	return ret;
}

void irdm_sym_block(const struct irdm_sym_class *c, const struct irdm_csc *K,
		    const double *dsqrt, double *a)
{
	size_t m = c->n;

	memset(a, 0, m * m * sizeof(double));
	for (size_t q = 0; q < m; q++)
		for (size_t t = c->start[q]; t < c->start[q + 1]; t++) {
			size_t b = (size_t)c->dof[t];
			double vb = c->val[t];
			for (int64_t p = K->colptr[b]; p < K->colptr[b + 1]; p++) {
				size_t i = (size_t)K->rowind[p];
				int64_t r = c->local[i];
				if (r >= 0)
					a[q * m + (size_t)r] += K->val[p] / (dsqrt[i] * dsqrt[b]) * (c->at_val[i] * vb);
			}
		}
}
