/* SPDX-License-Identifier: MIT */
/*
 * Contact detection: the CONTACT_BVH the precompute writes (structure,
 * adjacency), the closest point query against a brute-force loop over every
 * contactable triangle (rest and deformed surface), the point-triangle
 * distance against an independent one, the god-object on a box (stroking,
 * release, edges, corners, boundaries, deep pushes, a moved surface), the
 * engine contact site, and the loader's rejection of damaged BVH payloads.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/bvh_build.h"
#include "image/image_writer.h"
#include "irdm/contact.h"
#include "irdm/image.h"
#include "irdm/posix/image_map.h"
#include "irdm/vec3.h"
#include "precompute/precompute.h"
#include "support/image_fixture.h"

enum { IMG_ALL,
       IMG_TOP,
       IMG_HALF,
       IMG_COUNT };

/* The test box: 10 x 10 x 20 cm, 2 x 2 x 4 hexes, bottom fixed. */
struct box_image {
	char path[600];
	struct irdm_image img;
	struct irdm_contact_mesh cm;
	uint32_t *beyond;      /* cm's face-beyond table */
	uint32_t rim_searched; /* its build's searches */
	double lo[3], hi[3];   /* bounds of the rest nodes */
};

static char tmpdir[512];
static struct box_image boxes[IMG_COUNT];

/* -------------------------------------------------------------- helpers */

static uint64_t rng_state = 0x9e3779b97f4a7c15u;

static double urand(void) /* [0, 1), xorshift64* */
{
	rng_state ^= rng_state >> 12;
	rng_state ^= rng_state << 25;
	rng_state ^= rng_state >> 27;
	return (double)((rng_state * 2685821657736338717u) >> 11) / 9007199254740992.0;
}

static double urange(double a, double b)
{
	return a + (b - a) * urand();
}

static double dist3(const double *a, const double *b)
{
	double d[3] = { a[0] - b[0], a[1] - b[1], a[2] - b[2] };

	return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

/* n . (p - q) */
static double dot3(const double *n, const double *p, const double *q)
{
	return n[0] * (p[0] - q[0]) + n[1] * (p[1] - q[1]) + n[2] * (p[2] - q[2]);
}

static int make_box(struct box_image *b, const char *name, const char *touch)
{
	struct irdm_precompute_opts o = { 0 };
	struct irdm_precompute_report rep;
	struct irdm_scene sc;
	char err[512];

	snprintf(b->path, sizeof(b->path), "%s/%s.img", tmpdir, name);
	irdm_scene_defaults(&sc);
	sc.max_error = 0; /* not what is tested here */
	if (irdm_scene_set(&sc, "mesh", "box:0.1,0.1,0.2", "test", err, sizeof(err)) ||
	    irdm_scene_set(&sc, "resolution", "2,2,4", "test", err, sizeof(err)) ||
	    irdm_scene_set(&sc, "representation", "modal:10", "test", err, sizeof(err)) ||
	    irdm_scene_set(&sc, "touch", touch, "test", err, sizeof(err)) ||
	    irdm_scene_check(&sc, err, sizeof(err))) {
		fprintf(stderr, "scene: %s\n", err);
		return -1;
	}
	o.out_path = b->path;
	if (irdm_precompute(&sc, &o, &rep, err, sizeof(err))) {
		fprintf(stderr, "precompute: %s\n", err);
		return -1;
	}
	if (irdm_image_map(b->path, 0, &b->img, err, sizeof(err))) {
		fprintf(stderr, "map: %s\n", err);
		return -1;
	}
	if (irdm_contact_mesh_init(&b->cm, &b->img))
		return -1;
	b->beyond = malloc(irdm_contact_beyond_size(&b->cm));
	if (!b->beyond)
		return -1;
	b->rim_searched = irdm_contact_beyond_build(&b->cm, b->beyond);
	for (unsigned a = 0; a < 3; a++) {
		b->lo[a] = INFINITY;
		b->hi[a] = -INFINITY;
	}
	for (uint32_t r = 0; r < b->img.meta->n_nodes; r++)
		for (unsigned a = 0; a < 3; a++) {
			b->lo[a] = fmin(b->lo[a], b->img.nodes[r].pos_m[a]);
			b->hi[a] = fmax(b->hi[a], b->img.nodes[r].pos_m[a]);
		}
	return 0;
}

static int group_setup(void **state)
{
	(void)state;
	snprintf(tmpdir, sizeof(tmpdir), "%s/irdm-contact-XXXXXX",
		 getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
	if (!mkdtemp(tmpdir))
		return -1;
	if (make_box(&boxes[IMG_ALL], "all", "surface") ||
	    make_box(&boxes[IMG_TOP], "top", "z>=0.2") ||
	    make_box(&boxes[IMG_HALF], "half", "x<=0.05"))
		return -1;
	return 0;
}

static int group_teardown(void **state)
{
	(void)state;
	for (unsigned i = 0; i < IMG_COUNT; i++) {
		irdm_image_unmap(&boxes[i].img);
		free(boxes[i].beyond);
		unlink(boxes[i].path);
	}
	rmdir(tmpdir);
	return 0;
}

/* Brute force: every contactable, non-degenerate triangle, the same
 * triangle distance, strictly the first minimum. */
static int brute_closest(const struct irdm_contact_mesh *cm, const struct irdm_contact_disp *d,
			 const double *p, double radius, struct irdm_contact_hit *hit)
{
	double best = radius * radius;
	int found = 0;

	for (uint32_t t = 0; t < cm->n_tris; t++) {
		double v[3][3], bary[3], q[3], d2, ab[3], ac[3], n[3], nn, s;

		if (!irdm_contact_tri_contactable(cm, t))
			continue;
		irdm_contact_tri_pos(cm, d, t, v);
		irdm_v3_sub(ab, v[1], v[0]);
		irdm_v3_sub(ac, v[2], v[0]);
		irdm_v3_cross(n, ab, ac);
		nn = irdm_v3_norm(n);
		assert_true(nn > 0); /* the box has no degenerate triangle */
		d2 = irdm_contact_closest_on_tri(v[0], v[1], v[2], p, bary, q);
		if (d2 < best || (!found && d2 <= best)) {
			best = d2;
			found = 1;
			hit->tri = t;
			memcpy(hit->bary, bary, sizeof(bary));
			memcpy(hit->point_m, q, sizeof(q));
			s = 0;
			for (unsigned a = 0; a < 3; a++) {
				hit->normal[a] = n[a] / nn;
				s += (p[a] - q[a]) * hit->normal[a];
			}
			hit->dist_m = s < 0 ? -sqrt(d2) : sqrt(d2);
		}
	}
	return found;
}

static bool inside_box(const struct box_image *b, const double *p)
{
	for (unsigned a = 0; a < 3; a++)
		if (!(p[a] > b->lo[a] && p[a] < b->hi[a]))
			return false;
	return true;
}

/* A smooth displacement field, |u| <= amp * sqrt(3). */
static void smooth_disp(const double *x, double amp, double *u)
{
	const double k = 2 * M_PI / 0.2;

	u[0] = amp * sin(k * x[2] + 0.3) * cos(k * x[1]);
	u[1] = amp * sin(k * x[0] + 1.1) * cos(0.5 * k * x[2]);
	u[2] = amp * cos(k * (x[0] + x[1]) + 0.7);
}

static void disp_array(const struct box_image *b, double amp, double *u)
{
	for (uint32_t r = 0; r < b->img.meta->n_nodes; r++) {
		double x[3] = { b->img.nodes[r].pos_m[0], b->img.nodes[r].pos_m[1],
				b->img.nodes[r].pos_m[2] };

		smooth_disp(x, amp, &u[3 * r]);
	}
}

static void disp_callback(const void *ctx, uint32_t row, double u[3])
{
	const struct box_image *b = ctx;
	double x[3] = { b->img.nodes[row].pos_m[0], b->img.nodes[row].pos_m[1],
			b->img.nodes[row].pos_m[2] };

	smooth_disp(x, 0.004, u);
}

/* ----------------------------------------------------- structure checks */

static void test_bvh_present(void **state)
{
	const struct box_image *b = &boxes[IMG_ALL];
	const struct irdm_bvh_header *h = b->cm.hdr;
	uint32_t n = 0;

	(void)state;
	assert_non_null(b->img.contact_bvh);
	assert_int_equal(h->n_surface_tris, b->img.meta->n_tris);
	for (uint32_t t = 0; t < b->cm.n_tris; t++) {
		const uint32_t *v = &b->img.tris[3 * t];
		bool all = true;

		for (unsigned k = 0; k < 3; k++) {
			bool col = false;

			for (uint32_t c = 0; c < b->img.meta->n_cols; c++)
				col = col || b->img.columns[c] == v[k];
			all = all && col;
		}
		assert_int_equal(all, irdm_contact_tri_contactable(&b->cm, t));
		n += all;
	}
	assert_int_equal(h->n_contact_tris, n);
	/* bottom fixed: some triangles are not contactable, most are */
	assert_true(n > b->cm.n_tris / 2 && n < b->cm.n_tris);
	assert_true(h->depth >= 2 && h->depth <= IRDM_BVH_MAX_DEPTH);
	assert_true(h->leaf_max >= 1 && h->leaf_max <= IRDM_BVH_LEAF_MAX);
	/* top only: the 8 top triangles */
	assert_int_equal(boxes[IMG_TOP].cm.hdr->n_contact_tris, 8);
}

/* Adjacency: symmetric across the same edge, and present exactly where two
 * contactable triangles share an edge (counted independently, O(n^2)). */
static void test_adjacency(void **state)
{
	(void)state;
	for (unsigned i = 0; i < IMG_COUNT; i++) {
		const struct irdm_contact_mesh *cm = &boxes[i].cm;
		unsigned linked = 0, boundary = 0;

		for (uint32_t t = 0; t < cm->n_tris; t++) {
			const uint32_t *v = &cm->tris[3 * t];

			for (unsigned e = 0; e < 3; e++) {
				uint32_t a = v[e], b = v[(e + 1) % 3], u = cm->adj[3 * t + e];
				uint32_t sharing = 0, other = IRDM_BVH_NONE;

				if (!irdm_contact_tri_contactable(cm, t)) {
					assert_int_equal(u, IRDM_BVH_NONE);
					continue;
				}
				for (uint32_t s = 0; s < cm->n_tris; s++) {
					const uint32_t *w = &cm->tris[3 * s];
					bool has_a = w[0] == a || w[1] == a || w[2] == a;
					bool has_b = w[0] == b || w[1] == b || w[2] == b;

					if (s != t && has_a && has_b &&
					    irdm_contact_tri_contactable(cm, s)) {
						sharing++;
						other = s;
					}
				}
				if (sharing != 1) {
					assert_int_equal(u, IRDM_BVH_NONE);
					boundary++;
					continue;
				}
				assert_int_equal(u, other);
				linked++;
				/* B names A back across the same edge, reversed (CCW) */
				for (unsigned f = 0; f < 3; f++) {
					const uint32_t *w = &cm->tris[3 * u];

					if (w[f] == b && w[(f + 1) % 3] == a)
						assert_int_equal(cm->adj[3 * u + f], t);
				}
			}
		}
		assert_true(linked > 0);
		assert_true(boundary > 0); /* the region is open at the bottom / top rim */
	}
}

/*
 * The face-beyond table: the adjacency where it knows the neighbour; on
 * the touchable area's rim the lowest-index other surface triangle on the
 * edge (counted independently); one search per rim edge at the build.
 */
static void test_beyond_table(void **state)
{
	(void)state;
	for (unsigned i = 0; i < IMG_COUNT; i++) {
		const struct irdm_contact_mesh *cm = &boxes[i].cm;
		uint32_t rim = 0, display_only = 0;

		assert_ptr_equal(cm->beyond, boxes[i].beyond);
		for (uint32_t t = 0; t < cm->n_tris; t++) {
			const uint32_t *v = &cm->tris[3 * t];
			bool touchable = irdm_contact_tri_contactable(cm, t);

			for (unsigned e = 0; e < 3; e++) {
				uint32_t a = v[e], b = v[(e + 1) % 3], u = cm->adj[3 * t + e];
				uint32_t first = IRDM_BVH_NONE;

				if (u != IRDM_BVH_NONE || !touchable) {
					assert_int_equal(cm->beyond[3 * t + e], u);
					continue;
				}
				rim++;
				for (uint32_t s = cm->n_tris; s-- > 0;) {
					const uint32_t *w = &cm->tris[3 * s];
					bool has_a = w[0] == a || w[1] == a || w[2] == a;
					bool has_b = w[0] == b || w[1] == b || w[2] == b;

					if (s != t && has_a && has_b)
						first = s;
				}
				assert_int_equal(cm->beyond[3 * t + e], first);
				display_only += first != IRDM_BVH_NONE &&
						!irdm_contact_tri_contactable(cm, first);
			}
		}
		assert_int_equal(boxes[i].rim_searched, rim);
		if (i != IMG_ALL)
			assert_true(display_only > 0);
	}
}

/* ----------------------------------------------- point-triangle distance */

/* Independent reference: project on the plane, inside -> that; otherwise
 * the best of the three segments. */
static double ref_tri_dist(const double *a, const double *b, const double *c, const double *p)
{
	const double *v[3] = { a, b, c };
	double ab[3], ac[3], ap[3], n[3], nn, best = INFINITY;

	for (unsigned i = 0; i < 3; i++) {
		ab[i] = b[i] - a[i];
		ac[i] = c[i] - a[i];
		ap[i] = p[i] - a[i];
	}
	n[0] = ab[1] * ac[2] - ab[2] * ac[1];
	n[1] = ab[2] * ac[0] - ab[0] * ac[2];
	n[2] = ab[0] * ac[1] - ab[1] * ac[0];
	nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
	/* collinear vertices give a rounding-noise normal: no interior then */
	if (nn > 1e-20 * (ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]) *
			 (ac[0] * ac[0] + ac[1] * ac[1] + ac[2] * ac[2])) {
		/* solve ap = s ab + t ac + h n by Cramer in the 2x2 normal equations */
		double aa = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
		double bb = ac[0] * ac[0] + ac[1] * ac[1] + ac[2] * ac[2];
		double ab_ac = ab[0] * ac[0] + ab[1] * ac[1] + ab[2] * ac[2];
		double pa = ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2];
		double pb = ap[0] * ac[0] + ap[1] * ac[1] + ap[2] * ac[2];
		double det = aa * bb - ab_ac * ab_ac;
		double s = (pa * bb - pb * ab_ac) / det, t = (pb * aa - pa * ab_ac) / det;

		if (s >= 0 && t >= 0 && s + t <= 1)
			return fabs(ap[0] * n[0] + ap[1] * n[1] + ap[2] * n[2]) / sqrt(nn);
	}
	for (unsigned e = 0; e < 3; e++) {
		const double *x = v[e], *y = v[(e + 1) % 3];
		double d[3], l2 = 0, t = 0, q[3];

		for (unsigned i = 0; i < 3; i++) {
			d[i] = y[i] - x[i];
			l2 += d[i] * d[i];
			t += (p[i] - x[i]) * d[i];
		}
		t = l2 > 0 ? fmin(fmax(t / l2, 0), 1) : 0;
		for (unsigned i = 0; i < 3; i++)
			q[i] = x[i] + t * d[i];
		best = fmin(best, dist3(p, q));
	}
	return best;
}

