// SPDX-License-Identifier: MIT
/*
 * The mesh and surface objects themselves: freeing, volume, provenance
 * hash.  Every reader uses the free functions on its error paths, so they
 * sit here, below the readers and the dispatcher (mesh.c).
 */
#include <stdlib.h>
#include <string.h>

#include "mesh/mesh_priv.h"
#include "util/fnv1a.h"

void irdm_mesh_free(struct irdm_mesh *m)
{
	if (!m)
		return;
	free(m->pos_m);
	free(m->tets);
	free(m->tris);
	memset(m, 0, sizeof(*m));
}

void irdm_surface_free(struct irdm_surface *s)
{
	if (!s)
		return;
	free(s->pos_m);
	free(s->tris);
	memset(s, 0, sizeof(*s));
}

double mesh_tet_vol6(const double *x, const uint32_t *t)
{
	const double *a = x + 3 * t[0], *b = x + 3 * t[1];
	const double *c = x + 3 * t[2], *d = x + 3 * t[3];
	double u[3], v[3], w[3];
	int i;

	for (i = 0; i < 3; i++) {
		u[i] = b[i] - a[i];
		v[i] = c[i] - a[i];
		w[i] = d[i] - a[i];
	}
	return (u[1] * v[2] - u[2] * v[1]) * w[0] +
	       (u[2] * v[0] - u[0] * v[2]) * w[1] +
	       (u[0] * v[1] - u[1] * v[0]) * w[2];
}

double irdm_mesh_volume(const struct irdm_mesh *m)
{
	double sum = 0.0;
	size_t e;

	for (e = 0; e < m->n_tets; e++)
		sum += mesh_tet_vol6(m->pos_m, m->tets + 4 * e);
	return sum / 6.0;
}

uint64_t irdm_mesh_hash(const struct irdm_mesh *m)
{
	uint64_t h = IRDM_FNV1A_INIT;

	if (m->pos_m)
		h = irdm_fnv1a(h, m->pos_m, 3 * m->n_nodes * sizeof(*m->pos_m));
	if (m->tets)
		h = irdm_fnv1a(h, m->tets, 4 * m->n_tets * sizeof(*m->tets));
	return h;
}
