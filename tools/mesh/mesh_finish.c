// SPDX-License-Identifier: MIT
/*
 * Validation of a parsed tetrahedral mesh and extraction of its outward
 * boundary.  Everything downstream (assembly, modal analysis, contact on
 * the surface) assumes what is checked here, so a bad mesh stops at this
 * point with a message that names the offending node or element.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/error.h"
#include "mesh/mesh_priv.h"

/*
 * A tet is degenerate when |6V| <= DEGENERATE_REL * L^3, L its longest
 * edge.  A regular tet has 6V = L^3 / sqrt(2); rounding in the 3x3
 * determinant is a few ulps of L^3 (~1e-15), so 1e-12 sits safely above
 * noise and only catches (near-)flat elements.  It is scale free.
 */
#define DEGENERATE_REL 1e-12

/*
 * Outward faces of a positive tet (n0..n3), each CCW seen from outside;
 * row k is the face opposite node k.
 */
static const unsigned char outward[4][3] = {
	{ 1, 2, 3 },
	{ 0, 3, 2 },
	{ 0, 1, 3 },
	{ 0, 2, 1 },
};

struct face {
	uint32_t v[3]; /* sorted node indices */
	uint32_t tet;
	unsigned char local; /* row of outward[] */
	unsigned char odd;   /* sorting took an odd permutation */
};

uint64_t mesh_node_label(const struct mesh_labels *lab, size_t i)
{
	return lab && lab->node_tag ? lab->node_tag[i] : (uint64_t)i + 1;
}

uint64_t mesh_tet_label(const struct mesh_labels *lab, size_t i)
{
	return lab && lab->tet_tag ? lab->tet_tag[i] : (uint64_t)i + 1;
}

void mesh_labels_free(struct mesh_labels *lab)
{
	free(lab->node_tag);
	free(lab->tet_tag);
	lab->node_tag = NULL;
	lab->tet_tag = NULL;
}

static double sq_dist(const double *a, const double *b)
{
	double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];

	return dx * dx + dy * dy + dz * dz;
}

static int check_nodes(const struct irdm_mesh *m, const struct mesh_labels *lab,
		       char *err, size_t errlen)
{
	size_t i;

	for (i = 0; i < 3 * m->n_nodes; i++) {
		if (!isfinite(m->pos_m[i])) {
			mesh_err(err, errlen, lab->node_what,
				 "node %llu has a non-finite coordinate",
				 (unsigned long long)mesh_node_label(lab, i / 3));
			return IRDM_EFORMAT;
		}
	}
	return 0;
}

static int check_tet_nodes(const struct irdm_mesh *m, size_t e,
			   const struct mesh_labels *lab, char *err, size_t errlen)
{
	const uint32_t *t = m->tets + 4 * e;
	unsigned long long el = mesh_tet_label(lab, e);
	int i, j;

	for (i = 0; i < 4; i++) {
		if (t[i] >= m->n_nodes) {
			mesh_err(err, errlen, lab->tet_what,
				 "element %llu refers to node index %lu, but there are only %zu nodes",
				 el, (unsigned long)t[i], m->n_nodes);
			return IRDM_EFORMAT;
		}
		for (j = 0; j < i; j++) {
			if (t[i] == t[j]) {
				mesh_err(err, errlen, lab->tet_what,
					 "element %llu uses node %llu twice", el,
					 (unsigned long long)mesh_node_label(lab, t[i]));
				return IRDM_EFORMAT;
			}
		}
	}
	return 0;
}