static void test_point_triangle(void **state)
{
	(void)state;
	for (int i = 0; i < 20000; i++) {
		double v[3][3], p[3], bary[3], q[3], d2, ref, sum, r[3];
		int kind = i % 5;

		for (unsigned k = 0; k < 3; k++)
			for (unsigned a = 0; a < 3; a++)
				v[k][a] = urange(-1, 1);
		if (kind == 3) /* collinear */
			for (unsigned a = 0; a < 3; a++)
				v[2][a] = v[0][a] + 0.37 * (v[1][a] - v[0][a]);
		if (kind == 4) /* two coincident vertices */
			memcpy(v[2], v[1], sizeof(v[1]));
		for (unsigned a = 0; a < 3; a++)
			p[a] = urange(-2, 2);
		d2 = irdm_contact_closest_on_tri(v[0], v[1], v[2], p, bary, q);
		ref = ref_tri_dist(v[0], v[1], v[2], p);
		if (!(fabs(sqrt(d2) - ref) <= 1e-12 * (1 + ref)))
			fail_msg("case %d kind %d: %.17g vs %.17g, bary %g %g %g", i, kind,
				 sqrt(d2), ref, bary[0], bary[1], bary[2]);
		sum = bary[0] + bary[1] + bary[2];
		assert_true(fabs(sum - 1) < 1e-12);
		for (unsigned k = 0; k < 3; k++)
			assert_true(bary[k] >= -1e-12 && bary[k] <= 1 + 1e-12);
		for (unsigned a = 0; a < 3; a++)
			r[a] = bary[0] * v[0][a] + bary[1] * v[1][a] + bary[2] * v[2][a];
		assert_true(dist3(r, q) < 1e-12);
		assert_true(fabs(dist3(p, q) - sqrt(d2)) < 1e-12);
	}
}

/* ------------------------------------------------------ closest queries */

