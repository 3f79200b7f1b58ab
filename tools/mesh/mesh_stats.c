/* SPDX-License-Identifier: MIT */
/*
 * What a mesh is made of, said before the eigensolve spends minutes on it:
 * sizes, element volumes and shapes, the worst element, and warnings for
 * the two mistakes a new user makes with CAD parts (a tiny feature that
 * grades the mesh over many decades; a part in millimetres read as metres).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mesh/mesh.h"

/*
 * Shape quality of a tet, 1 for the regular one, 0 for a flat one:
 * 12 (3 V)^(2/3) / sum of its 6 squared edge lengths (scale-free).
 */
static double quality(const double *p[4], double vol)
{
	double l2 = 0;

	for (int a = 0; a < 4; a++)
		for (int b = a + 1; b < 4; b++)
			for (int k = 0; k < 3; k++)
				l2 += (p[a][k] - p[b][k]) * (p[a][k] - p[b][k]);
	return l2 > 0 ? 12 * pow(3 * fabs(vol), 2.0 / 3.0) / l2 : 0;
}

static double volume(const double *p[4])
{
	double e[3][3];

	for (int k = 0; k < 3; k++)
		for (int i = 0; i < 3; i++)
			e[k][i] = p[k + 1][i] - p[0][i];
	return (e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
		e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
		e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) /
	       6;
}

void irdm_mesh_stats(const struct irdm_mesh *m, struct irdm_mesh_stats *st)
{
	memset(st, 0, sizeof(*st));
	st->n_nodes = m->n_nodes;
	st->n_tets = m->n_tets;
	st->vol_min_m3 = st->quality_min = INFINITY;
	for (size_t t = 0; t < m->n_tets; t++) {
		const double *p[4];
		double v, q;

		for (int k = 0; k < 4; k++)
			p[k] = &m->pos_m[3 * (size_t)m->tets[4 * t + k]];
		v = fabs(volume(p));
		q = quality(p, v);
		st->vol_min_m3 = fmin(st->vol_min_m3, v);
		st->vol_max_m3 = fmax(st->vol_max_m3, v);
		st->quality_max = fmax(st->quality_max, q);
		if (q < st->quality_min) {
			st->quality_min = q;
			st->worst_tet = t;
		}
	}
	for (int i = 0; i < 3 && m->n_nodes; i++) {
		double lo = INFINITY, hi = -INFINITY;
		for (size_t v = 0; v < m->n_nodes; v++) {
			lo = fmin(lo, m->pos_m[3 * v + i]);
			hi = fmax(hi, m->pos_m[3 * v + i]);
		}
		st->size_m = fmax(st->size_m, hi - lo);
	}
}

int irdm_mesh_stats_text(const struct irdm_mesh *m, const struct irdm_mesh_stats *st,
			 char lines[3][256])
{
	const double *w = &m->pos_m[3 * (size_t)m->tets[4 * st->worst_tet]];
	double span = st->vol_min_m3 > 0 ? st->vol_max_m3 / st->vol_min_m3 : INFINITY;
	int n = 0;

	snprintf(lines[n++], 256,
		 "mesh stats: %zu nodes, %zu tets, %.3g m across; tet volumes %.3g..%.3g m^3 "
		 "(ratio %.2g); shape quality %.3f..%.3f (1: regular), worst tet %zu at "
		 "(%.4g, %.4g, %.4g)",
		 st->n_nodes, st->n_tets, st->size_m, st->vol_min_m3,
		 st->vol_max_m3, span, st->quality_min, st->quality_max, st->worst_tet, w[0], w[1],
		 w[2]);
	if (span > IRDM_MESH_VOL_SPAN_WARN)
		snprintf(lines[n++], 256,
			 "warning: tet volumes span a factor %.2g (more than %.0e): a tiny feature "
			 "grades the mesh, and the eigensolve pays for its smallest elements "
			 "(tetgen switches with -a, or a simpler surface)",
			 span,
			 IRDM_MESH_VOL_SPAN_WARN);
	if (st->size_m > IRDM_MESH_SIZE_WARN_M || st->size_m < IRDM_MESH_SIZE_SMALL_M)
		snprintf(lines[n++], 256,
			 "warning: the object is %.3g m across: is mesh_scale right? (a part "
			 "drawn in millimetres needs mesh_scale = 0.001)",
			 st->size_m);
	return n;
}