static int check_tet_volume(const struct irdm_mesh *m, size_t e,
			    const struct mesh_labels *lab, char *err, size_t errlen)
{
	const uint32_t *t = m->tets + 4 * e;
	const double *x = m->pos_m;
	unsigned long long el = mesh_tet_label(lab, e);
	double l2 = 0.0, l3, v6;
	int i, j;

	for (i = 0; i < 4; i++)
		for (j = i + 1; j < 4; j++)
			l2 = fmax(l2, sq_dist(x + 3 * t[i], x + 3 * t[j]));
	l3 = l2 * sqrt(l2);
	v6 = mesh_tet_vol6(x, t);
	if (!isfinite(v6) || !isfinite(l3)) {
		mesh_err(err, errlen, lab->tet_what,
			 "element %llu is too large to measure (coordinates overflow)",
			 el);
		return IRDM_EFORMAT;
	}
	if (fabs(v6) <= DEGENERATE_REL * l3) {
		mesh_err(err, errlen, lab->tet_what,
			 "element %llu has zero volume (volume %.3g m^3, longest edge %.3g m)",
			 el, v6 / 6.0, sqrt(l2));
		return IRDM_EFORMAT;
	}
	if (v6 < 0.0) {
		mesh_err(err, errlen, lab->tet_what,
			 "element %llu is inverted (volume %.3g m^3)", el, v6 / 6.0);
		return IRDM_EFORMAT;
	}
	return 0;
}

static int check_referenced(const struct irdm_mesh *m,
			    const struct mesh_labels *lab, char *err, size_t errlen)
{
	unsigned char *used;
	size_t i;
	int ret = 0;

	used = calloc(m->n_nodes, 1);
	if (!used) {
		mesh_err(err, errlen, lab->tet_what, "out of memory");
		return IRDM_ENOMEM;
	}
	for (i = 0; i < 4 * m->n_tets; i++)
		used[m->tets[i]] = 1;
	for (i = 0; i < m->n_nodes; i++) {
		if (!used[i]) {
			mesh_err(err, errlen, lab->node_what,
				 "node %llu is not used by any element",
				 (unsigned long long)mesh_node_label(lab, i));
			ret = IRDM_EFORMAT;
			break;
		}
	}
	free(used);
	return ret;
}

static int face_cmp(const void *pa, const void *pb)
{
	const struct face *a = pa, *b = pb;
	int i;

	for (i = 0; i < 3; i++)
		if (a->v[i] != b->v[i])
			return a->v[i] < b->v[i] ? -1 : 1;
	if (a->tet != b->tet)
		return a->tet < b->tet ? -1 : 1;
	return (int)a->local - (int)b->local;
}

static void swap_u32(uint32_t *a, uint32_t *b, unsigned char *odd)
{
	uint32_t t = *a;

	*a = *b;
	*b = t;
	*odd ^= 1;
}

static void make_face(const uint32_t *tet, uint32_t e, unsigned char k,
		      struct face *f)
{
	int i;

	for (i = 0; i < 3; i++)
		f->v[i] = tet[outward[k][i]];
	f->tet = e;
	f->local = k;
	f->odd = 0;
	if (f->v[0] > f->v[1])
		swap_u32(&f->v[0], &f->v[1], &f->odd);
	if (f->v[1] > f->v[2])
		swap_u32(&f->v[1], &f->v[2], &f->odd);
	if (f->v[0] > f->v[1])
		swap_u32(&f->v[0], &f->v[1], &f->odd);
}

/* A face run of length >= 2 is an error unless it is a proper shared face. */
static int check_shared(const struct face *f, size_t n,
			const struct mesh_labels *lab, char *err, size_t errlen)
{
	unsigned long long a = mesh_node_label(lab, f->v[0]);
	unsigned long long b = mesh_node_label(lab, f->v[1]);
	unsigned long long c = mesh_node_label(lab, f->v[2]);

	if (n > 2) {
		mesh_err(err, errlen, lab->tet_what,
			 "face (%llu %llu %llu) is shared by %zu elements (%llu, %llu, %llu...): non-manifold",
			 a, b, c, n,
			 (unsigned long long)mesh_tet_label(lab, f[0].tet),
			 (unsigned long long)mesh_tet_label(lab, f[1].tet),
			 (unsigned long long)mesh_tet_label(lab, f[2].tet));
		return IRDM_EFORMAT;
	}
	/* Two positive tets on opposite sides see the face with opposite turns. */
	if (f[0].odd == f[1].odd) {
		mesh_err(err, errlen, lab->tet_what,
			 "elements %llu and %llu overlap: both lie on the same side of face (%llu %llu %llu)",
			 (unsigned long long)mesh_tet_label(lab, f[0].tet),
			 (unsigned long long)mesh_tet_label(lab, f[1].tet),
			 a, b, c);
		return IRDM_EFORMAT;
	}
	return 0;
}