static void compare_queries(const struct box_image *b, const struct irdm_contact_disp *d,
			    double max_disp, int n, double radius, bool check_sign)
{
	unsigned hits = 0, misses = 0;

	for (int i = 0; i < n; i++) {
		struct irdm_contact_hit h = { 0 }, r = { 0 };
		double p[3];
		int fb, fr;

		for (unsigned a = 0; a < 3; a++)
			p[a] = urange(b->lo[a] - 0.04, b->hi[a] + 0.04);
		fb = irdm_contact_closest(&b->cm, d, max_disp, p, radius, &h);
		fr = brute_closest(&b->cm, d, p, radius, &r);
		assert_int_equal(fb, fr);
		if (!fb) {
			misses++;
			continue;
		}
		hits++;
		assert_true(fabs(fabs(h.dist_m) - fabs(r.dist_m)) <= 1e-12);
		assert_true(dist3(h.point_m, r.point_m) <= 1e-9);
		assert_true(fabs(dist3(p, h.point_m) - fabs(h.dist_m)) <= 1e-12);
		assert_true(fabs(h.bary[0] + h.bary[1] + h.bary[2] - 1) < 1e-12);
		assert_true(fabs(h.normal[0] * h.normal[0] + h.normal[1] * h.normal[1] +
				 h.normal[2] * h.normal[2] - 1) < 1e-12);
		assert_true(irdm_contact_tri_contactable(&b->cm, h.tri));
		/* signs differ only at a tie (an edge or a vertex), where the
		 * query takes the face that sees p best */
		if (fabs(h.dist_m) > 1e-9 && (h.dist_m < 0) != (r.dist_m < 0) &&
		    !(h.tri != r.tri && dist3(h.point_m, r.point_m) < 1e-12 &&
		      fabs(dot3(h.normal, p, h.point_m)) >= fabs(dot3(r.normal, p, r.point_m))))
			fail_msg("sign: p %.17g %.17g %.17g: bvh tri %u d %.17g bary %g %g %g n %g %g %g; brute tri %u d %.17g bary %g %g %g n %g %g %g",
				 p[0], p[1], p[2], h.tri, h.dist_m, h.bary[0], h.bary[1], h.bary[2],
				 h.normal[0], h.normal[1], h.normal[2], r.tri, r.dist_m,
				 r.bary[0], r.bary[1], r.bary[2], r.normal[0], r.normal[1], r.normal[2]);
		/* in the upper part every closest point is on a contactable face */
		if (check_sign && p[2] > 0.5 * (b->lo[2] + b->hi[2]) && fabs(h.dist_m) > 1e-9)
			assert_int_equal(h.dist_m < 0, inside_box(b, p));
	}
	if (radius < 1) {
		assert_true(hits > 0);
		assert_true(misses > 0);
	}
}

static void test_closest_rest(void **state)
{
	(void)state;
	compare_queries(&boxes[IMG_ALL], NULL, 0, 4000, 1.0, true);
	compare_queries(&boxes[IMG_ALL], NULL, 0, 2000, 0.02, true);
	compare_queries(&boxes[IMG_TOP], NULL, 0, 2000, 1.0, false);
	compare_queries(&boxes[IMG_TOP], NULL, 0, 2000, 0.03, false);
}

static void test_closest_displaced(void **state)
{
	struct box_image *b = &boxes[IMG_ALL];
	double *u = malloc(3 * (size_t)b->img.meta->n_nodes * sizeof(double));
	struct irdm_contact_disp arr = { .u_m = u };
	struct irdm_contact_disp cb = { .fn = disp_callback, .ctx = b };
	const double amp = 0.004, bound = amp * sqrt(3.0);

	(void)state;
	assert_non_null(u);
	disp_array(b, amp, u);
	compare_queries(b, &arr, bound, 4000, 1.0, false);
	compare_queries(b, &arr, bound, 2000, 0.02, false);
	compare_queries(b, &cb, bound, 1000, 0.02, false);
	/* array and callback give the same answers */
	for (int i = 0; i < 500; i++) {
		struct irdm_contact_hit h1, h2;
		double p[3];

		for (unsigned a = 0; a < 3; a++)
			p[a] = urange(b->lo[a] - 0.02, b->hi[a] + 0.02);
		assert_int_equal(irdm_contact_closest(&b->cm, &arr, bound, p, 0.05, &h1),
				 irdm_contact_closest(&b->cm, &cb, bound, p, 0.05, &h2));
	}
	free(u);
}

static void test_closest_args(void **state)
{
	const struct box_image *b = &boxes[IMG_ALL];
	struct irdm_contact_hit h;
	double p[3], bad[3] = { NAN, 0, 0 };
	struct irdm_contact_mesh none;

	(void)state;
	p[0] = 0.5 * (b->lo[0] + b->hi[0]);
	p[1] = 0.5 * (b->lo[1] + b->hi[1]);
	p[2] = b->hi[2] + 0.05;
	assert_int_equal(irdm_contact_closest(&b->cm, NULL, 0, bad, 1, &h), IRDM_EINVAL);
	assert_int_equal(irdm_contact_closest(&b->cm, NULL, -1, p, 1, &h), IRDM_EINVAL);
	assert_int_equal(irdm_contact_closest(&b->cm, NULL, 0, p, NAN, &h), IRDM_EINVAL);
	assert_int_equal(irdm_contact_closest(&b->cm, NULL, 0, p, 0.01, &h), 0);
	assert_int_equal(irdm_contact_closest(&b->cm, NULL, 0, p, 0.06, &h), 1);
	assert_true(fabs(h.dist_m - 0.05) < 1e-12);
	assert_int_equal(irdm_contact_mesh_init(&none, NULL), IRDM_EINVAL);
}

/* Normals point out: for the box, equal to the face normal. */
static void test_box_normals(void **state)
{
	const struct box_image *b = &boxes[IMG_ALL];
	double mid[3];

	(void)state;
	for (unsigned a = 0; a < 3; a++)
		mid[a] = 0.5 * (b->lo[a] + b->hi[a]);
	for (uint32_t t = 0; t < b->cm.n_tris; t++) {
		struct irdm_contact_hit h;
		double v[3][3], c[3], p[3], face[3] = { 0, 0, 0 };
		int axis = -1;

		if (!irdm_contact_tri_contactable(&b->cm, t))
			continue;
		irdm_contact_tri_pos(&b->cm, NULL, t, v);
		for (unsigned a = 0; a < 3; a++)
			c[a] = (v[0][a] + v[1][a] + v[2][a]) / 3;
		for (unsigned a = 0; a < 3; a++)
			if (c[a] == b->lo[a] || c[a] == b->hi[a]) {
				axis = (int)a;
				face[a] = c[a] == b->hi[a] ? 1 : -1;
			}
		assert_true(axis >= 0);
		/* 2 mm outside and inside the centroid */
		for (int side = -1; side <= 1; side += 2) {
			for (unsigned a = 0; a < 3; a++)
				p[a] = c[a] + side * 0.002 * face[a];
			assert_int_equal(irdm_contact_closest(&b->cm, NULL, 0, p, 0.01, &h), 1);
			assert_int_equal(h.tri, t);
			for (unsigned a = 0; a < 3; a++)
				assert_true(fabs(h.normal[a] - face[a]) < 1e-12);
			assert_true(fabs(h.dist_m - side * 0.002) < 1e-12);
			assert_true(dist3(h.point_m, c) < 1e-12);
		}
		/* the normal points away from the box centre */
		assert_true((c[0] - mid[0]) * face[0] + (c[1] - mid[1]) * face[1] +
				    (c[2] - mid[2]) * face[2] >
			    0);
	}
}

/* ------------------------------------------------------------ god-object */

static int upd(struct irdm_proxy *px, const struct box_image *b, const struct irdm_contact_disp *d,
	       double x, double y, double z)
{
	struct irdm_proxy_config cfg;
	double p[3] = { x, y, z };

	irdm_proxy_config_default(&cfg);
	cfg.max_disp_m = 0.01;
	return irdm_proxy_update(px, &b->cm, d, &cfg, p);
}

/* Stroking the top: the contact point is the device's projection, across
 * several triangles, continuous; lifting the device releases it. */
