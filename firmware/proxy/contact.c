/* SPDX-License-Identifier: MIT */
/*
 * Contact detection on the deformed surface: closest point query over the
 * image's CONTACT_BVH and a frictionless god-object: the constraint-plane
 * god-object of Zilles and Salisbury (1995), kept local as Ruspini et al.'s
 * virtual proxy is (a walk over the touchable triangles; the faces beyond
 * convex edges and beyond the touchable area's rim end the contact, a
 * concave edge holds the proxy; docs/architecture.md).  Runs in the force
 * loop: no allocation, no system call, no recursion, bounded work (the
 * faces beyond the touchable area's rim are a table made at set-up:
 * irdm_contact_beyond_build()).
 *
 * The BVH boxes bound the REST surface; the surface the device touches is
 * rest + u.  With |u| <= max_disp_m for every node, a box grown by
 * max_disp_m on every side bounds the displaced triangles of its subtree,
 * so pruning on the grown boxes is exact.
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "irdm/contact.h"
#include "irdm/vec3.h"

_Static_assert(IRDM_CONTACT_STACK > IRDM_BVH_MAX_DEPTH, "stack holds a root-leaf path");

/* Two distances whose squares differ by less than this are a tie (the same
 * edge point seen from its two triangles differs by a few ulps). */
#define TIE_REL 1e-13
#define TIE_ABS 1e-30
/* Relative slack of the rest-distance prune (tri_far): far above rounding. */
#define FAR_SLACK 1e-9
/* sin^2 of the smallest angle of a triangle that still has a normal */
#define DEGENERATE_SIN2 1e-24
/* A barycentric within this of zero puts a point on the edge (rounding of
 * the projection of a point on a shared edge is a few ulps either way). */
#define ON_EDGE 1e-12

static void disp_of(const struct irdm_contact_disp *d, uint32_t row, double u[3])
{
	if (d && d->u_m) {
		u[0] = d->u_m[3 * (size_t)row];
		u[1] = d->u_m[3 * (size_t)row + 1];
		u[2] = d->u_m[3 * (size_t)row + 2];
	} else if (d && d->fn) {
		d->fn(d->ctx, row, u);
	} else {
		irdm_v3_zero(u);
	}
}

int irdm_contact_mesh_init(struct irdm_contact_mesh *cm, const struct irdm_image *img)
{
	const uint8_t *base;
	const struct irdm_bvh_header *h;

	memset(cm, 0, sizeof(*cm));
	if (!img || !img->meta || !img->contact_bvh)
		return IRDM_EINVAL;
	h = img->contact_bvh;
	base = (const uint8_t *)h;
	cm->img = img;
	cm->hdr = h;
	cm->nodes = (const struct irdm_bvh_node *)(base + h->nodes_offset);
	cm->index = (const uint32_t *)(base + h->index_offset);
	cm->adj = (const uint32_t *)(base + h->adj_offset);
	cm->col_of_row = (const uint32_t *)(base + h->col_of_row_offset);
	cm->tris = img->tris;
	cm->rest = img->nodes;
	cm->n_tris = img->meta->n_tris;
	cm->n_rows = img->meta->n_nodes;
	return IRDM_OK;
}

size_t irdm_contact_beyond_size(const struct irdm_contact_mesh *cm)
{
	return 3 * (size_t)cm->n_tris * sizeof(uint32_t);
}

/* The lowest-index SURFACE triangle other than t with vertices a and b. */
static uint32_t search_beyond(const struct irdm_contact_mesh *cm, uint32_t t, uint32_t a,
			      uint32_t b)
{
	for (uint32_t u = 0; u < cm->n_tris; u++) {
		const uint32_t *w = &cm->tris[3 * (size_t)u];
		bool has_a = w[0] == a || w[1] == a || w[2] == a;
		bool has_b = w[0] == b || w[1] == b || w[2] == b;

		if (u != t && has_a && has_b)
			return u;
	}
	return IRDM_BVH_NONE;
}

