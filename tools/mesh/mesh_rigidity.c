/* SPDX-License-Identifier: MIT */
/*
 * Does the mesh resist every motion but the ones it should allow?  A
 * question about connectivity and geometry, answered before the
 * eigensolve and without a tolerance on eigenvalues (whose scale, on a
 * graded mesh, is set by its smallest element and says nothing about its
 * softest mode).
 *
 * Tets that share a face move as one rigid cluster unless they strain
 * (the shared face's three nodes fix the neighbour).  A cluster is
 * anchored when three non-collinear of its nodes are anchor points: fixed
 * nodes, or nodes of an anchored cluster.  A grounded object needs every
 * cluster anchored from its fixed nodes; a floating one, every cluster
 * anchored from its largest (then it moves only as one rigid body, with
 * exactly six zero-energy modes).  The test is sufficient: an anchored mesh
 * has a positive-definite stiffness (grounded), or one whose null space is
 * the six rigid motions (floating).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh/mesh.h"

struct face {
	uint32_t v[3];
	uint32_t tet;
};

static int face_cmp(const void *a, const void *b)
{
	const struct face *x = a, *y = b;

	for (int k = 0; k < 3; k++)
		if (x->v[k] != y->v[k])
			return x->v[k] < y->v[k] ? -1 : 1;
	return 0;
}

static uint32_t find(uint32_t *parent, uint32_t i)
{
	while (parent[i] != i) {
		parent[i] = parent[parent[i]];
		i = parent[i];
	}
	return i;
}

static void sort3(uint32_t v[3])
{
	uint32_t t;

	if (v[0] > v[1]) {
		t = v[0];
		v[0] = v[1];
		v[1] = t;
	}
	if (v[1] > v[2]) {
		t = v[1];
		v[1] = v[2];
		v[2] = t;
	}
	if (v[0] > v[1]) {
		t = v[0];
		v[0] = v[1];
		v[1] = t;
	}
}

/* cluster[t]: a representative tet of tet t's face-connected cluster. */
static int face_clusters(const struct irdm_mesh *m, uint32_t *cluster)
{
	static const int fv[4][3] = { { 1, 2, 3 }, { 0, 2, 3 }, { 0, 1, 3 }, { 0, 1, 2 } };
	struct face *f = malloc(4 * m->n_tets * sizeof(*f));

	if (!f)
		return -1;
	for (uint32_t t = 0; t < m->n_tets; t++) {
		cluster[t] = t;
		for (int k = 0; k < 4; k++) {
			struct face *x = &f[4 * (size_t)t + k];
			for (int j = 0; j < 3; j++)
				x->v[j] = m->tets[4 * (size_t)t + fv[k][j]];
			sort3(x->v);
			x->tet = t;
		}
	}
	qsort(f, 4 * m->n_tets, sizeof(*f), face_cmp);
	for (size_t i = 1; i < 4 * m->n_tets; i++)
		if (!face_cmp(&f[i - 1], &f[i]))
			cluster[find(cluster, f[i].tet)] = find(cluster, f[i - 1].tet);
	for (uint32_t t = 0; t < m->n_tets; t++)
		cluster[t] = find(cluster, t);
	free(f);
	return 0;
}

/* Tets grouped by cluster: by[first[c] .. first[c] + count[c]). */
struct groups {
	uint32_t *by, *first, *count;
};

static int group(const struct irdm_mesh *m, const uint32_t *cluster, struct groups *g)
{
	size_t n = m->n_tets ? m->n_tets : 1;
	uint32_t at = 0;

	g->by = malloc(n * sizeof(*g->by));
	g->first = malloc(n * sizeof(*g->first));
	g->count = calloc(n, sizeof(*g->count));
	if (!g->by || !g->first || !g->count)
		return -1;
	for (uint32_t t = 0; t < m->n_tets; t++)
		g->count[cluster[t]]++;
	for (uint32_t c = 0; c < m->n_tets; c++) {
		g->first[c] = at;
		at += g->count[c];
	}
	memset(g->count, 0, n * sizeof(*g->count));
	for (uint32_t t = 0; t < m->n_tets; t++) {
		uint32_t c = cluster[t];
		g->by[g->first[c] + g->count[c]++] = t;
	}
	return 0;
}

static void groups_free(struct groups *g)
{
	free(g->by);
	free(g->first);
	free(g->count);
}