static void test_proxy_stroke(void **state)
{
	const struct box_image *b = &boxes[IMG_ALL];
	const double top = b->hi[2], x0 = b->lo[0] + 0.013, y0 = b->lo[1] + 0.017;
	const double x1 = b->hi[0] - 0.011, y1 = b->hi[1] - 0.019;
	struct irdm_proxy px;
	uint32_t seen[64];
	unsigned n_seen = 0, walked = 0;
	double prev[3];

	(void)state;
	irdm_proxy_reset(&px);
	assert_int_equal(upd(&px, b, NULL, x0, y0, top + 0.004), IRDM_PROXY_FREE);
	assert_false(px.active);
	assert_int_equal(upd(&px, b, NULL, x0, y0, top - 0.003), IRDM_PROXY_TOUCH);
	assert_true(px.active);
	assert_true(fabs(px.point_m[0] - x0) < 1e-12 && fabs(px.point_m[1] - y0) < 1e-12);
	assert_true(fabs(px.point_m[2] - top) < 1e-12);
	assert_true(fabs(px.depth_m + 0.003) < 1e-12);
	memcpy(prev, px.point_m, sizeof(prev));
	for (int k = 1; k <= 400; k++) {
		double s = k / 400.0, x = x0 + s * (x1 - x0), y = y0 + s * (y1 - y0);
		double z = top - 0.003 - 0.002 * sin(0.1 * k); /* pressing harder and softer */
		double step = hypot(x1 - x0, y1 - y0) / 400;
		bool new_tri = true;

		assert_int_equal(upd(&px, b, NULL, x, y, z), IRDM_PROXY_SLIDE);
		assert_true(fabs(px.point_m[0] - x) < 1e-12);
		assert_true(fabs(px.point_m[1] - y) < 1e-12);
		assert_true(fabs(px.point_m[2] - top) < 1e-12);
		assert_true(fabs(px.normal[2] - 1) < 1e-12);
		assert_true(fabs(px.depth_m - (z - top)) < 1e-12);
		assert_true(dist3(px.point_m, prev) <= step + 1e-12);
		for (unsigned a = 0; a < 3; a++)
			assert_true(px.bary[a] >= -1e-12);
		memcpy(prev, px.point_m, sizeof(prev));
		walked += px.steps;
		for (unsigned i = 0; i < n_seen; i++)
			new_tri = new_tri && seen[i] != px.tri;
		if (new_tri && n_seen < 64)
			seen[n_seen++] = px.tri;
	}
	assert_true(n_seen >= 3);
	assert_true(walked >= n_seen - 1);
	assert_int_equal(upd(&px, b, NULL, x1, y1, top + 0.001), IRDM_PROXY_RELEASE);
	assert_false(px.active);
	assert_int_equal(upd(&px, b, NULL, x1, y1, top + 0.001), IRDM_PROXY_FREE);
}

/* Pushing in deep (further than to the sides): the proxy stays on top. */
static void test_proxy_deep(void **state)
{
	const struct box_image *b = &boxes[IMG_ALL];
	const double top = b->hi[2], xc = 0.5 * (b->lo[0] + b->hi[0]);
	const double yc = 0.5 * (b->lo[1] + b->hi[1]) + 0.007;
	struct irdm_proxy px;

	(void)state;
	irdm_proxy_reset(&px);
	assert_int_equal(upd(&px, b, NULL, xc, yc, top - 0.001), IRDM_PROXY_TOUCH);
	for (int k = 1; k <= 100; k++) {
		double z = top - 0.001 - 0.0015 * k; /* down to 15 cm deep */

		assert_int_equal(upd(&px, b, NULL, xc + 0.0001 * k, yc, z), IRDM_PROXY_SLIDE);
		assert_true(fabs(px.point_m[2] - top) < 1e-12);
		assert_true(fabs(px.point_m[0] - (xc + 0.0001 * k)) < 1e-12);
	}
	/* a fresh detection at that depth would pick a side face instead */
	{
		struct irdm_contact_hit h;
		double p[3] = { xc + 0.01, yc, top - 0.151 };

		assert_int_equal(irdm_contact_closest(&b->cm, NULL, 0, p, 1, &h), 1);
		assert_true(fabs(h.normal[2]) < 1e-12);
	}
}

/* Sliding over the top edge onto a touchable side: released as soon as the
 * device is outside the side; coming from the side over the edge: released
 * when it is above the top; over a corner: released. */
static void test_proxy_edges(void **state)
{
	const struct box_image *b = &boxes[IMG_ALL];
	const double top = b->hi[2], xc = 0.5 * (b->lo[0] + b->hi[0]) + 0.003;
	const double yc = 0.5 * (b->lo[1] + b->hi[1]) - 0.004;
	struct irdm_proxy px;
	int ev, k;

	(void)state;
	irdm_proxy_reset(&px);
	assert_int_equal(upd(&px, b, NULL, xc, yc, top - 0.003), IRDM_PROXY_TOUCH);
	for (k = 1; k < 200; k++) {
		double x = xc + 0.0005 * k;

		ev = upd(&px, b, NULL, x, yc, top - 0.003);
		if (x <= b->hi[0]) {
			assert_int_equal(ev, IRDM_PROXY_SLIDE);
			assert_true(fabs(px.point_m[0] - x) < 1e-12);
			assert_true(fabs(px.point_m[2] - top) < 1e-12);
			continue;
		}
		/* past the side plane: walked onto the side and released */
		assert_int_equal(ev, IRDM_PROXY_RELEASE);
		assert_true(fabs(px.normal[0] - 1) < 1e-12);
		assert_true(fabs(px.point_m[0] - b->hi[0]) < 1e-12);
		assert_true(px.steps >= 1);
		break;
	}
	assert_true(k < 200);

	/* from the side, up over the edge */
	irdm_proxy_reset(&px);
	assert_int_equal(upd(&px, b, NULL, b->hi[0] + 0.004, yc, top - 0.01), IRDM_PROXY_FREE);
	assert_int_equal(upd(&px, b, NULL, b->hi[0] - 0.002, yc, top - 0.01), IRDM_PROXY_TOUCH);
	assert_true(fabs(px.normal[0] - 1) < 1e-12);
	for (k = 1; k < 200; k++) {
		double z = top - 0.01 + 0.0005 * k;

		ev = upd(&px, b, NULL, b->hi[0] - 0.002, yc, z);
		if (z <= top) {
			assert_int_equal(ev, IRDM_PROXY_SLIDE);
			assert_true(fabs(px.point_m[0] - b->hi[0]) < 1e-12);
			assert_true(fabs(px.point_m[2] - z) < 1e-12);
			continue;
		}
		assert_int_equal(ev, IRDM_PROXY_RELEASE);
		assert_true(fabs(px.normal[2] - 1) < 1e-12);
		break;
	}
	assert_true(k < 200);

	/* diagonally over the corner */
	irdm_proxy_reset(&px);
	assert_int_equal(upd(&px, b, NULL, xc, yc, top - 0.002), IRDM_PROXY_TOUCH);
	for (k = 1; k < 400; k++) {
		double x = xc + 0.0003 * k, y = yc + 0.0003 * k;

		ev = upd(&px, b, NULL, x, y, top - 0.002);
		assert_true(ev == IRDM_PROXY_SLIDE || ev == IRDM_PROXY_RELEASE);
		if (ev == IRDM_PROXY_RELEASE)
			break;
		assert_true(x < b->hi[0] + 1e-12 && y < b->hi[1] + 1e-12);
	}
	assert_true(k < 400);
	assert_true(xc + 0.0003 * k >= b->hi[0] || yc + 0.0003 * k >= b->hi[1]);
}

/*
 * Only the top is touchable, the sides are display-only: sliding off the
 * top's rim below its plane, the tip is outside the object by the side's
 * face: the contact ends at the first update past the side (no hold at
 * the rim, which pulled the tool back) and no new contact begins there;
 * over a corner the same; inside the rim the proxy follows the tip.
 */
