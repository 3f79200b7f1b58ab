// SPDX-License-Identifier: MIT
/*
 * Triangle surfaces shared by the OBJ, OFF and STL readers: growth while
 * parsing and the structural check that makes a surface safe to index
 * and worth handing to tetgen.
 */
#include <math.h>

#include "irdm/error.h"
#include "mesh/mesh_priv.h"

int surface_add_vert(struct surface_build *b, const double x[3])
{
	struct irdm_surface *s = b->s;
	double *p;

	if (s->n_verts >= MESH_MAX_ITEMS)
		return -1;
	p = mesh_grow(s->pos_m, &b->cap_verts, s->n_verts + 1, 3 * sizeof(*p));
	if (!p)
		return -1;
	s->pos_m = p;
	p += 3 * s->n_verts++;
	p[0] = x[0];
	p[1] = x[1];
	p[2] = x[2];
	return 0;
}

int surface_add_tri(struct surface_build *b, uint32_t v0, uint32_t v1,
		    uint32_t v2)
{
	struct irdm_surface *s = b->s;
	uint32_t *p;

	if (s->n_tris >= MESH_MAX_ITEMS)
		return -1;
	p = mesh_grow(s->tris, &b->cap_tris, s->n_tris + 1, 3 * sizeof(*p));
	if (!p)
		return -1;
	s->tris = p;
	p += 3 * s->n_tris++;
	p[0] = v0;
	p[1] = v1;
	p[2] = v2;
	return 0;
}

/* Collinear corners: tetgen cannot mesh such a facet, and it would leave
 * edges that look open ("not closed") instead of saying which triangle. */
static bool zero_area(const struct irdm_surface *s, const uint32_t *t)
{
	const double *a = &s->pos_m[3 * (size_t)t[0]], *b = &s->pos_m[3 * (size_t)t[1]];
	const double *c = &s->pos_m[3 * (size_t)t[2]];
	double u[3], v[3], n[3], lu = 0, lv = 0, ln = 0;

	for (int k = 0; k < 3; k++) {
		u[k] = b[k] - a[k];
		v[k] = c[k] - a[k];
	}
	n[0] = u[1] * v[2] - u[2] * v[1];
	n[1] = u[2] * v[0] - u[0] * v[2];
	n[2] = u[0] * v[1] - u[1] * v[0];
	for (int k = 0; k < 3; k++) {
		lu += u[k] * u[k];
		lv += v[k] * v[k];
		ln += n[k] * n[k];
	}
	/* |u x v| = |u| |v| sin(angle): below 1e-12 of |u| |v|, the angle is nil */
	return ln <= 1e-24 * lu * lv;
}

int surface_check(const struct irdm_surface *s, const char *what,
		  char *err, size_t errlen)
{
	size_t i;

	/* A tetrahedron is the smallest closed triangle surface. */
	if (s->n_verts < 4 || s->n_tris < 4) {
		mesh_err(err, errlen, what,
			 "surface has %zu vertices and %zu triangles; a closed surface needs at least 4 of each",
			 s->n_verts, s->n_tris);
		return IRDM_EFORMAT;
	}
	for (i = 0; i < 3 * s->n_verts; i++) {
		if (!isfinite(s->pos_m[i])) {
			mesh_err(err, errlen, what,
				 "vertex %zu has a non-finite coordinate", i / 3 + 1);
			return IRDM_EFORMAT;
		}
	}
	for (i = 0; i < s->n_tris; i++) {
		const uint32_t *t = s->tris + 3 * i;

		if (t[0] >= s->n_verts || t[1] >= s->n_verts ||
		    t[2] >= s->n_verts) {
			mesh_err(err, errlen, what,
				 "triangle %zu refers to a vertex beyond the %zu defined",
				 i + 1, s->n_verts);
			return IRDM_EFORMAT;
		}
		if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
			mesh_err(err, errlen, what,
				 "triangle %zu is degenerate (a vertex repeats)", i + 1);
			return IRDM_EFORMAT;
		}
		if (zero_area(s, t)) {
			mesh_err(err, errlen, what,
				 "triangle %zu is degenerate (zero area: its vertices are collinear)",
				 i + 1);
			return IRDM_EFORMAT;
		}
	}
	return 0;
}