/*
 * Boundary faces are those that occur once.  Sorting the 4n faces by their
 * sorted node triple makes shared faces adjacent: O(n log n).
 */
static int compute_boundary(struct irdm_mesh *m, const struct mesh_labels *lab,
			    char *err, size_t errlen)
{
	size_t nf = 4 * m->n_tets, i, j, k, nb = 0;
	struct face *f;
	uint32_t *tris = NULL;
	int ret = IRDM_ENOMEM;

	f = malloc(nf * sizeof(*f));
	if (!f)
		goto fail_oom;
	for (i = 0; i < m->n_tets; i++)
		for (j = 0; j < 4; j++)
			make_face(m->tets + 4 * i, (uint32_t)i, (unsigned char)j,
				  &f[4 * i + j]);
	qsort(f, nf, sizeof(*f), face_cmp);

	/* Every boundary face is kept; there are at most nf of them. */
	tris = malloc(nf * 3 * sizeof(*tris));
	if (!tris)
		goto fail_oom;
	for (i = 0; i < nf; i = j) {
		for (j = i + 1; j < nf; j++)
			if (memcmp(f[j].v, f[i].v, sizeof(f[i].v)))
				break;
		if (j - i > 1) {
			ret = check_shared(f + i, j - i, lab, err, errlen);
			if (ret)
				goto out_free;
			continue;
		}
		for (k = 0; k < 3; k++)
			tris[3 * nb + k] = m->tets[4 * (size_t)f[i].tet +
						   outward[f[i].local][k]];
		nb++;
	}
	free(m->tris);
	m->tris = tris;
	m->n_tris = nb;
	tris = NULL;
	ret = 0;
	goto out_free;

fail_oom:
	mesh_err(err, errlen, lab->tet_what, "out of memory computing the boundary");
out_free:
	free(tris);
	free(f);
	return ret;
}

int mesh_finish_labeled(struct irdm_mesh *m, const struct mesh_labels *lab,
			char *err, size_t errlen)
{
	size_t e;
	int ret = IRDM_EFORMAT;

	if (!m->n_nodes || !m->n_tets || !m->pos_m || !m->tets) {
		mesh_err(err, errlen, lab->tet_what,
			 "mesh is empty (%zu nodes, %zu tetrahedra)",
			 m->n_nodes, m->n_tets);
		goto fail;
	}
	if (m->n_nodes > MESH_MAX_ITEMS || m->n_tets > MESH_MAX_ITEMS) {
		mesh_err(err, errlen, lab->tet_what,
			 "mesh too large (%zu nodes, %zu tetrahedra; limit %u)",
			 m->n_nodes, m->n_tets, MESH_MAX_ITEMS);
		goto fail;
	}
	ret = check_nodes(m, lab, err, errlen);
	for (e = 0; !ret && e < m->n_tets; e++)
		ret = check_tet_nodes(m, e, lab, err, errlen);
	for (e = 0; !ret && e < m->n_tets; e++)
		ret = check_tet_volume(m, e, lab, err, errlen);
	if (!ret)
		ret = check_referenced(m, lab, err, errlen);
	if (!ret)
		ret = compute_boundary(m, lab, err, errlen);
	if (ret)
		goto fail;
	return IRDM_OK;

fail:
	irdm_mesh_free(m);
	return ret;
}

int irdm_mesh_finish(struct irdm_mesh *m, const char *what, char *err,
		     size_t errlen)
{
	struct mesh_labels lab = { what, what, NULL, NULL };

	return mesh_finish_labeled(m, &lab, err, errlen);
}