static void test_proxy_boundary(void **state)
{
	const struct box_image *b = &boxes[IMG_TOP];
	const double top = b->hi[2], xc = 0.5 * (b->lo[0] + b->hi[0]) + 0.002;
	const double yc = 0.5 * (b->lo[1] + b->hi[1]) + 0.001;
	struct irdm_proxy px;
	int k;

	(void)state;
	irdm_proxy_reset(&px);
	assert_int_equal(upd(&px, b, NULL, xc, yc, top - 0.002), IRDM_PROXY_TOUCH);
	for (k = 1; k <= 150; k++) {
		double x = xc + 0.0005 * k;
		int ev = upd(&px, b, NULL, x, yc, top - 0.002);

		if (x <= b->hi[0]) {
			assert_int_equal(ev, IRDM_PROXY_SLIDE);
			assert_true(fabs(px.point_m[0] - x) < 1e-12);
			assert_true(fabs(px.point_m[1] - yc) < 1e-12);
			assert_true(fabs(px.point_m[2] - top) < 1e-12);
			continue;
		}
		assert_int_equal(ev, IRDM_PROXY_RELEASE);
		assert_false(px.active);
		break;
	}
	assert_true(k <= 150);
	/* outside, beside the rim and below the top: never touches */
	for (k = 1; k <= 40; k++)
		assert_int_equal(upd(&px, b, NULL, b->hi[0] + 0.0002 * k, yc, top - 0.0001 * k),
				 IRDM_PROXY_FREE);
	assert_int_equal(upd(&px, b, NULL, b->hi[0] + 0.05, b->hi[1] + 0.05, top - 0.002),
			 IRDM_PROXY_FREE);
	/* back over the top from above, then diagonally off a corner */
	assert_int_equal(upd(&px, b, NULL, xc, yc, top - 0.002), IRDM_PROXY_TOUCH);
	for (k = 1; k < 400; k++) {
		double x = xc + 0.0003 * k, y = yc + 0.0003 * k;
		int ev = upd(&px, b, NULL, x, y, top - 0.002);

		if (x <= b->hi[0] && y <= b->hi[1]) {
			assert_int_equal(ev, IRDM_PROXY_SLIDE);
			continue;
		}
		assert_int_equal(ev, IRDM_PROXY_RELEASE);
		break;
	}
	assert_true(k < 400);
	assert_int_equal(upd(&px, b, NULL, b->hi[0] + 0.001, b->hi[1] + 0.001, top - 0.002),
			 IRDM_PROXY_FREE);
	/* non-finite input releases */
	assert_int_equal(upd(&px, b, NULL, xc, yc, top - 0.002), IRDM_PROXY_TOUCH);
	assert_int_equal(upd(&px, b, NULL, NAN, yc, top), IRDM_EINVAL);
	assert_false(px.active);
}

/* The two top triangles that share the edge of the top's grid at x = xe
 * between y0 and y1, found by brute force: smaller index first. */
static void edge_pair(const struct box_image *b, double xe, double y0, double y1, uint32_t *pair)
{
	unsigned n = 0;

	for (uint32_t t = 0; t < b->cm.n_tris && n < 2; t++) {
		const uint32_t *v = &b->img.tris[3 * t];
		unsigned on = 0, top = 0;

		for (unsigned k = 0; k < 3; k++) {
			const float *x = b->img.nodes[v[k]].pos_m;

			top += fabs(x[2] - b->hi[2]) < 1e-9;
			on += fabs(x[0] - xe) < 1e-9 && x[1] > y0 - 1e-9 && x[1] < y1 + 1e-9;
		}
		if (top == 3 && on == 2)
			pair[n++] = t;
	}
	assert_int_equal(n, 2);
}

/*
 * A stroke exactly along an edge of the top's grid: the proxy keeps one
 * triangle (the lower index of the two that share the edge) all along,
 * whichever side it came from, without a walk; the same point gives the
 * same triangle coming from either side (no hysteresis).
 */
static void test_proxy_shared_edge(void **state)
{
	const struct box_image *b = &boxes[IMG_ALL];
	const double top = b->hi[2], xe = 0.5 * (b->lo[0] + b->hi[0]);
	const double y0 = b->lo[1] + 0.004, y1 = 0.5 * (b->lo[1] + b->hi[1]) - 0.004;
	uint32_t pair[2];

	(void)state;
	edge_pair(b, xe, b->lo[1], 0.5 * (b->lo[1] + b->hi[1]), pair);
	for (int side = -1; side <= 1; side += 2) {
		struct irdm_proxy px;

		irdm_proxy_reset(&px);
		assert_int_equal(upd(&px, b, NULL, xe + side * 0.01, y0, top - 0.002),
				 IRDM_PROXY_TOUCH);
		for (int k = 1; k <= 20; k++) /* onto the edge */
			assert_int_equal(upd(&px, b, NULL, xe + side * 0.01 * (1 - k / 20.0), y0,
					     top - 0.002),
					 IRDM_PROXY_SLIDE);
		assert_int_equal(px.tri, pair[0]);
		for (int k = 0; k <= 500; k++) {
			double y = y0 + (y1 - y0) * k / 500.0;

			assert_int_equal(upd(&px, b, NULL, xe, y, top - 0.002 - 1e-4 * sin(k)),
					 IRDM_PROXY_SLIDE);
			assert_int_equal(px.tri, pair[0]);
			assert_int_equal(px.steps, 0);
			assert_true(fabs(px.point_m[0] - xe) < 1e-12);
			assert_true(fabs(px.point_m[1] - y) < 1e-12);
		}
	}
}

/* A V-shaped surface along x = xe (u_z = s (w - |x - xe|) within w of it,
 * s > 0 a ridge, s < 0 a groove). */
static void vee_disp(const struct box_image *b, double xe, double w, double s, double *u)
{
	for (uint32_t r = 0; r < b->img.meta->n_nodes; r++) {
		const float *x = b->img.nodes[r].pos_m;
		double a = w - fabs(x[0] - xe);

		u[3 * r] = u[3 * r + 1] = 0;
		u[3 * r + 2] = fabs(x[2] - b->hi[2]) < 1e-9 && a > 0 ? s * a : 0;
	}
}

/*
 * Constraint planes at creases of the surface.  A groove (concave edge):
 * a tip pushed in past the crease, behind both faces, keeps the proxy on
 * the crease, in contact.  A ridge (convex edge): a tip past the crest
 * below the first face but in front of the second is outside: released.
 */
static void test_proxy_creases(void **state)
{
	const struct box_image *b = &boxes[IMG_ALL];
	const struct irdm_meta *m = b->img.meta;
	double *u = calloc(3 * (size_t)m->n_nodes, sizeof(double));
	struct irdm_contact_disp d = { .u_m = u };
	const double top = b->hi[2], xe = 0.5 * (b->lo[0] + b->hi[0]);
	const double w = 0.05, yc = 0.5 * (b->lo[1] + b->hi[1]) + 0.013;
	struct irdm_proxy px;
	int ev;

	(void)state;
	assert_non_null(u);
	/* groove 5 mm deep (slopes 0.1): from the left face to under the crease */
	vee_disp(b, xe, w, -0.1, u);
	irdm_proxy_reset(&px);
	assert_int_equal(upd(&px, b, &d, xe - 0.02, yc, top - 0.004), IRDM_PROXY_TOUCH);
	for (int k = 1; k <= 20; k++)
		assert_int_equal(upd(&px, b, &d, xe - 0.02 + 0.00095 * k, yc,
				     top - 0.004 - 0.00055 * k),
				 IRDM_PROXY_SLIDE);
	/* 10 mm under the crease, within 0.1 x 10 mm of it: behind both
	 * faces, each projection beyond the other face: held on the crease */
	for (int k = -9; k <= 9; k++) {
		ev = upd(&px, b, &d, xe + 0.0001 * k, yc, top - 0.1 * w - 0.01);
		assert_int_equal(ev, IRDM_PROXY_SLIDE);
		assert_true(fabs(px.point_m[0] - xe) < 1e-9);
		assert_true(fabs(px.point_m[1] - yc) < 1e-9);
		assert_true(fabs(px.point_m[2] - (top - 0.1 * w)) < 1e-9);
	}
	/* further right, 1 mm behind the right face only: on that face */
	ev = upd(&px, b, &d, xe + 0.01, yc, top - 0.1 * (w - 0.01) - 0.001);
	assert_int_equal(ev, IRDM_PROXY_SLIDE);
	assert_true(px.point_m[0] > xe + 0.009 && px.normal[0] < 0);
	/* ridge 5 mm high: sliding down past the crest, below the first face */
	vee_disp(b, xe, w, 0.1, u);
	irdm_proxy_reset(&px);
	assert_int_equal(upd(&px, b, &d, xe - 0.02, yc, top + 0.1 * (w - 0.02) - 0.001),
			 IRDM_PROXY_TOUCH);
	for (int k = 1; k <= 40; k++) {
		double x = xe - 0.02 + 0.001 * k;
		double first_face_z = top + 0.1 * (w - fabs(xe - 0.02 - xe)) + 0.1 * (x - xe + 0.02);
		double second_face_z = top + 0.1 * (w - (x - xe));

		ev = upd(&px, b, &d, x, yc, first_face_z - 0.001);
		if (first_face_z - 0.001 <= second_face_z + 1e-9 || x <= xe) {
			assert_int_equal(ev, IRDM_PROXY_SLIDE);
			continue;
		}
		assert_true(x > xe + 0.005);
		assert_int_equal(ev, IRDM_PROXY_RELEASE);
		break;
	}
	assert_false(px.active);
	free(u);
}

/*
 * The face beyond the touchable area's rim is looked at even while the
 * tip projects inside the rim triangle.  Top-only box whose x = hi side
 * leans in under the top (an overhang: u_x = -0.2 (top - z)): a tip under
 * the top, inside the rim, is in contact while it is behind the side and
 * released (and not touched again) once it is in front of it.  Box
 * touchable for x <= xe with a groove along x = xe (a concave rim): a tip
 * behind the touchable face and in front of the display-only face's
 * plane is inside the object: the contact stays.
 */