uint32_t irdm_contact_beyond_build(struct irdm_contact_mesh *cm, uint32_t *table)
{
	uint32_t searched = 0;

	for (uint32_t t = 0; t < cm->n_tris; t++) {
		const uint32_t *v = &cm->tris[3 * (size_t)t];
		bool touchable = irdm_contact_tri_contactable(cm, t);

		for (unsigned e = 0; e < 3; e++) {
			uint32_t u = cm->adj[3 * (size_t)t + e];

			if (u == IRDM_BVH_NONE && touchable) {
				u = search_beyond(cm, t, v[e], v[(e + 1) % 3]);
				searched++;
			}
			table[3 * (size_t)t + e] = u;
		}
	}
	cm->beyond = table;
	return searched;
}

bool irdm_contact_tri_contactable(const struct irdm_contact_mesh *cm, uint32_t t)
{
	const uint32_t *v;

	if (t >= cm->n_tris)
		return false;
	v = &cm->tris[3 * (size_t)t];
	return cm->col_of_row[v[0]] != IRDM_BVH_NONE && cm->col_of_row[v[1]] != IRDM_BVH_NONE &&
	       cm->col_of_row[v[2]] != IRDM_BVH_NONE;
}

void irdm_contact_tri_pos(const struct irdm_contact_mesh *cm, const struct irdm_contact_disp *d,
			  uint32_t t, double v[3][3])
{
	for (unsigned k = 0; k < 3; k++) {
		uint32_t r = cm->tris[3 * (size_t)t + k];
		const float *x = cm->rest[r].pos_m;
		double u[3];

		disp_of(d, r, u);
		for (unsigned a = 0; a < 3; a++)
			v[k][a] = (double)x[a] + u[a];
	}
}

/* Unit outward normal of (a, b, c); false for a zero-area triangle. */
static bool tri_normal(const double v[3][3], double n[3])
{
	double ab[3], ac[3], nn;

	irdm_v3_sub(ab, v[1], v[0]);
	irdm_v3_sub(ac, v[2], v[0]);
	irdm_v3_cross(n, ab, ac);
	nn = irdm_v3_dot(n, n);
	if (!(nn > DEGENERATE_SIN2 * irdm_v3_dot(ab, ab) * irdm_v3_dot(ac, ac)) || !isfinite(nn))
		return false;
	irdm_v3_scale(n, 1 / sqrt(nn), n);
	return true;
}

bool irdm_contact_tri_normal(const struct irdm_contact_mesh *cm, const struct irdm_contact_disp *d,
			     uint32_t t, double n[3])
{
	double v[3][3];

	if (t >= cm->n_tris)
		return false;
	irdm_contact_tri_pos(cm, d, t, v);
	return tri_normal(v, n);
}

/* Closest point on segment ab: parameter t of a + t (b - a). */
static double seg_param(const double *a, const double *b, const double *p)
{
	double ab[3], ap[3], l2, t;

	irdm_v3_sub(ab, b, a);
	irdm_v3_sub(ap, p, a);
	l2 = irdm_v3_dot(ab, ab);
	if (!(l2 > 0))
		return 0;
	t = irdm_v3_dot(ap, ab) / l2;
	return t < 0 ? 0 : t > 1 ? 1 :
				   t;
}

static double finish(const double *a, const double *b, const double *c, const double *p,
		     const double *bary, double *q)
{
	double d[3];

	irdm_v3_bary(q, bary, a, b, c);
	irdm_v3_sub(d, p, q);
	return irdm_v3_dot(d, d);
}

/* A triangle with no interior: the best of its three edges. */
static double closest_on_edges(const double *a, const double *b, const double *c,
			       const double *p, double *bary, double *q)
{
	const double *v[3] = { a, b, c };
	double best = INFINITY, bb[3], qq[3];

	for (unsigned e = 0; e < 3; e++) {
		double t = seg_param(v[e], v[(e + 1) % 3], p), d2;

		bb[e] = 1 - t;
		bb[(e + 1) % 3] = t;
		bb[(e + 2) % 3] = 0;
		d2 = finish(a, b, c, p, bb, qq);
		if (d2 < best) {
			best = d2;
			memcpy(bary, bb, sizeof(bb));
			memcpy(q, qq, sizeof(qq));
		}
	}
	return best;
}

/* One closest point query on a triangle: its vertices, the query point,
 * and where the answer goes. */
struct tri_query {
	const double *a, *b, *c, *p;
	double *bary, *q;
};

/* Answer with the point of weights (u, v, w); returns its squared distance. */
static double answer(const struct tri_query *tq, double u, double v, double w)
{
	tq->bary[0] = u;
	tq->bary[1] = v;
	tq->bary[2] = w;
	return finish(tq->a, tq->b, tq->c, tq->p, tq->bary, tq->q);
}

