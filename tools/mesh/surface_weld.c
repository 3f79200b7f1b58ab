/* SPDX-License-Identifier: MIT */
/*
 * Welding a triangle surface's coincident vertices.  Generators write a
 * closed part's seam twice (a torus's first and last ring, a revolved
 * profile's start and end) with positions equal to ~1e-9, not bit for bit;
 * without welding each seam edge has one triangle and the surface reads
 * as open.  Vertices within IRDM_WELD_REL of the bounding box's diagonal
 * of each other become one (the first in file order); the triangles are
 * renumbered and the vertices left unused removed.
 */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

#include "irdm/error.h"
#include "mesh/mesh_priv.h"

struct by_x {
	double x;
	uint32_t i;
};

static int by_x_cmp(const void *a, const void *b)
{
	const struct by_x *p = a, *q = b;

	if (p->x != q->x)
		return p->x < q->x ? -1 : 1;
	return (p->i > q->i) - (p->i < q->i);
}

/* The bounding box's diagonal. */
static double diagonal(const struct irdm_surface *s)
{
	double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
	double d = 0;

	for (size_t v = 0; v < s->n_verts; v++)
		for (int k = 0; k < 3; k++) {
			lo[k] = fmin(lo[k], s->pos_m[3 * v + (size_t)k]);
			hi[k] = fmax(hi[k], s->pos_m[3 * v + (size_t)k]);
		}
	for (int k = 0; k < 3; k++)
		d += (hi[k] - lo[k]) * (hi[k] - lo[k]);
	return sqrt(d);
}

static bool near(const double *a, const double *b, double tol)
{
	return fabs(a[0] - b[0]) <= tol && fabs(a[1] - b[1]) <= tol && fabs(a[2] - b[2]) <= tol;
}

/* rep[v]: the vertex v is welded to (v itself if none); the count welded. */
static size_t find_reps(const struct irdm_surface *s, struct by_x *o, uint32_t *rep, double tol)
{
	size_t n = s->n_verts, welded = 0;

	for (size_t v = 0; v < n; v++) {
		o[v] = (struct by_x){ s->pos_m[3 * v], (uint32_t)v };
		rep[v] = (uint32_t)v;
	}
	qsort(o, n, sizeof(*o), by_x_cmp);
	for (size_t a = 0; a < n; a++) {
		uint32_t i = o[a].i;

		if (rep[i] != i)
			continue;
		for (size_t b = a + 1; b < n && o[b].x - o[a].x <= tol; b++) {
			uint32_t j = o[b].i;
			if (rep[j] != j || !near(&s->pos_m[3 * (size_t)i], &s->pos_m[3 * (size_t)j], tol))
				continue;
			/* the first in file order stays */
			rep[j] = i < j ? i : j;
			rep[i] = rep[j];
			welded++;
		}
	}
	/* a group's members point at its first vertex, which points at itself */
	for (size_t v = 0; v < n; v++)
		while (rep[rep[v]] != rep[v])
			rep[v] = rep[rep[v]];
	return welded;
}

int surface_weld(struct irdm_surface *s, size_t *welded, double *tol_out)
{
	size_t n = s->n_verts, kept = 0;
	struct by_x *o = malloc((n ? n : 1) * sizeof(*o));
	uint32_t *rep = malloc((n ? n : 1) * sizeof(*rep));
	uint32_t *idx = malloc((n ? n : 1) * sizeof(*idx));
	double tol = IRDM_WELD_REL * diagonal(s);

	*welded = 0;
	*tol_out = tol;
	if (!o || !rep || !idx) {
		free(o);
		free(rep);
		free(idx);
		return IRDM_ENOMEM;
	}
	*welded = n ? find_reps(s, o, rep, tol) : 0;
	if (*welded) {
		for (size_t v = 0; v < n; v++)
			if (rep[v] == v) {
				idx[v] = (uint32_t)kept;
				for (int k = 0; k < 3; k++)
					s->pos_m[3 * kept + (size_t)k] = s->pos_m[3 * v + (size_t)k];
				kept++;
			}
		for (size_t t = 0; t < 3 * s->n_tris; t++)
			if (s->tris[t] < n) /* out of range: surface_check says so */
				s->tris[t] = idx[rep[s->tris[t]]];
		s->n_verts = kept;
	}
	free(o);
	free(rep);
	free(idx);
	return IRDM_OK;
}
