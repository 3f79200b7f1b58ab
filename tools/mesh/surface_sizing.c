// SPDX-License-Identifier: MIT
/*
 * Tetrahedralise a closed surface to a size: a target node count or a
 * largest tet volume, turned into tetgen's -a bound (and a radius-edge
 * bound -q) and re-run a few times until the node count is near the
 * target.
 *
 * Why the quality bound moves: tetgen grades its tets down to the smallest
 * surface triangle, and the radius-edge bound decides how fast they grow
 * again.  A CAD part with 0.5 mm fillets on a 60 mm body (972 triangles)
 * gives 35,873 nodes under -pq1.414 and still 20,013 under -pq2a400 (the
 * volume bound is not what binds), but 8,237 under -pq4 and 3,553 under
 * -pq10a40 (measured with tetgen 1.5).  So while there are too many nodes
 * the search loosens the quality bound (1.414, 4, 16) as well as scaling
 * the volume bound by the excess; too few, it scales the volume bound.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "irdm/error.h"
#include "mesh/mesh_priv.h"

#define SIZING_RUNS 6      /* tetgen runs at most */
#define SIZING_FACTOR 2.0  /* accepted: target / 2 .. target * 2 nodes */
#define NODES_PER_TET 0.25 /* about, for quality meshes of a few 1000 nodes */
#define RHO_START 1.414    /* the unsized default's radius-edge bound */
#define RHO_MAX 16.0

/* Enclosed volume (file units^3) by the divergence theorem; outward or
 * inward orientation alike (absolute value). */
double irdm_surface_volume(const struct irdm_surface *s)
{
	double v = 0;

	for (size_t t = 0; t < s->n_tris; t++) {
		const double *a = &s->pos_m[3 * s->tris[3 * t]];
		const double *b = &s->pos_m[3 * s->tris[3 * t + 1]];
		const double *c = &s->pos_m[3 * s->tris[3 * t + 2]];
		v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
		     a[2] * (b[0] * c[1] - b[1] * c[0]);
	}
	return fabs(v) / 6;
}

struct sizing_try {
	double rho, vol; /* -q rho -a vol */
	char sw[64];
};

static void try_switches(struct sizing_try *t)
{
	snprintf(t->sw, sizeof(t->sw), "pq%.4ga%.6g", t->rho, t->vol);
}

/* How far n is from the target, as a factor >= 1. */
static double off_by(size_t n, unsigned target)
{
	double r = (double)n / (double)target;

	return r >= 1 ? r : 1 / r;
}

/* The next try after n nodes: the volume bound scaled by n / target (nodes
 * go about as 1 / volume), and, too many, the quality bound loosened. */
static void next_try(struct sizing_try *t, size_t n, unsigned target)
{
	double r = (double)n / (double)target;

	if (r > 1 && t->rho < RHO_MAX)
		t->rho = t->rho < 4 ? 4 : RHO_MAX;
	t->vol *= r;
	try_switches(t);
}

static int run_fixed(const struct irdm_surface *s, struct irdm_mesh_sizing *sz, const char *what,
		     struct irdm_mesh *m, char *err, size_t errlen)
{
	struct sizing_try t = { RHO_START, sz->max_tet_volume, "" };

	try_switches(&t);
	int ret = irdm_surface_tetrahedralize(s, t.sw, what, m, err, errlen);
	if (!ret)
		snprintf(sz->note, sizeof(sz->note),
			 "mesh sizing: max_tet_volume %.3g (file units^3): tetgen -%s, %zu nodes",
			 sz->max_tet_volume, t.sw, m->n_nodes);
	return ret;
}

int irdm_surface_tetrahedralize_sized(const struct irdm_surface *s, struct irdm_mesh_sizing *sz,
				      const char *what, struct irdm_mesh *m, char *err,
				      size_t errlen)
{
	struct irdm_mesh best;
	struct sizing_try t, kept;
	int runs = 0, ret = IRDM_OK;

	sz->note[0] = '\0';
	memset(m, 0, sizeof(*m));
	if (sz->switches || (!sz->target_nodes && !(sz->max_tet_volume > 0)))
		return irdm_surface_tetrahedralize(s, sz->switches, what, m, err, errlen);
	if (!sz->target_nodes)
		return run_fixed(s, sz, what, m, err, errlen);
	t.rho = RHO_START;
	t.vol = irdm_surface_volume(s) / (sz->target_nodes / NODES_PER_TET);
	if (sz->max_tet_volume > 0 && t.vol > sz->max_tet_volume)
		t.vol = sz->max_tet_volume;
	try_switches(&t);
	kept = t;
	memset(&best, 0, sizeof(best));
	for (runs = 1; runs <= SIZING_RUNS; runs++) {
		struct irdm_mesh cur;
		ret = irdm_surface_tetrahedralize(s, t.sw, what, &cur, err, errlen);
		if (ret)
			break;
		size_t n = cur.n_nodes;
		if (!best.n_nodes || off_by(cur.n_nodes, sz->target_nodes) <
					     off_by(best.n_nodes, sz->target_nodes)) {
			irdm_mesh_free(&best);
			best = cur;
			kept = t;
		} else {
			irdm_mesh_free(&cur);
		}
		if (off_by(best.n_nodes, sz->target_nodes) <= SIZING_FACTOR)
			break;
		next_try(&t, n, sz->target_nodes);
		if (sz->max_tet_volume > 0 && t.vol > sz->max_tet_volume)
			t.vol = sz->max_tet_volume;
	}
	if (ret) {
		irdm_mesh_free(&best);
		return ret;
	}
	*m = best;
	snprintf(sz->note, sizeof(sz->note),
		 "mesh sizing: target_nodes %u: %d tetgen run%s, kept -%s: %zu nodes", sz->target_nodes,
		 runs > SIZING_RUNS ? SIZING_RUNS : runs, runs == 1 ? "" : "s", kept.sw, m->n_nodes);
	return IRDM_OK;
}