static void test_proxy_rim_faces(void **state)
{
	const struct box_image *b = &boxes[IMG_TOP], *h = &boxes[IMG_HALF];
	double *u = calloc(3 * (size_t)b->img.meta->n_nodes, sizeof(double));
	double *uh = calloc(3 * (size_t)h->img.meta->n_nodes, sizeof(double));
	struct irdm_contact_disp d = { .u_m = u }, dh = { .u_m = uh };
	const double top = b->hi[2], yc = 0.5 * (b->lo[1] + b->hi[1]) + 0.003;
	const double xe = 0.5 * (h->lo[0] + h->hi[0]);
	struct irdm_proxy px;

	(void)state;
	assert_non_null(u);
	assert_non_null(uh);
	for (uint32_t r = 0; r < b->img.meta->n_nodes; r++) {
		const float *x = b->img.nodes[r].pos_m;

		if (fabs(x[0] - b->hi[0]) < 1e-9)
			u[3 * r] = -0.2 * (top - x[2]);
	}
	irdm_proxy_reset(&px);
	assert_int_equal(upd(&px, b, &d, b->hi[0] - 0.02, yc, top - 0.002), IRDM_PROXY_TOUCH);
	/* 2 mm down, 1 mm inside the rim: the side is 0.4 mm further out */
	assert_int_equal(upd(&px, b, &d, b->hi[0] - 0.001, yc, top - 0.002), IRDM_PROXY_SLIDE);
	assert_true(px.bary[0] > 0 && px.bary[1] > 0 && px.bary[2] > 0);
	/* 10 mm down: the side is 2 mm in, the tip 1 mm in front of it */
	assert_int_equal(upd(&px, b, &d, b->hi[0] - 0.001, yc, top - 0.01), IRDM_PROXY_RELEASE);
	assert_int_equal(upd(&px, b, &d, b->hi[0] - 0.001, yc, top - 0.01), IRDM_PROXY_FREE);

	/* the concave rim: 5 mm groove at x = xe, touchable on x <= xe */
	vee_disp(h, xe, 0.05, -0.1, uh);
	irdm_proxy_reset(&px);
	assert_int_equal(upd(&px, h, &dh, xe - 0.02, yc, top - 0.004), IRDM_PROXY_TOUCH);
	for (int k = 1; k <= 18; k++) {
		double x = xe - 0.02 + 0.001 * k;
		/* 0.2 mm under the touchable face, above the other's plane */
		double z = top - 0.1 * (0.05 - (xe - x)) - 0.0002;

		assert_int_equal(upd(&px, h, &dh, x, yc, z), IRDM_PROXY_SLIDE);
		assert_true(fabs(px.point_m[0] - x) < 2e-5);
	}
	free(u);
	free(uh);
}

/*
 * The update reads the set-up's table and searches nothing: the overhang
 * of test_proxy_rim_faces on a copy of the mesh whose table says the rim
 * edges are open (a wall at right angles to the top) keeps the contact
 * the side face would end.
 */
static void test_proxy_reads_beyond_table(void **state)
{
	struct box_image b = boxes[IMG_TOP];
	const struct irdm_contact_mesh *cm = &boxes[IMG_TOP].cm;
	double *u = calloc(3 * (size_t)b.img.meta->n_nodes, sizeof(double));
	uint32_t *open = malloc(irdm_contact_beyond_size(cm));
	struct irdm_contact_disp d = { .u_m = u };
	const double top = b.hi[2], yc = 0.5 * (b.lo[1] + b.hi[1]) + 0.003;
	struct irdm_proxy px;

	(void)state;
	assert_non_null(u);
	assert_non_null(open);
	for (uint32_t k = 0; k < 3 * cm->n_tris; k++)
		open[k] = cm->adj[k];
	b.cm.beyond = open;
	for (uint32_t r = 0; r < b.img.meta->n_nodes; r++) {
		const float *x = b.img.nodes[r].pos_m;

		if (fabs(x[0] - b.hi[0]) < 1e-9)
			u[3 * r] = -0.2 * (top - x[2]);
	}
	irdm_proxy_reset(&px);
	assert_int_equal(upd(&px, &b, &d, b.hi[0] - 0.02, yc, top - 0.002), IRDM_PROXY_TOUCH);
	assert_int_equal(upd(&px, &b, &d, b.hi[0] - 0.001, yc, top - 0.002), IRDM_PROXY_SLIDE);
	/* the tip 1 mm in front of the side face, behind the open edge's wall */
	assert_int_equal(upd(&px, &b, &d, b.hi[0] - 0.001, yc, top - 0.01), IRDM_PROXY_SLIDE);
	free(open);
	free(u);
}

static int upd_mu(struct irdm_proxy *px, const struct box_image *b, double mu_s, double mu_d,
		  const double *p)
{
	struct irdm_proxy_config cfg;

	irdm_proxy_config_default(&cfg);
	cfg.max_disp_m = 0.01;
	cfg.mu_s = mu_s;
	cfg.mu_d = mu_d;
	return irdm_proxy_update(px, &b->cm, NULL, &cfg, p);
}

/* The coupling's spring energy / k: 0.5 |p - proxy|^2. */
static double spring(const double *p, const double *proxy)
{
	double d = dist3(p, proxy);

	return 0.5 * d * d;
}

/*
 * Coulomb friction against the analytic stick/slip threshold on the flat
 * top.  The device pressed 2 mm in is drawn along x in 1 um steps, then
 * back: with the coupling a spring k (device - proxy), the force on the
 * device is k (proxy - device), normal part k dn, tangential k |q - proxy|
 * (q the device's projection).  The proxy sticks (its point does not
 * move) until the tangential force reaches mu_s k dn: the largest ratio
 * while stuck is mu_s to within one step (1 um of 1 mm: 0.1 %, asserted
 * 1 %); after each slip the ratio is mu_d (the cone's rim); drawn back, it
 * sticks again until the force has turned round to mu_s the other way
 * (mu_d < mu_s: stick-slip, a slip each (mu_s - mu_d) dn of travel).
 * Dissipation: no update ever raises the spring's energy at the device's
 * new position (the proxy's move only takes energy out).
 */
static void test_proxy_friction(void **state)
{
	const struct box_image *b = &boxes[IMG_ALL];
	const double top = b->hi[2], mu_s = 0.5, mu_d = 0.4, dn = 0.002, step = 1e-6;
	double p[3] = { 0.5 * (b->lo[0] + b->hi[0]) - 0.02, 0.5 * (b->lo[1] + b->hi[1]) + 0.003,
			top - dn };
	double stuck_max = 0, back_max = 0, rim_err = 0, worst_gain = -INFINITY;
	unsigned slips = 0, back_slips = 0;
	struct irdm_proxy px;

	(void)state;
	irdm_proxy_reset(&px);
	assert_int_equal(upd_mu(&px, b, mu_s, mu_d, p), IRDM_PROXY_TOUCH);
	for (int k = 0; k < 6000; k++) {
		double before[3], ratio;
		bool back = k >= 3000;

		memcpy(before, px.point_m, sizeof(before));
		p[0] += back ? -step : step;
		double e_old = spring(p, before);

		assert_int_equal(upd_mu(&px, b, mu_s, mu_d, p), IRDM_PROXY_SLIDE);
		assert_true(fabs(px.point_m[2] - top) < 1e-12);
		assert_true(fabs(px.depth_m + dn) < 1e-12);
		worst_gain = fmax(worst_gain, spring(p, px.point_m) - e_old);
		ratio = hypot(p[0] - px.point_m[0], p[1] - px.point_m[1]) / dn;
		if (dist3(before, px.point_m) == 0) { /* stuck */
			if (back)
				back_max = back_slips ? back_max : fmax(back_max, ratio);
			else
				stuck_max = slips ? stuck_max : fmax(stuck_max, ratio);
			assert_true(ratio <= mu_s * (1 + 1e-12));
			continue;
		}
		rim_err = fmax(rim_err, fabs(ratio - mu_d));
		slips += !back;
		back_slips += back;
	}
	print_message("friction: stuck up to F_t / F_n = %.5f (mu_s %.2f), back %.5f; on the rim "
		      "|ratio - mu_d| <= %.1e; %u + %u slips; largest energy gain %.1e (k = 1)\n",
		      stuck_max, mu_s, back_max, rim_err, slips, back_slips, worst_gain);
	assert_true(slips >= 5 && back_slips >= 5); /* stick-slip: every 0.2 mm */
	assert_true(fabs(stuck_max - mu_s) <= 0.01 * mu_s);
	assert_true(fabs(back_max - mu_s) <= 0.01 * mu_s);
	assert_true(rim_err <= 1e-9);
	assert_true(worst_gain <= 1e-18);
	/* frictionless (mu_s = 0): the proxy is the projection again */
	p[0] += 0.001;
	assert_int_equal(upd_mu(&px, b, 0, 0, p), IRDM_PROXY_SLIDE);
	assert_true(fabs(px.point_m[0] - p[0]) < 1e-12);
}