/* Whether the anchor points among cluster c's nodes span a plane. */
static bool spans_plane(const struct irdm_mesh *m, const struct groups *g, uint32_t c,
			const bool *anchor, double tol2)
{
	const double *p0 = NULL, *p1 = NULL;

	for (uint32_t j = g->first[c]; j < g->first[c] + g->count[c]; j++) {
		uint32_t t = g->by[j];
		for (int k = 0; k < 4; k++) {
			uint32_t v = m->tets[4 * (size_t)t + k];
			const double *p = &m->pos_m[3 * (size_t)v];
			double a[3], b[3], x[3];

			if (!anchor[v])
				continue;
			if (!p0) {
				p0 = p;
				continue;
			}
			for (int i = 0; i < 3; i++)
				a[i] = p[i] - p0[i];
			if (!p1) {
				if (a[0] * a[0] + a[1] * a[1] + a[2] * a[2] > tol2)
					p1 = p;
				continue;
			}
			for (int i = 0; i < 3; i++)
				b[i] = p1[i] - p0[i];
			x[0] = a[1] * b[2] - a[2] * b[1];
			x[1] = a[2] * b[0] - a[0] * b[2];
			x[2] = a[0] * b[1] - a[1] * b[0];
			if (x[0] * x[0] + x[1] * x[1] + x[2] * x[2] > tol2 * tol2)
				return true;
		}
	}
	return false;
}

static void anchor_cluster(const struct irdm_mesh *m, const struct groups *g, uint32_t c,
			   bool *anchor, bool *done)
{
	for (uint32_t i = g->first[c]; i < g->first[c] + g->count[c]; i++)
		for (int k = 0; k < 4; k++)
			anchor[m->tets[4 * (size_t)g->by[i] + k]] = true;
	done[c] = true;
}

/* The largest cluster (most tets). */
static uint32_t largest(const struct irdm_mesh *m, const struct groups *g)
{
	uint32_t best = 0;

	for (uint32_t c = 0; c < m->n_tets; c++)
		if (g->count[c] > g->count[best])
			best = c;
	return best;
}

/* Anchor clusters until nothing changes.  Return: a loose cluster, or UINT32_MAX. */
static uint32_t propagate(const struct irdm_mesh *m, const uint32_t *cluster,
			  const struct groups *g, bool *anchor, bool *done, double tol2)
{
	bool changed = true;

	while (changed) {
		changed = false;
		for (uint32_t c = 0; c < m->n_tets; c++) {
			if (!g->count[c] || done[c] || !spans_plane(m, g, c, anchor, tol2))
				continue;
			anchor_cluster(m, g, c, anchor, done);
			changed = true;
		}
	}
	for (uint32_t t = 0; t < m->n_tets; t++)
		if (!done[cluster[t]])
			return cluster[t];
	return UINT32_MAX;
}

/* Square of a length far below the mesh's size and far above rounding. */
static double tolerance2(const struct irdm_mesh *m)
{
	double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
	double d2 = 0;

	for (size_t v = 0; v < m->n_nodes; v++)
		for (int i = 0; i < 3; i++) {
			lo[i] = fmin(lo[i], m->pos_m[3 * v + i]);
			hi[i] = fmax(hi[i], m->pos_m[3 * v + i]);
		}
	for (int i = 0; i < 3; i++)
		d2 += (hi[i] - lo[i]) * (hi[i] - lo[i]);
	return 1e-18 * d2;
}

int irdm_mesh_check_rigidity(const struct irdm_mesh *m, const bool *fixed, bool floating,
			     char *err, size_t errlen)
{
	uint32_t *cluster = malloc((m->n_tets ? m->n_tets : 1) * sizeof(*cluster));
	struct groups g = { NULL, NULL, NULL };
	bool *anchor = calloc(m->n_nodes ? m->n_nodes : 1, sizeof(*anchor));
	bool *done = calloc(m->n_tets ? m->n_tets : 1, sizeof(*done));
	uint32_t loose, v, n_loose = 0;
	int ret = -1;

	if (!cluster || !anchor || !done || face_clusters(m, cluster) || group(m, cluster, &g)) {
		snprintf(err, errlen, "model: out of memory for the rigidity check");
		goto out_free;
	}
	if (floating)
		anchor_cluster(m, &g, largest(m, &g), anchor, done);
	else
		for (size_t i = 0; i < m->n_nodes; i++)
			anchor[i] = fixed && fixed[i];
	loose = propagate(m, cluster, &g, anchor, done, tolerance2(m));
	if (loose == UINT32_MAX) {
		ret = 0;
		goto out_free;
	}
	for (uint32_t t = 0; t < m->n_tets; t++)
		n_loose += !done[cluster[t]];
	v = m->tets[4 * (size_t)loose];
	snprintf(err, errlen,
		 floating ? "model: a floating object must move as one body: %u tet(s) around node %u "
			    "(%.4g, %.4g, %.4g) hang on fewer than 3 non-collinear nodes of the rest" :
			    "model: %u tet(s) around node %u (%.4g, %.4g, %.4g) can move without "
			    "straining (fewer than 3 non-collinear fixed or held nodes): fix more "
			    "nodes or declare it floating",
		 n_loose, v, m->pos_m[3 * (size_t)v], m->pos_m[3 * (size_t)v + 1],
		 m->pos_m[3 * (size_t)v + 2]);
out_free:
	free(cluster);
	groups_free(&g);
	free(anchor);
	free(done);
	return ret;
}