/* Answer with the point at t = num / den (0 unless den > 0) on the edge
 * from vertex i to vertex j. */
static double answer_edge(const struct tri_query *tq, unsigned i, unsigned j, double num,
			  double den)
{
	double t = den > 0 ? num / den : 0, w[3] = { 0, 0, 0 };

	w[i] = 1 - t;
	w[j] = t;
	return answer(tq, w[0], w[1], w[2]);
}

/* Where p lies seen from vertex v: (p - v) . ab and (p - v) . ac. */
static void vertex_dots(const double *ab, const double *ac, const double *p, const double *v,
			double *d_ab, double *d_ac)
{
	double vp[3];

	irdm_v3_sub(vp, p, v);
	*d_ab = irdm_v3_dot(ab, vp);
	*d_ac = irdm_v3_dot(ac, vp);
}

double irdm_contact_closest_on_tri(const double a[3], const double b[3], const double c[3],
				   const double p[3], double bary[3], double q[3])
{
	const struct tri_query tq = { a, b, c, p, bary, q };
	double ab[3], ac[3], n[3];
	double d1, d2, d3, d4, d5, d6, va, vb, vc, den;

	irdm_v3_sub(ab, b, a);
	irdm_v3_sub(ac, c, a);
	/* The region tests below rely on the signs of areas: meaningless for
	 * (nearly) collinear vertices, whose closest point is on an edge. */
	irdm_v3_cross(n, ab, ac);
	if (!(irdm_v3_dot(n, n) > DEGENERATE_SIN2 * irdm_v3_dot(ab, ab) * irdm_v3_dot(ac, ac)))
		return closest_on_edges(a, b, c, p, bary, q);
	vertex_dots(ab, ac, p, a, &d1, &d2);
	if (d1 <= 0 && d2 <= 0) /* vertex region a */
		return answer(&tq, 1, 0, 0);
	vertex_dots(ab, ac, p, b, &d3, &d4);
	if (d3 >= 0 && d4 <= d3) /* vertex region b */
		return answer(&tq, 0, 1, 0);
	vc = d1 * d4 - d3 * d2;
	if (vc <= 0 && d1 >= 0 && d3 <= 0) /* edge ab; d1 - d3 = |ab|^2 */
		return answer_edge(&tq, 0, 1, d1, d1 - d3);
	vertex_dots(ab, ac, p, c, &d5, &d6);
	if (d6 >= 0 && d5 <= d6) /* vertex region c */
		return answer(&tq, 0, 0, 1);
	vb = d5 * d2 - d1 * d6;
	if (vb <= 0 && d2 >= 0 && d6 <= 0) /* edge ac; d2 - d6 = |ac|^2 */
		return answer_edge(&tq, 0, 2, d2, d2 - d6);
	va = d3 * d6 - d5 * d4;
	if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) /* edge bc */
		return answer_edge(&tq, 1, 2, d4 - d3, (d4 - d3) + (d5 - d6));
	den = va + vb + vc; /* = |ab x ac|^2 */
	if (!(den > 0) || !isfinite(den))
		return closest_on_edges(a, b, c, p, bary, q);
	vb /= den;
	vc /= den;
	return answer(&tq, 1 - vb - vc, vb, vc);
}

/* Squared distance from p to the box of nd grown by g. */
static double box_d2(const struct irdm_bvh_node *nd, const double *p, double g)
{
	double d2 = 0;

	for (unsigned a = 0; a < 3; a++) {
		double lo = (double)nd->lo[a] - g, hi = (double)nd->hi[a] + g, e = 0;

		if (p[a] < lo)
			e = lo - p[a];
		else if (p[a] > hi)
			e = p[a] - hi;
		d2 += e * e;
	}
	return d2;
}

struct query {
	const struct irdm_contact_mesh *cm;
	const struct irdm_contact_disp *d;
	const double *p;
	double grow_m;   /* max_disp_m: |u| of every node is below it */
	double best;     /* squared distance bound / best so far */
	double best_cos; /* |cos| between p - q and the normal */
	bool found;
	struct irdm_contact_hit *hit;
};