/* The surface moved: contact is detected on the displaced surface, and the
 * engine's site carries the rest point with the same barycentrics. */
static void test_proxy_displaced_site(void **state)
{
	const struct box_image *b = &boxes[IMG_ALL];
	const struct irdm_meta *m = b->img.meta;
	double *u = calloc(3 * (size_t)m->n_nodes, sizeof(double));
	struct irdm_contact_disp d = { .u_m = u };
	const double top = b->hi[2], xc = b->lo[0] + 0.031, yc = b->lo[1] + 0.062;
	struct irdm_contact_site site;
	struct irdm_proxy px;
	double rest[3] = { 0, 0, 0 }, moved[3] = { 0, 0, 0 };

	(void)state;
	assert_non_null(u);
	for (uint32_t r = 0; r < m->n_nodes; r++)
		u[3 * r + 2] = -0.005;
	irdm_proxy_reset(&px);
	assert_int_equal(irdm_proxy_site(&px, &b->cm, &site), IRDM_EINVAL);
	assert_int_equal(upd(&px, b, &d, xc, yc, top - 0.002), IRDM_PROXY_FREE);
	assert_int_equal(upd(&px, b, &d, xc, yc, top - 0.006), IRDM_PROXY_TOUCH);
	assert_true(fabs(px.point_m[2] - (top - 0.005)) < 1e-12);
	assert_true(fabs(px.depth_m + 0.001) < 1e-12);
	assert_int_equal(irdm_proxy_site(&px, &b->cm, &site), IRDM_OK);
	assert_int_equal(site.n_nodes, 3);
	for (unsigned k = 0; k < 3; k++) {
		uint32_t r = site.row[k];

		assert_int_equal(r, b->img.tris[3 * px.tri + k]);
		assert_true(site.col[k] < m->n_cols);
		assert_int_equal(b->img.columns[site.col[k]], r);
		assert_true(site.weight[k] == px.bary[k]);
		for (unsigned a = 0; a < 3; a++) {
			rest[a] += site.weight[k] * b->img.nodes[r].pos_m[a];
			moved[a] += site.weight[k] * (b->img.nodes[r].pos_m[a] + u[3 * r + a]);
		}
	}
	assert_true(fabs(site.weight[0] + site.weight[1] + site.weight[2] - 1) < 1e-12);
	assert_true(dist3(rest, site.rest_m) < 1e-12);
	assert_true(dist3(moved, px.point_m) < 1e-12);
	assert_true(fabs(site.rest_m[0] - xc) < 1e-12 && fabs(site.rest_m[1] - yc) < 1e-12);
	assert_true(fabs(site.rest_m[2] - top) < 1e-12);
	assert_true(fabs(site.normal[2] - 1) < 1e-12);
	/* the surface sinks away from the still device: released */
	for (uint32_t r = 0; r < m->n_nodes; r++)
		u[3 * r + 2] = -0.0065;
	assert_int_equal(upd(&px, b, &d, xc, yc, top - 0.006), IRDM_PROXY_RELEASE);
	free(u);
}

/* ----------------------------------------------------------- the loader */

struct bvh_copy {
	uint8_t *buf;
	size_t size;
	uint8_t *payload; /* BVH payload inside buf */
	struct irdm_bvh_header h;
};

static void copy_image(const struct box_image *b, struct bvh_copy *c)
{
	c->size = b->img.size;
	c->buf = img_fixture_copy(b->img.base, b->img.size);
	assert_non_null(c->buf);
	c->payload = c->buf + ((const uint8_t *)b->img.contact_bvh - b->img.base);
	memcpy(&c->h, c->payload, sizeof(c->h));
}

static struct irdm_bvh_node *node_at(struct bvh_copy *c, uint32_t i)
{
	return (struct irdm_bvh_node *)(c->payload + c->h.nodes_offset) + i;
}

static uint32_t *u32_at(struct bvh_copy *c, uint32_t off, uint32_t i)
{
	return (uint32_t *)(c->payload + off) + i;
}

static void expect_reject(struct bvh_copy *c, const char *needle)
{
	struct irdm_image img;
	char err[256];
	int ret;

	img_fixture_reseal(c->buf, c->size);
	ret = irdm_image_parse(c->buf, c->size, &img, err, sizeof(err));
	if (ret != IRDM_EFORMAT || !strstr(err, needle) || strchr(err, '\n'))
		fail_msg("expected EFORMAT with \"%s\", got %d: %s", needle, ret, err);
	assert_null(img.contact_bvh);
	assert_null(img.meta);
	free(c->buf);
}

static uint32_t first_internal(struct bvh_copy *c)
{
	for (uint32_t i = 0; i < c->h.n_bvh_nodes; i++)
		if (node_at(c, i)->count_or_right & IRDM_BVH_INTERNAL)
			return i;
	fail_msg("no internal node");
	return 0;
}

static uint32_t first_leaf(struct bvh_copy *c)
{
	for (uint32_t i = 0; i < c->h.n_bvh_nodes; i++)
		if (!(node_at(c, i)->count_or_right & IRDM_BVH_INTERNAL))
			return i;
	fail_msg("no leaf");
	return 0;
}

static void test_loader_rejects(void **state)
{
	const struct box_image *b = &boxes[IMG_ALL];
	struct bvh_copy c;
	uint32_t i, t;

	(void)state;
	/* the untouched copy loads */
	copy_image(b, &c);
	{
		struct irdm_image img;
		char err[256];

		img_fixture_reseal(c.buf, c.size);
		assert_int_equal(irdm_image_parse(c.buf, c.size, &img, err, sizeof(err)), 0);
		assert_non_null(img.contact_bvh);
		free(c.buf);
	}

	copy_image(b, &c); /* child out of range */
	i = first_internal(&c);
	node_at(&c, i)->left_or_first = c.h.n_bvh_nodes;
	expect_reject(&c, "child");

	copy_image(b, &c); /* right child out of range */
	i = first_internal(&c);
	node_at(&c, i)->count_or_right = IRDM_BVH_INTERNAL | 0x7fffffffu;
	expect_reject(&c, "child");

	copy_image(b, &c); /* cycle: a child pointing at the root */
	i = first_internal(&c);
	i = node_at(&c, i)->count_or_right & ~IRDM_BVH_INTERNAL;
	while (!(node_at(&c, i)->count_or_right & IRDM_BVH_INTERNAL))
		i++;
	node_at(&c, i)->left_or_first = 0;
	expect_reject(&c, "child");

	copy_image(b, &c); /* self loop */
	i = first_internal(&c);
	node_at(&c, i)->left_or_first = i;
	expect_reject(&c, "child");

	copy_image(b, &c); /* two parents: shared subtree */
	i = first_internal(&c);
	node_at(&c, i)->count_or_right = IRDM_BVH_INTERNAL | node_at(&c, i)->left_or_first;
	expect_reject(&c, "more than one parent");

	copy_image(b, &c); /* NaN box */
	node_at(&c, c.h.n_bvh_nodes - 1)->lo[1] = NAN;
	expect_reject(&c, "box");

	copy_image(b, &c); /* inverted box */
	node_at(&c, 0)->lo[2] = node_at(&c, 0)->hi[2] + 1;
	expect_reject(&c, "box");

	copy_image(b, &c); /* leaf box misses its triangle */
	i = first_leaf(&c);
	for (unsigned a = 0; a < 3; a++)
		if (node_at(&c, i)->lo[a] < node_at(&c, i)->hi[a]) {
			node_at(&c, i)->hi[a] = node_at(&c, i)->lo[a];
			break;
		}
	expect_reject(&c, "contain");

	copy_image(b, &c); /* bad leaf range: past the list */
	i = first_leaf(&c);
	node_at(&c, i)->left_or_first = c.h.n_contact_tris - 1;
	node_at(&c, i)->count_or_right = 2;
	expect_reject(&c, "leaf");

	copy_image(b, &c); /* bad leaf range: too many */
	i = first_leaf(&c);
	node_at(&c, i)->count_or_right = IRDM_BVH_LEAF_MAX + 1;
	expect_reject(&c, "leaf");

	copy_image(b, &c); /* bad leaf range: overlapping leaves */
	i = first_leaf(&c);
	node_at(&c, i)->left_or_first = node_at(&c, i)->left_or_first ? 0 : 1;
	expect_reject(&c, "leaf");

	copy_image(b, &c); /* index out of range */
	*u32_at(&c, c.h.index_offset, 3) = b->img.meta->n_tris;
	expect_reject(&c, "index[3]");

	copy_image(b, &c); /* index repeats */
	*u32_at(&c, c.h.index_offset, 3) = *u32_at(&c, c.h.index_offset, 4);
	expect_reject(&c, "repeats");

	copy_image(b, &c); /* index names a non-contactable triangle */
	for (t = 0; irdm_contact_tri_contactable(&b->cm, t); t++)
		;
	*u32_at(&c, c.h.index_offset, 0) = t;
	expect_reject(&c, "not a column");

	copy_image(b, &c); /* asymmetric adjacency */
	for (t = 0; *u32_at(&c, c.h.adj_offset, 3 * t) == IRDM_BVH_NONE; t++)
		;
	for (i = 0; *u32_at(&c, c.h.index_offset, i) == t ||
		    *u32_at(&c, c.h.index_offset, i) == *u32_at(&c, c.h.adj_offset, 3 * t);
	     i++)
		;
	*u32_at(&c, c.h.adj_offset, 3 * t) = *u32_at(&c, c.h.index_offset, i);
	expect_reject(&c, "neighbour");

	copy_image(b, &c); /* adjacency out of range */
	*u32_at(&c, c.h.adj_offset, 3 * t + 0) = b->img.meta->n_tris + 7;
	expect_reject(&c, "neighbour");

	copy_image(b, &c); /* col_of_row wrong */
	*u32_at(&c, c.h.col_of_row_offset, b->img.columns[0]) = 1;
	expect_reject(&c, "col_of_row");

	copy_image(b, &c); /* depth lies */
	((struct irdm_bvh_header *)c.payload)->depth = c.h.depth + 1;
	expect_reject(&c, "levels deep");

	copy_image(b, &c); /* depth beyond the limit */
	((struct irdm_bvh_header *)c.payload)->depth = IRDM_BVH_MAX_DEPTH + 1;
	expect_reject(&c, "depth");

	copy_image(b, &c); /* layout */
	((struct irdm_bvh_header *)c.payload)->adj_offset += 4;
	expect_reject(&c, "layout");

	copy_image(b, &c); /* counts */
	((struct irdm_bvh_header *)c.payload)->n_surface_tris += 1;
	expect_reject(&c, "triangles");

	copy_image(b, &c); /* reserved */
	((struct irdm_bvh_header *)c.payload)->reserved[5] = 1;
	expect_reject(&c, "reserved");
}

