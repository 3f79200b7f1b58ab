/* SPDX-License-Identifier: MIT */
/*
 * Is a triangle surface closed?  tetgen needs a closed, manifold surface
 * and, given an open one (a teapot's rim, a scan with holes), dies on an
 * assertion; this says what is wrong first: how many edges belong to one
 * triangle only (open) or to more than two (non-manifold), and where the
 * first of them is.
 */
#include <stdlib.h>

#include "irdm/error.h"
#include "mesh/mesh_priv.h"

struct edge {
	uint32_t a, b; /* a < b */
};

static int edge_cmp(const void *x, const void *y)
{
	const struct edge *p = x, *q = y;

	if (p->a != q->a)
		return p->a < q->a ? -1 : 1;
	return (p->b > q->b) - (p->b < q->b);
}

static void say_edge(const struct irdm_surface *s, const struct edge *e, const char *kind,
		     size_t count, const char *what, char *err, size_t errlen)
{
	const double *p = &s->pos_m[3 * (size_t)e->a], *q = &s->pos_m[3 * (size_t)e->b];

	mesh_err(err, errlen, what,
		 "surface is not closed: %zu %s edge%s, the first from (%.6g, %.6g, %.6g) to "
		 "(%.6g, %.6g, %.6g); tetgen needs a closed surface without self-intersections",
		 count, kind, count == 1 ? "" : "s", p[0], p[1], p[2], q[0], q[1], q[2]);
}

int surface_check_closed(const struct irdm_surface *s, const char *what, char *err,
			 size_t errlen)
{
	size_t n = 3 * s->n_tris, open = 0, multi = 0, first_open = 0, first_multi = 0;
	struct edge *e = malloc((n ? n : 1) * sizeof(*e));

	if (!e) {
		mesh_err(err, errlen, what, "out of memory");
		return IRDM_ENOMEM;
	}
	for (size_t t = 0; t < s->n_tris; t++)
		for (int k = 0; k < 3; k++) {
			uint32_t u = s->tris[3 * t + k], v = s->tris[3 * t + (k + 1) % 3];
			e[3 * t + k] = (struct edge){ u < v ? u : v, u < v ? v : u };
		}
	qsort(e, n, sizeof(*e), edge_cmp);
	for (size_t i = 0; i < n;) {
		size_t j = i + 1;

		while (j < n && !edge_cmp(&e[i], &e[j]))
			j++;
		if (j - i == 1 && !open++)
			first_open = i;
		if (j - i > 2 && !multi++)
			first_multi = i;
		i = j;
	}
	if (open)
		say_edge(s, &e[first_open], "open (one triangle)", open, what, err, errlen);
	else if (multi)
		say_edge(s, &e[first_multi], "non-manifold (three or more triangles)", multi, what,
			 err, errlen);
	free(e);
	return open || multi ? IRDM_EFORMAT : 0;
}