/*
 * Whether triangle t cannot hold an answer, judged from its REST position
 * alone (no displacement is asked for): every point of the displaced
 * triangle is a point of the rest one moved by a convex combination of its
 * vertices' u, so by at most grow_m, and its distance to p is at least the
 * rest distance - grow_m.  The slack keeps rounding on the side of looking.
 */
static bool tri_far(const struct query *qr, uint32_t t)
{
	double v[3][3], bary[3], q[3], d;

	irdm_contact_tri_pos(qr->cm, NULL, t, v);
	d = sqrt(irdm_contact_closest_on_tri(v[0], v[1], v[2], qr->p, bary, q)) - qr->grow_m;
	return d > 0 && d * d > (qr->best * (1 + TIE_REL) + TIE_ABS) * (1 + FAR_SLACK) + TIE_ABS;
}

static void query_tri(struct query *qr, uint32_t t)
{
	double v[3][3], n[3], bary[3], q[3], pq[3], d2, s, c;
	bool better;

	if (tri_far(qr, t))
		return;
	irdm_contact_tri_pos(qr->cm, qr->d, t, v);
	if (!tri_normal(v, n))
		return;
	d2 = irdm_contact_closest_on_tri(v[0], v[1], v[2], qr->p, bary, q);
	if (!(d2 <= qr->best * (1 + TIE_REL) + TIE_ABS))
		return;
	irdm_v3_sub(pq, qr->p, q);
	s = irdm_v3_dot(pq, n);
	c = d2 > 0 ? fabs(s) / sqrt(d2) : 1;
	if (!qr->found || d2 < qr->best * (1 - TIE_REL) - TIE_ABS)
		better = d2 <= qr->best;
	else /* a tie: the face that sees p best gives the sign */
		better = c > qr->best_cos || (c == qr->best_cos && d2 < qr->best);
	if (!better)
		return;
	qr->found = true;
	qr->best = d2;
	qr->best_cos = c;
	qr->hit->tri = t;
	memcpy(qr->hit->bary, bary, sizeof(bary));
	memcpy(qr->hit->point_m, q, sizeof(q));
	memcpy(qr->hit->normal, n, sizeof(n));
	qr->hit->dist_m = s < 0 ? -sqrt(d2) : sqrt(d2);
}

int irdm_contact_closest(const struct irdm_contact_mesh *cm, const struct irdm_contact_disp *d,
			 double max_disp_m, const double p[3], double radius_m,
			 struct irdm_contact_hit *hit)
{
	struct query qr = { cm, d, p, max_disp_m, radius_m * radius_m, 0, false, hit };
	uint32_t stack[IRDM_CONTACT_STACK];
	unsigned sp = 0;

	if (!cm || !cm->hdr || !hit || !p || !irdm_v3_finite(p) || !(radius_m >= 0) ||
	    !isfinite(radius_m) || !(max_disp_m >= 0) || !isfinite(max_disp_m))
		return IRDM_EINVAL;
	if (!cm->hdr->n_bvh_nodes)
		return 0;
	stack[sp++] = 0;
	while (sp) {
		const struct irdm_bvh_node *nd = &cm->nodes[stack[--sp]];
		uint32_t l, r;
		double dl, dr;

		if (box_d2(nd, p, max_disp_m) > qr.best * (1 + TIE_REL) + TIE_ABS)
			continue;
		if (!(nd->count_or_right & IRDM_BVH_INTERNAL)) {
			for (uint32_t k = 0; k < nd->count_or_right; k++)
				query_tri(&qr, cm->index[nd->left_or_first + k]);
			continue;
		}
		if (sp + 2 > IRDM_CONTACT_STACK) /* never: depth <= 48 */
			return IRDM_EINVAL;
		l = nd->left_or_first;
		r = nd->count_or_right & ~IRDM_BVH_INTERNAL;
		dl = box_d2(&cm->nodes[l], p, max_disp_m);
		dr = box_d2(&cm->nodes[r], p, max_disp_m);
		/* nearer child on top: it shrinks the bound first */
		if (dl <= dr) {
			stack[sp++] = r;
			stack[sp++] = l;
		} else {
			stack[sp++] = l;
			stack[sp++] = r;
		}
	}
	return qr.found ? 1 : 0;
}

/* ------------------------------------------------------------ god-object */