/* A small image written by hand: without the section it loads with no BVH;
 * the version 1.0 reserved form (not BYTES) is skipped; a BVH built for it
 * loads; a payload too short for its header is rejected. */
static void test_fixture_images(void **state)
{
	struct irdm_image_writer w;
	struct img_fixture fx;
	struct irdm_contact_mesh cm;
	struct irdm_contact_hit h;
	struct irdm_image img;
	static const uint32_t blob[10] = { 1, 2, 3 };
	double p[3] = { 0.015, 0.005, 0.001 };
	char err[256];
	void *bvh, *buf;
	size_t bvh_size, size;

	(void)state;
	assert_int_equal(img_fixture_fir(&fx, IRDM_ELEM_F32, 16, 16, 2), 0);
	/* no section */
	assert_int_equal(img_fixture_buffer(&fx, &buf, &size), 0);
	assert_int_equal(irdm_image_parse(buf, size, &img, err, sizeof(err)), 0);
	assert_null(img.contact_bvh);
	assert_int_equal(irdm_contact_mesh_init(&cm, &img), IRDM_EINVAL);
	free(buf);
	/* reserved form */
	irdm_iw_init(&w);
	img_fixture_add(&fx, &w);
	assert_int_equal(irdm_iw_add(&w, IRDM_SEC_CONTACT_BVH, IRDM_ELEM_U32, blob, 40), 0);
	assert_int_equal(irdm_iw_to_buffer(&w, &buf, &size), 0);
	assert_int_equal(irdm_image_parse(buf, size, &img, err, sizeof(err)), 0);
	assert_null(img.contact_bvh);
	free(buf);
	/* too short */
	irdm_iw_init(&w);
	img_fixture_add(&fx, &w);
	assert_int_equal(irdm_iw_add(&w, IRDM_SEC_CONTACT_BVH, IRDM_ELEM_BYTES, blob, 40), 0);
	assert_int_equal(irdm_iw_to_buffer(&w, &buf, &size), 0);
	assert_int_equal(irdm_image_parse(buf, size, &img, err, sizeof(err)), IRDM_EFORMAT);
	assert_non_null(strstr(err, "CONTACT_BVH"));
	free(buf);
	/* built: a fan on a 4 x 4 grid, all nodes columns (some triangles are
	 * flat-degenerate: collinear grid points) */
	assert_int_equal(irdm_bvh_build(fx.nodes, fx.meta.n_nodes, fx.columns, fx.meta.n_cols,
					fx.tris, fx.meta.n_tris, &bvh, &bvh_size, err, sizeof(err)),
			 0);
	irdm_iw_init(&w);
	img_fixture_add(&fx, &w);
	assert_int_equal(irdm_iw_add(&w, IRDM_SEC_CONTACT_BVH, IRDM_ELEM_BYTES, bvh, bvh_size), 0);
	assert_int_equal(irdm_iw_to_buffer(&w, &buf, &size), 0);
	if (irdm_image_parse(buf, size, &img, err, sizeof(err)))
		fail_msg("%s", err);
	assert_non_null(img.contact_bvh);
	assert_int_equal(img.contact_bvh->n_contact_tris, fx.meta.n_tris);
	assert_int_equal(irdm_contact_mesh_init(&cm, &img), 0);
	assert_int_equal(irdm_contact_closest(&cm, NULL, 0, p, 0.1, &h), 1);
	assert_true(fabs(fabs(h.dist_m) - 0.001) < 1e-9);
	free(buf);
	free(bvh);
	/* no contactable triangle: an empty tree loads, queries find nothing */
	img_fixture_free(&fx);
	assert_int_equal(img_fixture_fir(&fx, IRDM_ELEM_F32, 6, 2, 2), 0);
	assert_int_equal(irdm_bvh_build(fx.nodes, fx.meta.n_nodes, fx.columns, fx.meta.n_cols,
					fx.tris, fx.meta.n_tris, &bvh, &bvh_size, err, sizeof(err)),
			 0);
	irdm_iw_init(&w);
	img_fixture_add(&fx, &w);
	assert_int_equal(irdm_iw_add(&w, IRDM_SEC_CONTACT_BVH, IRDM_ELEM_BYTES, bvh, bvh_size), 0);
	assert_int_equal(irdm_iw_to_buffer(&w, &buf, &size), 0);
	if (irdm_image_parse(buf, size, &img, err, sizeof(err)))
		fail_msg("%s", err);
	assert_int_equal(img.contact_bvh->n_bvh_nodes, 0);
	assert_int_equal(irdm_contact_mesh_init(&cm, &img), 0);
	assert_int_equal(irdm_contact_closest(&cm, NULL, 0, p, 1, &h), 0);
	free(buf);
	free(bvh);
	/* the builder refuses bad indices */
	fx.tris[0] = 99;
	assert_int_equal(irdm_bvh_build(fx.nodes, fx.meta.n_nodes, fx.columns, fx.meta.n_cols,
					fx.tris, fx.meta.n_tris, &bvh, &bvh_size, err, sizeof(err)),
			 IRDM_EINVAL);
	assert_non_null(strstr(err, "triangle 0"));
	img_fixture_free(&fx);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_bvh_present),
		cmocka_unit_test(test_adjacency),
		cmocka_unit_test(test_point_triangle),
		cmocka_unit_test(test_closest_rest),
		cmocka_unit_test(test_closest_displaced),
		cmocka_unit_test(test_closest_args),
		cmocka_unit_test(test_box_normals),
		cmocka_unit_test(test_proxy_stroke),
		cmocka_unit_test(test_proxy_deep),
		cmocka_unit_test(test_proxy_edges),
		cmocka_unit_test(test_proxy_boundary),
		cmocka_unit_test(test_proxy_shared_edge),
		cmocka_unit_test(test_proxy_creases),
		cmocka_unit_test(test_proxy_rim_faces),
		cmocka_unit_test(test_proxy_reads_beyond_table),
		cmocka_unit_test(test_beyond_table),
		cmocka_unit_test(test_proxy_friction),
		cmocka_unit_test(test_proxy_displaced_site),
		cmocka_unit_test(test_loader_rejects),
		cmocka_unit_test(test_fixture_images),
	};

	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