void irdm_proxy_config_default(struct irdm_proxy_config *cfg)
{
	cfg->radius_m = 0.01;
	cfg->max_disp_m = 0.05;
	cfg->max_walk = 16;
	cfg->mu_s = 0;
	cfg->mu_d = 0;
}

void irdm_proxy_reset(struct irdm_proxy *px)
{
	memset(px, 0, sizeof(*px));
}

/*
 * Barycentrics of the projection of p on the plane of v (not clamped);
 * false for a zero-area triangle.
 */
static bool plane_bary(const double v[3][3], const double *p, double *lam)
{
	double ab[3], ac[3], ap[3], n[3], x[3], nn;

	irdm_v3_sub(ab, v[1], v[0]);
	irdm_v3_sub(ac, v[2], v[0]);
	irdm_v3_sub(ap, p, v[0]);
	irdm_v3_cross(n, ab, ac);
	nn = irdm_v3_dot(n, n);
	if (!(nn > DEGENERATE_SIN2 * irdm_v3_dot(ab, ab) * irdm_v3_dot(ac, ac)) || !isfinite(nn))
		return false;
	irdm_v3_cross(x, ap, ac);
	lam[1] = irdm_v3_dot(x, n) / nn;
	irdm_v3_cross(x, ab, ap);
	lam[2] = irdm_v3_dot(x, n) / nn;
	lam[0] = 1 - lam[1] - lam[2];
	return true;
}

/*
 * The neighbour to walk to: across the edge opposite the most negative
 * barycentric that has a neighbour other than `from` (going back means a
 * concave crease: stay).  Edge e of the image joins v[e] and v[e + 1], so
 * the edge opposite vertex i is (i + 1) % 3.
 */
static uint32_t next_tri(const struct irdm_contact_mesh *cm, uint32_t t, const double *lam,
			 uint32_t from)
{
	unsigned order[3] = { 0, 1, 2 };

	for (unsigned i = 0; i < 2; i++) /* sort vertices by lam, ascending */
		for (unsigned j = 0; j + 1 < 3 - i; j++)
			if (lam[order[j + 1]] < lam[order[j]]) {
				unsigned x = order[j];

				order[j] = order[j + 1];
				order[j + 1] = x;
			}
	for (unsigned k = 0; k < 3 && lam[order[k]] < -ON_EDGE; k++) {
		uint32_t u = cm->adj[3 * (size_t)t + (order[k] + 1) % 3];

		if (u != IRDM_BVH_NONE && u != from)
			return u;
	}
	return IRDM_BVH_NONE;
}

static bool inside_tri(const double *lam)
{
	return lam[0] >= -ON_EDGE && lam[1] >= -ON_EDGE && lam[2] >= -ON_EDGE;
}

/*
 * The SURFACE triangle other than t on edge e of t, touchable or not:
 * the set-up's table (IRDM_BVH_NONE for an edge of an open surface).
 */
static uint32_t face_beyond(const struct irdm_contact_mesh *cm, uint32_t t, unsigned e)
{
	return cm->beyond ? cm->beyond[3 * (size_t)t + e] : cm->adj[3 * (size_t)t + e];
}

/*
 * Outward normal of the face beyond edge e of t (vertices v, normal n):
 * the neighbour's, or for an edge of an open surface a wall standing on
 * the edge at right angles to t.  False for a degenerate neighbour.
 */
static bool normal_beyond(const struct irdm_contact_mesh *cm, const struct irdm_contact_disp *d,
			  uint32_t t, unsigned e, const double v[3][3], const double *n,
			  double *nu)
{
	uint32_t u = face_beyond(cm, t, e);
	double w[3][3], ed[3], len;

	if (u != IRDM_BVH_NONE) {
		irdm_contact_tri_pos(cm, d, u, w);
		return tri_normal(w, nu);
	}
	irdm_v3_sub(ed, v[(e + 1) % 3], v[e]);
	irdm_v3_cross(nu, ed, n); /* counter-clockwise: points away from t */
	len = sqrt(irdm_v3_dot(nu, nu));
	if (!(len > 0))
		return false;
	irdm_v3_scale(nu, 1 / len, nu);
	return true;
}

/*
 * Whether p, behind the plane of t, is outside the object by the face
 * beyond one of t's edges: the edges p projects beyond (where the walk
 * stopped), and the edges on the touchable area's rim, whose faces
 * beyond are display-only and would otherwise never be looked at.  The
 * constraint planes of the god-object (Zilles and Salisbury 1995): at a
 * convex edge the object is the intersection of the two faces'
 * half-spaces, so p in front of the neighbour's plane is outside and the
 * contact ends; at a concave edge it is their union, and p behind t is
 * inside: the proxy stays on t, or on the edge where both planes
 * constrain it.
 */
static bool outside_beyond(const struct irdm_contact_mesh *cm, const struct irdm_contact_disp *d,
			   uint32_t t, const double v[3][3], const double *n, const double *lam,
			   const double *p)
{
	for (unsigned e = 0; e < 3; e++) {
		unsigned opp = (e + 2) % 3;
		bool rim = cm->adj[3 * (size_t)t + e] == IRDM_BVH_NONE;
		double nu[3], to_opp[3], to_p[3];

		if ((!rim && !(lam[opp] < -ON_EDGE)) || !normal_beyond(cm, d, t, e, v, n, nu))
			continue;
		irdm_v3_sub(to_opp, v[opp], v[e]);
		irdm_v3_sub(to_p, p, v[e]);
		if (irdm_v3_dot(nu, to_opp) <= 0 && irdm_v3_dot(nu, to_p) > 0)
			return true;
	}
	return false;
}

/*
 * The same point on a shared edge or vertex belongs to every triangle
 * around it; the proxy takes the one of lowest index among those that
 * hold p's projection, so the choice is a function of where p is, not of
 * where the proxy came from (no hysteresis), and a stroke along an edge
 * keeps one triangle, and so one engine site, as a stroke inside a
 * triangle does.  Each step goes to a lower index: bounded.
 */
static uint32_t lowest_holder(const struct irdm_contact_mesh *cm,
			      const struct irdm_contact_disp *d, uint32_t t, double v[3][3],
			      double *lam, const double *p)
{
	for (unsigned pass = 0; pass < IRDM_CONTACT_MAX_WALK; pass++) {
		uint32_t best = t;
		double bv[3][3], bl[3];

		for (unsigned i = 0; i < 3; i++) {
			uint32_t u = cm->adj[3 * (size_t)t + (i + 1) % 3];
			double w[3][3], l[3];

			if (!(lam[i] <= ON_EDGE) || u == IRDM_BVH_NONE || u >= best)
				continue;
			irdm_contact_tri_pos(cm, d, u, w);
			if (!plane_bary(w, p, l) || !inside_tri(l))
				continue;
			best = u;
			memcpy(bv, w, sizeof(w));
			memcpy(bl, l, sizeof(l));
		}
		if (best == t)
			break;
		t = best;
		memcpy(v, bv, sizeof(bv));
		memcpy(lam, bl, sizeof(bl));
	}
	return t;
}

void irdm_proxy_force(struct irdm_proxy *px, const double force_n[3])
{
	px->force_known = px->active && irdm_v3_finite(force_n);
	memcpy(px->force_n, force_n, sizeof(px->force_n));
}

static int proxy_release(struct irdm_proxy *px, int ret)
{
	px->active = false;
	px->force_known = false;
	return ret;
}

/* Fill the proxy from its triangle t (vertices v) and weights lam. */
static void proxy_set(struct irdm_proxy *px, uint32_t t, const double v[3][3], const double *lam,
		      const double *p, unsigned steps)
{
	double n[3], pq[3];

	tri_normal(v, n);
	px->tri = t;
	memcpy(px->bary, lam, sizeof(px->bary));
	irdm_v3_bary(px->point_m, lam, v[0], v[1], v[2]);
	memcpy(px->normal, n, sizeof(n));
	irdm_v3_sub(pq, p, px->point_m);
	px->depth_m = irdm_v3_dot(pq, n);
	px->steps = steps;
}

/*
 * A new contact: the device has crossed the surface at the closest point,
 * unless it is outside the object by a face beyond the hit triangle's
 * edges (beside an edge of the touchable area, where the closest
 * touchable point is on the rim and its sign says nothing).
 */
static int proxy_touch(struct irdm_proxy *px, const struct irdm_contact_mesh *cm,
		       const struct irdm_contact_disp *d, const struct irdm_proxy_config *cfg,
		       const double p[3])
{
	struct irdm_contact_hit hit;
	double v[3][3], lam[3], n[3];
	uint32_t t;
	int r = irdm_contact_closest(cm, d, cfg->max_disp_m, p, cfg->radius_m, &hit);

	if (r < 0)
		return r;
	if (r == 0 || hit.dist_m > 0)
		return IRDM_PROXY_FREE;
	t = hit.tri;
	irdm_contact_tri_pos(cm, d, t, v);
	if (!plane_bary(v, p, lam) || !tri_normal(v, n))
		return IRDM_PROXY_FREE;
	if (outside_beyond(cm, d, t, v, n, lam, p))
		return IRDM_PROXY_FREE;
	px->active = true;
	if (inside_tri(lam) && (t = lowest_holder(cm, d, t, v, lam, p)) != hit.tri) {
		proxy_set(px, t, v, lam, p, 0);
		return IRDM_PROXY_TOUCH;
	}
	px->tri = t; /* as the query found it */
	memcpy(px->bary, hit.bary, sizeof(px->bary));
	memcpy(px->point_m, hit.point_m, sizeof(px->point_m));
	memcpy(px->normal, hit.normal, sizeof(px->normal));
	px->depth_m = hit.dist_m;
	px->steps = 0;
	return IRDM_PROXY_TOUCH;
}

/*
 * The projection of p on the displaced surface, walking from triangle t:
 * the triangle, its vertices and p's weights on it (clamped to the
 * max_walk steps: lam as the plane gives it, q not set).  Return: 1
 * inside a triangle (q the point), 0 stopped at an edge, -1 a triangle
 * crushed flat.
 */
static int walk(const struct irdm_contact_mesh *cm, const struct irdm_contact_disp *d,
		unsigned max_walk, const double *p, uint32_t *tp, double v[3][3], double *lam,
		double *q, unsigned *steps)
{
	uint32_t t = *tp, from = IRDM_BVH_NONE;

	*steps = 0;
	for (;;) {
		uint32_t u;

		irdm_contact_tri_pos(cm, d, t, v);
		if (!plane_bary(v, p, lam))
			return -1;
		if (inside_tri(lam)) {
			*tp = lowest_holder(cm, d, t, v, lam, p);
			irdm_v3_bary(q, lam, v[0], v[1], v[2]);
			return 1;
		}
		u = *steps < max_walk ? next_tri(cm, t, lam, from) : IRDM_BVH_NONE;
		if (u == IRDM_BVH_NONE) {
			*tp = t;
			return 0;
		}
		from = t;
		t = u;
		(*steps)++;
	}
}

/*
 * Coulomb friction on the proxy: the friction cone of the god-object
 * (Salisbury et al. 1995; Harwin and Melder 2002).  The proxy is a point
 * of the surface (triangle and weights: it moves with the surface); the
 * frictionless proxy q is the device's projection, depth dn behind the
 * surface.  With the coupling a spring between the device and the proxy,
 * the tangential force over the normal one is |q - proxy| / dn: while it
 * is within mu_s the proxy sticks; beyond, it slides toward q until the
 * ratio is mu_d, on the cone's rim.  The proxy only ever moves toward q,
 * which shortens the spring: it never gives the device energy (passive by
 * construction); what the move takes out of the spring is what friction
 * dissipates.  Given the force the contact made (irdm_proxy_force()), the
 * same test is made on it: F_t / F_n in place of |q - proxy| / dn.
 * Return: 0; -1 if the slid-to point cannot be placed.
 */
static int friction(struct irdm_proxy *px, const struct irdm_contact_mesh *cm,
		    const struct irdm_contact_disp *d, const struct irdm_proxy_config *cfg,
		    unsigned max_walk, uint32_t anchor_tri, const double *anchor_bary,
		    double depth)
{
	double v[3][3], a[3], tv[3], lam[3], q[3], c[3], tl, dn = -depth;
	uint32_t t;
	unsigned steps;

	irdm_contact_tri_pos(cm, d, anchor_tri, v);
	irdm_v3_bary(a, anchor_bary, v[0], v[1], v[2]);
	irdm_v3_sub(tv, px->point_m, a);
	tl = sqrt(irdm_v3_dot(tv, tv));
	if (px->force_known) {
		/* the force itself: dn such that tl / dn = F_t / F_n, so the
		 * test below is F_t <= mu_s F_n and a slip scales the offset
		 * by mu_d F_n / F_t (none without a normal force) */
		double fn = -irdm_v3_dot(px->force_n, px->normal), ft[3], ftl;

		irdm_v3_scale(ft, fn, px->normal);
		irdm_v3_add(ft, ft, px->force_n);
		ftl = sqrt(irdm_v3_dot(ft, ft));
		dn = !(fn > 0) ? 0 : ftl > 0 ? fn * tl / ftl :
					       INFINITY;
	}
	if (tl <= cfg->mu_s * dn) { /* stick */
		px->tri = anchor_tri;
		memcpy(px->bary, anchor_bary, sizeof(px->bary));
		memcpy(px->point_m, a, sizeof(a));
		tri_normal(v, px->normal);
		return 0;
	}
	/* slide to the rim: c = q - mu_d dn (q - a) / |q - a| */
	irdm_v3_scale(c, cfg->mu_d * dn / tl, tv);
	irdm_v3_sub(c, px->point_m, c);
	t = px->tri;
	switch (walk(cm, d, max_walk, c, &t, v, lam, q, &steps)) {
	case -1:
		return -1;
	case 0:
		irdm_contact_closest_on_tri(v[0], v[1], v[2], c, lam, q);
		break;
	}
	px->tri = t;
	memcpy(px->bary, lam, sizeof(lam));
	memcpy(px->point_m, q, sizeof(q));
	tri_normal(v, px->normal);
	return 0;
}

static bool friction_on(const struct irdm_proxy_config *cfg)
{
	return cfg->mu_s > 0;
}

int irdm_proxy_update(struct irdm_proxy *px, const struct irdm_contact_mesh *cm,
		      const struct irdm_contact_disp *d, const struct irdm_proxy_config *cfg,
		      const double p[3])
{
	double v[3][3], lam[3], n[3], q[3], anchor_bary[3];
	uint32_t t, anchor_tri;
	unsigned steps, max_walk;
	bool outside;
	int in;

	if (!px || !cm || !cm->hdr || !cfg || !p)
		return IRDM_EINVAL;
	if (!irdm_v3_finite(p))
		return proxy_release(px, IRDM_EINVAL);
	if (!px->active)
		return proxy_touch(px, cm, d, cfg, p);
	t = anchor_tri = px->tri;
	memcpy(anchor_bary, px->bary, sizeof(anchor_bary));
	if (t >= cm->n_tris || !irdm_contact_tri_contactable(cm, t))
		return proxy_release(px, IRDM_EINVAL);
	max_walk = cfg->max_walk < IRDM_CONTACT_MAX_WALK ? cfg->max_walk : IRDM_CONTACT_MAX_WALK;
	in = walk(cm, d, max_walk, p, &t, v, lam, q, &steps);
	if (in < 0) /* crushed flat: detect afresh */
		return proxy_release(px, IRDM_PROXY_RELEASE);
	tri_normal(v, n);
	outside = outside_beyond(cm, d, t, v, n, lam, p);
	if (!in)
		irdm_contact_closest_on_tri(v[0], v[1], v[2], p, lam, q);
	proxy_set(px, t, v, lam, p, steps);
	if (outside || px->depth_m > 0)
		return proxy_release(px, IRDM_PROXY_RELEASE);
	if (friction_on(cfg) &&
	    friction(px, cm, d, cfg, max_walk, anchor_tri, anchor_bary, px->depth_m))
		return proxy_release(px, IRDM_PROXY_RELEASE);
	return IRDM_PROXY_SLIDE;
}

int irdm_proxy_site(const struct irdm_proxy *px, const struct irdm_contact_mesh *cm,
		    struct irdm_contact_site *site)
{
	if (!px || !cm || !cm->hdr || !site || !px->active || px->tri >= cm->n_tris)
		return IRDM_EINVAL;
	site->n_nodes = 3;
	for (unsigned k = 0; k < 3; k++) {
		uint32_t r = cm->tris[3 * (size_t)px->tri + k];

		site->row[k] = r;
		site->col[k] = cm->col_of_row[r];
		site->weight[k] = px->bary[k];
	}
	for (unsigned a = 0; a < 3; a++) {
		site->rest_m[a] = 0;
		for (unsigned k = 0; k < 3; k++)
			site->rest_m[a] += px->bary[k] * (double)cm->rest[site->row[k]].pos_m[a];
		site->normal[a] = px->normal[a];
	}
	return IRDM_OK;
}
