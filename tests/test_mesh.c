// SPDX-License-Identifier: MIT
/*
 * Mesh module: generators, validation, boundary extraction, TetGen and
 * Gmsh readers.  Expected numbers come from geometry (box volumes, face
 * counts), not from the code under test.  Text inputs are copied into
 * exactly-sized heap buffers so AddressSanitizer catches any read past
 * the given length.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mesh/mesh.h"

#define DATA "tests/data/mesh/"

/* ---- helpers --------------------------------------------------------- */

/* A heap copy of s without the terminating NUL. */
static char *exact_copy(const char *s, size_t len)
{
	char *p = malloc(len ? len : 1);

	assert_non_null(p);
	memcpy(p, s, len);
	return p;
}

static int parse_tetgen_str(const char *node, size_t node_len, const char *ele,
			    size_t ele_len, struct irdm_mesh *m, char *err,
			    size_t errlen)
{
	char *n = exact_copy(node, node_len), *e = exact_copy(ele, ele_len);
	int ret;

	ret = irdm_mesh_parse_tetgen(n, node_len, e, ele_len, "t.ele", m, err,
				     errlen);
	if (!ret)
		ret = irdm_mesh_finish(m, "t.ele", err, errlen);
	free(n);
	free(e);
	return ret;
}

static int parse_gmsh_str(const char *txt, size_t len, struct irdm_mesh *m,
			  char *err, size_t errlen)
{
	char *p = exact_copy(txt, len);
	int ret;

	ret = irdm_mesh_parse_gmsh(p, len, "t.msh", m, err, errlen);
	if (!ret)
		ret = irdm_mesh_finish(m, "t.msh", err, errlen);
	free(p);
	return ret;
}

/* Scratch directory for file-based tests (group setup/teardown). */
static char scratch[] = "/tmp/irdm-test-mesh-XXXXXX";

static void scratch_path(char *buf, size_t n, const char *name)
{
	snprintf(buf, n, "%s/%s", scratch, name);
}

static void write_file(const char *name, const void *data, size_t len)
{
	char path[128];
	FILE *f;

	scratch_path(path, sizeof(path), name);
	f = fopen(path, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(data, 1, len, f), len);
	assert_int_equal(fclose(f), 0);
}

static int group_setup(void **state)
{
	(void)state;
	return mkdtemp(scratch) ? 0 : -1;
}

static int group_teardown(void **state)
{
	static const char *const names[] = { "t.node", "t.ele", "t.msh" };
	char path[128];
	size_t i;

	(void)state;
	for (i = 0; i < sizeof(names) / sizeof(names[0]); i++) {
		scratch_path(path, sizeof(path), names[i]);
		remove(path);
	}
	return remove(scratch);
}

static void assert_empty(const struct irdm_mesh *m)
{
	assert_int_equal(m->n_nodes, 0);
	assert_int_equal(m->n_tets, 0);
	assert_int_equal(m->n_tris, 0);
	assert_null(m->pos_m);
	assert_null(m->tets);
	assert_null(m->tris);
}

/* The parse must fail with a one-line message starting with what. */
static void assert_err(int ret, const struct irdm_mesh *m, const char *err,
		       const char *what, const char *needle)
{
	if (ret >= 0 || ret < IRDM_ERR_MIN)
		fail_msg("expected failure with \"%s\" (an IRDM_E* code, got %d)", needle, ret);
	assert_empty(m);
	if (strncmp(err, what, strlen(what)))
		fail_msg("message \"%s\" does not start with \"%s\"", err, what);
	assert_null(strchr(err, '\n'));
	if (!strstr(err, needle))
		fail_msg("message \"%s\" lacks \"%s\"", err, needle);
}

static void tri_normal(const struct irdm_mesh *m, size_t t, double n[3])
{
	const double *a = m->pos_m + 3 * m->tris[3 * t];
	const double *b = m->pos_m + 3 * m->tris[3 * t + 1];
	const double *c = m->pos_m + 3 * m->tris[3 * t + 2];
	double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
	double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };

	n[0] = u[1] * v[2] - u[2] * v[1];
	n[1] = u[2] * v[0] - u[0] * v[2];
	n[2] = u[0] * v[1] - u[1] * v[0];
}

/*
 * A closed outward surface has zero area-weighted normal sum, and by the
 * divergence theorem sum a.(b x c)/6 over its triangles is the volume
 * enclosed, which must equal the sum of the tet volumes.
 */
static void assert_closed_outward(const struct irdm_mesh *m, double scale)
{
	double sum[3] = { 0, 0, 0 }, vol = 0.0, n[3];
	size_t t;

	assert_true(m->n_tris > 0);
	for (t = 0; t < m->n_tris; t++) {
		const double *a = m->pos_m + 3 * m->tris[3 * t];
		const double *b = m->pos_m + 3 * m->tris[3 * t + 1];
		const double *c = m->pos_m + 3 * m->tris[3 * t + 2];

		tri_normal(m, t, n);
		sum[0] += n[0];
		sum[1] += n[1];
		sum[2] += n[2];
		vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) +
			a[1] * (b[2] * c[0] - b[0] * c[2]) +
			a[2] * (b[0] * c[1] - b[1] * c[0])) /
		       6.0;
	}
	assert_true(fabs(sum[0]) < 1e-12 * scale * scale);
	assert_true(fabs(sum[1]) < 1e-12 * scale * scale);
	assert_true(fabs(sum[2]) < 1e-12 * scale * scale);
	assert_true(fabs(vol - irdm_mesh_volume(m)) < 1e-12 * fabs(vol));
}

/*
 * Every boundary triangle of an axis-aligned box lies in one of its six
 * faces, and its normal is that face's outward normal.
 */
static void assert_box_boundary(const struct irdm_mesh *m, const double l[3])
{
	size_t t;
	int k, v, axis, hits;
	double n[3];

	for (t = 0; t < m->n_tris; t++) {
		tri_normal(m, t, n);
		hits = 0;
		for (axis = 0; axis < 3; axis++) {
			for (k = 0; k < 2; k++) {
				double plane = k ? l[axis] : 0.0, out = k ? 1 : -1;
				int on = 1;

				for (v = 0; v < 3; v++)
					on &= fabs(m->pos_m[3 * m->tris[3 * t + v] + axis] -
						   plane) < 1e-12;
				if (!on)
					continue;
				hits++;
				assert_true(n[axis] * out > 0);
				assert_true(fabs(n[(axis + 1) % 3]) < 1e-15);
				assert_true(fabs(n[(axis + 2) % 3]) < 1e-15);
			}
		}
		assert_int_equal(hits, 1);
	}
}

static void check_box(double lx, double ly, double lz, unsigned nx, unsigned ny,
		      unsigned nz, unsigned per_hex)
{
	const double l[3] = { lx, ly, lz };
	struct irdm_mesh m;
	char err[256];
	size_t tris;

	assert_int_equal(irdm_mesh_gen_box(lx, ly, lz, nx, ny, nz, per_hex, &m,
					   err, sizeof(err)),
			 0);
	assert_int_equal(m.n_nodes, (size_t)(nx + 1) * (ny + 1) * (nz + 1));
	assert_int_equal(m.n_tets, (size_t)nx * ny * nz * per_hex);
	assert_true(fabs(irdm_mesh_volume(&m) - lx * ly * lz) <
		    1e-12 * lx * ly * lz);
	/* two triangles per boundary quad; a non-conforming split adds more */
	tris = 2 * 2 * ((size_t)nx * ny + (size_t)ny * nz + (size_t)nx * nz);
	assert_int_equal(m.n_tris, tris);
	assert_box_boundary(&m, l);
	assert_closed_outward(&m, fmax(lx, fmax(ly, lz)));
	/* node (i,j,k) sits at index i + (nx+1)(j + (ny+1)k) */
	assert_true(m.pos_m[3 * (nx + (nx + 1) * (ny + (ny + 1) * (size_t)nz))] == lx);
	assert_true(m.pos_m[3 * ((nx + 1) * (size_t)1) + 1] == ly / ny);
	irdm_mesh_free(&m);
}

/* ---- generators ------------------------------------------------------ */

static void test_box_paper_cuboid(void **state)
{
	struct irdm_mesh m;
	char err[256];

	(void)state;
	assert_int_equal(irdm_mesh_gen_box(0.1, 0.1, 0.2, 11, 11, 22, 5, &m, err,
					   sizeof(err)),
			 0);
	assert_int_equal(m.n_nodes, 3312);
	assert_int_equal(m.n_tets, 13310);
	assert_true(fabs(irdm_mesh_volume(&m) - 0.002) < 1e-15);
	assert_int_equal(m.n_tris, 4 * (11 * 11 + 11 * 22 + 11 * 22));
	assert_string_equal(m.name, "box-11x11x22-5");
	irdm_mesh_free(&m);
	check_box(0.1, 0.1, 0.2, 11, 11, 22, 5);
}

static void test_box_cubes(void **state)
{
	unsigned n;

	(void)state;
	for (n = 1; n <= 5; n++) {
		check_box(1.0, 1.0, 1.0, n, n, n, 5);
		check_box(1.0, 1.0, 1.0, n, n, n, 6);
	}
	check_box(0.3, 0.02, 1.7, 3, 2, 7, 5);
	check_box(0.3, 0.02, 1.7, 4, 1, 3, 6);
}

static void test_box_bad_args(void **state)
{
	struct irdm_mesh m;
	char err[256];

	(void)state;
	assert_err(irdm_mesh_gen_box(1, 1, 1, 0, 1, 1, 5, &m, err, sizeof(err)),
		   &m, err, "box", "hexes");
	assert_err(irdm_mesh_gen_box(1, 1, 1, 1, 1, 1, 4, &m, err, sizeof(err)),
		   &m, err, "box", "5 or 6");
	assert_err(irdm_mesh_gen_box(1, -1, 1, 1, 1, 1, 5, &m, err, sizeof(err)),
		   &m, err, "box", "positive");
	assert_err(irdm_mesh_gen_box(1, NAN, 1, 1, 1, 1, 5, &m, err, sizeof(err)),
		   &m, err, "box", "positive");
	assert_err(irdm_mesh_gen_box(1, 1, 1, 100000, 100000, 100000, 6, &m, err,
				     sizeof(err)),
		   &m, err, "box", "too many");
}

/* FNV-1a 64 reference, written out from its definition. */
static uint64_t ref_fnv(const void *a, size_t na, const void *b, size_t nb)
{
	const unsigned char *p = a;
	uint64_t h = 0xcbf29ce484222325ULL;
	size_t i;

	for (i = 0; i < na + nb; i++) {
		if (i == na)
			p = b;
		h = (h ^ p[i < na ? i : i - na]) * 0x100000001b3ULL;
	}
	return h;
}

static void test_hash(void **state)
{
	struct irdm_mesh m, e;
	char err[256];
	uint64_t h;

	(void)state;
	memset(&e, 0, sizeof(e));
	assert_true(irdm_mesh_hash(&e) == 0xcbf29ce484222325ULL);
	assert_int_equal(irdm_mesh_gen_box(1, 1, 1, 2, 2, 2, 5, &m, err,
					   sizeof(err)),
			 0);
	h = irdm_mesh_hash(&m);
	assert_true(h == ref_fnv(m.pos_m, 3 * m.n_nodes * sizeof(double), m.tets,
				 4 * m.n_tets * sizeof(uint32_t)));
	m.pos_m[5] += 1e-9;
	assert_true(irdm_mesh_hash(&m) != h);
	irdm_mesh_free(&m);
}

/* ---- TetGen ----------------------------------------------------------- */

/* The unit cube as 5 tets; node i at ((i-1)&1, (i-1)>>1&1, (i-1)>>2&1). */
static const char cube_node1[] =
	"# 1-based\n8 3 0 1\n"
	"1 0 0 0 1\n2 1 0 0 1\n3 0 1 0 1\n4 1 1 0 1\n"
	"5 0 0 1 1\n6 1 0 1 1\n7 0 1 1 1\n8 1 1 1 1\n";
static const char cube_ele1[] =
	"5 4 0\n1 1 4 7 6\n2 2 1 6 4\n3 3 4 7 1\n4 5 6 1 7\n5 8 7 4 6\n";
static const char cube_node0[] =
	"8  3  1  0   # one attribute, no markers\n"
	"0 0 0 0 9.5\n1 1 0 0 9.5\n2 0 1 0 9.5\n3 1 1 0 9.5\n"
	"4 0 0 1 9.5\n\n5 1 0 1 9.5\n6 0 1 1 9.5\n7 1 1 1 9.5\n";
static const char cube_ele0[] =
	"5 4 1\n0 0 3 6 5 1\n1 1 0 5 3 1\n# comment\n2 2 3 6 0 1\n"
	"3 4 5 0 6 1\n4 7 6 3 5 1"; /* no final newline */

static void test_tetgen_cube(void **state)
{
	struct irdm_mesh a, b;
	char err[256];

	(void)state;
	assert_int_equal(parse_tetgen_str(cube_node1, strlen(cube_node1), cube_ele1,
					  strlen(cube_ele1), &a, err, sizeof(err)),
			 0);
	assert_int_equal(parse_tetgen_str(cube_node0, strlen(cube_node0), cube_ele0,
					  strlen(cube_ele0), &b, err, sizeof(err)),
			 0);
	assert_int_equal(a.n_nodes, 8);
	assert_int_equal(a.n_tets, 5);
	assert_true(fabs(irdm_mesh_volume(&a) - 1.0) < 1e-15);
	assert_true(fabs(irdm_mesh_volume(&b) - 1.0) < 1e-15);
	/* 0- and 1-based files describe the same mesh */
	assert_memory_equal(a.tets, b.tets, 20 * sizeof(uint32_t));
	assert_memory_equal(a.pos_m, b.pos_m, 24 * sizeof(double));
	assert_true(irdm_mesh_hash(&a) == irdm_mesh_hash(&b));
	assert_int_equal(a.n_tris, 12);
	assert_closed_outward(&a, 1.0);
	assert_box_boundary(&a, (const double[3]){ 1, 1, 1 });
	assert_string_equal(a.name, "t");
	irdm_mesh_free(&a);
	irdm_mesh_free(&b);
}

static void test_tetgen_ten_node(void **state)
{
	static const char node[] =
		"5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 0.5 0 0\n";
	static const char ele[] = "1 10 0\n1 1 2 3 4 5 5 5 5 5 5\n";
	struct irdm_mesh m;
	char err[256];
	int ret;

	(void)state;
	/* the mid-edge node is unused here, which finish rightly rejects */
	ret = parse_tetgen_str(node, strlen(node), ele, strlen(ele), &m, err,
			       sizeof(err));
	assert_err(ret, &m, err, "t.ele", "node 5 is not used");
	ret = parse_tetgen_str(node, strlen(node) - 11, "1 10 0\n1 1 2 3 4\n", 17,
			       &m, err, sizeof(err));
	assert_err(ret, &m, err, "t.ele", "truncated");
	ret = parse_tetgen_str("4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", 40,
			       "1 10 0\n1 1 2 3 4 1 1 1 1 1 1\n", 29, &m, err,
			       sizeof(err));
	assert_int_equal(ret, 0);
	assert_true(fabs(irdm_mesh_volume(&m) - 1.0 / 6.0) < 1e-15);
	irdm_mesh_free(&m);
}

static void test_tetgen_real_output_orientation(void **state)
{
	/* Verbatim head of `tetgen -pq1.414Q` output for a unit cube. */
	static const char node[] =
		"8  3  0  0\n   1    0  0  0\n   2    1  0  0\n   3    1  1  0\n"
		"   4    0  1  0\n   5    0  0  1\n   6    1  0  1\n   7    1  1  1\n"
		"   8    0  1  1\n# Generated by tetgen -pq1.414Q cube.poly \n";
	static const char ele[] =
		"6  4  0\n    1       1     4     8     3\n    2       1     8     5     7\n"
		"    3       6     1     5     7\n    4       1     8     7     3\n"
		"    5       6     1     7     2\n    6       1     3     7     2\n"
		"# Generated by tetgen -pq1.414Q cube.poly \n";
	struct irdm_mesh m;
	char err[256];

	(void)state;
	assert_int_equal(parse_tetgen_str(node, strlen(node), ele, strlen(ele), &m,
					  err, sizeof(err)),
			 0);
	assert_true(fabs(irdm_mesh_volume(&m) - 1.0) < 1e-15);
	irdm_mesh_free(&m);
}

/*
 * Each case runs twice: in memory (parse + finish, elements named by
 * 1-based position) and through irdm_mesh_read() on files, which names
 * them as the file does; file_needle differs only for 0-based files.
 */
static void test_tetgen_errors(void **state)
{
	static const struct {
		const char *node, *ele, *needle, *file_needle;
	} cases[] = {
		/* element 3 with two nodes swapped */
		{ cube_node1, "5 4 0\n1 1 4 6 7\n2 2 1 6 4\n3 3 4 7 1\n4 5 6 1 7\n5 8 7 4 6\n",
		  "t.ele: element 1 is inverted (volume -0.333 m^3)", NULL },
		{ cube_node1, "5 4 0\n1 1 4 7 6\n2 2 1 6 4\n3 3 4 1 7\n4 5 6 1 7\n5 8 7 4 6\n",
		  "element 3 is inverted (volume -0.167 m^3)", NULL },
		/* 0-based file: its own index 2 is named */
		{ cube_node0, "5 4 0\n0 0 3 6 5\n1 1 0 5 3\n2 2 3 0 6\n3 4 5 0 6\n4 7 6 3 5\n",
		  "element 3 is inverted", "t.ele: element 2 is inverted" },
		{ "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 0 0 2\n",
		  "1 4 0\n0 0 1 2 3\n", "node 5 is not used", "t.node: node 4 is not used" },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 1 1 0\n", "1 4 0\n1 1 2 3 4\n",
		  "element 1 has zero volume", NULL },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1e-13\n", "1 4 0\n1 1 2 3 4\n",
		  "element 1 has zero volume", NULL },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 nan 1 0\n4 0 0 1\n", "1 4 0\n1 1 2 3 4\n",
		  "node 3 has a non-finite coordinate", NULL },
		/* attributes declared: a billion, or more than the records hold */
		{ "4 3 1000000000 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", "1 4 0\n1 1 2 3 4\n",
		  "line 1: 1000000000 attributes and marker flag 0 per node", NULL },
		{ "4 3 2 1\n1 0 0 0 5\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", "1 4 0\n1 1 2 3 4\n",
		  "line 2: the header declares 3 attribute or marker values per node, the line has 1",
		  NULL },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", "1 4 1\n1 1 2 3 4\n",
		  "line 2: the header declares 1 attribute or marker value per element, the line has 0",
		  NULL },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 inf\n", "1 4 0\n1 1 2 3 4\n",
		  "node 4 has a non-finite coordinate", NULL },
		{ "5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 9 9 9\n", "1 4 0\n1 1 2 3 4\n",
		  "node 5 is not used by any element", NULL },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", "1 4 0\n1 1 2 3 5\n",
		  "element 1 refers to node 5, which is not in the node file", NULL },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", "1 4 0\n1 1 2 3 0\n",
		  "refers to node 0", NULL },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", "1 4 0\n1 1 2 3 3\n",
		  "element 1 uses node 3 twice", NULL },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", "2 4 0\n1 1 2 3 4\n2 1 2 3 4\n",
		  "elements 1 and 2 overlap", NULL },
		/* three tets on one face */
		{ "6 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 0 0 -1\n6 0.1 0.1 2\n",
		  "3 4 0\n1 1 2 3 4\n2 1 3 2 5\n3 1 2 3 6\n", "non-manifold", NULL },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n", "1 4 0\n1 1 2 3 4\n",
		  "truncated: 3 of 4 nodes", NULL },
		{ cube_node1, "5 4 0\n1 1 4 7 6\n2 2 1 6 4\n", "(truncated?)", NULL },
		{ cube_node1, "3 4 0\n1 1 4 7 6\n2 2 1 6 4\n# a long comment\n",
		  "truncated: 2 of 3 elements", NULL },
		{ "4 3 0 0\n1 0 0 0\n3 1 0 0\n4 0 1 0\n5 0 0 1\n", "1 4 0\n",
		  "line 3: node index 3, expected 2", NULL },
		{ "1 3 0 0\n2 0 0 0\n", "1 4 0\n", "first node index is 2", NULL },
		{ "1 2 0 0\n1 0 0\n", "1 4 0\n", "dimension is 2", NULL },
		{ "0 3 0 0\n", "1 4 0\n", "declares 0 nodes", NULL },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", "1 8 0\n1 1 2 3 4\n",
		  "8 nodes per element", NULL },
		{ "49999999 3 0 0\n1 0 0 0\n", "1 4 0\n", "truncated?", NULL },
		{ "999999999999 3 0 0\n", "1 4 0\n", "limit", NULL },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0\n", "1 4 0\n", "needs 3 coordinates", NULL },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1x\n", "1 4 0\n", "needs 3 coordinates", NULL },
		{ "\x01\xff garbage", "1 4 0\n", "bad node header", NULL },
		{ "", "", "empty node file", NULL },
		{ "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", "# nothing\n", "empty element file", NULL },
		{ "4 3 0 0\n1 1e400 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", "1 4 0\n1 1 2 3 4\n",
		  "node 1 has a non-finite", NULL },
		{ "4 3 0 0\n1 1e300 0 0\n2 -1e300 0 0\n3 0 1e300 0\n4 0 0 1e300\n",
		  "1 4 0\n1 1 2 3 4\n", "too large to measure", NULL },
	};
	struct irdm_mesh m;
	char err[256], path[128];
	size_t i;
	int ret;

	(void)state;
	scratch_path(path, sizeof(path), "t.ele");
	for (i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		const char *fneedle = cases[i].file_needle ? cases[i].file_needle :
							     cases[i].needle;

		ret = parse_tetgen_str(cases[i].node, strlen(cases[i].node),
				       cases[i].ele, strlen(cases[i].ele), &m,
				       err, sizeof(err));
		assert_err(ret, &m, err, "t.ele", cases[i].needle);
		write_file("t.node", cases[i].node, strlen(cases[i].node));
		write_file("t.ele", cases[i].ele, strlen(cases[i].ele));
		ret = irdm_mesh_read(path, 1.0, NULL, &m, err, sizeof(err));
		assert_err(ret, &m, err, scratch, fneedle);
	}
}

static void test_tetgen_error_buffer_small(void **state)
{
	struct irdm_mesh m;
	char err[8];

	(void)state;
	memset(err, 'x', sizeof(err));
	assert_int_equal(parse_tetgen_str("", 0, "", 0, &m, err, sizeof(err)), IRDM_EFORMAT);
	assert_string_equal(err, "t.ele: ");
	assert_int_equal(parse_tetgen_str("", 0, "", 0, &m, NULL, 0), IRDM_EFORMAT);
}

/* Every prefix of a valid pair parses or fails cleanly, never overreads. */
static void test_tetgen_truncations(void **state)
{
	size_t nl = strlen(cube_node1), el = strlen(cube_ele1), k;
	struct irdm_mesh m;
	char err[256];

	(void)state;
	for (k = 0; k <= nl; k++) {
		if (parse_tetgen_str(cube_node1, k, cube_ele1, el, &m, err, sizeof(err)))
			assert_int_equal(strncmp(err, "t.ele: ", 7), 0);
		irdm_mesh_free(&m);
	}
	for (k = 0; k <= el; k++) {
		int ret = parse_tetgen_str(cube_node1, nl, cube_ele1, k, &m, err,
					   sizeof(err));

		/* only the complete file (or all but its last newline) is valid */
		assert_int_equal(ret, k >= el - 1 ? IRDM_OK : IRDM_EFORMAT);
		irdm_mesh_free(&m);
	}
}

/* ---- Gmsh ------------------------------------------------------------- */

static void test_gmsh_files_agree(void **state)
{
	static const char *const files[] = {
		DATA "cube6_v22.msh",
		DATA "cube6_v41.msh",
	};
	struct irdm_mesh m[2];
	char err[256];
	size_t i;

	(void)state;
	for (i = 0; i < 2; i++) {
		if (irdm_mesh_read(files[i], 1.0, NULL, &m[i], err, sizeof(err)))
			fail_msg("%s", err);
		/* the extra node (tag 7), used by a point only, is dropped */
		assert_int_equal(m[i].n_nodes, 8);
		assert_int_equal(m[i].n_tets, 6);
		assert_int_equal(m[i].n_tris, 12);
		assert_true(fabs(irdm_mesh_volume(&m[i]) - 1.0) < 1e-15);
		assert_closed_outward(&m[i], 1.0);
		assert_box_boundary(&m[i], (const double[3]){ 1, 1, 1 });
	}
	assert_string_equal(m[0].name, "cube6_v22");
	assert_true(irdm_mesh_hash(&m[0]) == irdm_mesh_hash(&m[1]));
	irdm_mesh_free(&m[0]);
	irdm_mesh_free(&m[1]);
}

static const char gmsh22_tet[] =
	"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
	"$Nodes\n4\n10 0 0 0\n20 1 0 0\n30 0 1 0\n40 0 0 1\n$EndNodes\n"
	"$Elements\n2\n1 2 2 0 1 10 20 30\n7 4 2 0 1 10 20 30 40\n$EndElements\n";

static void test_gmsh_errors(void **state)
{
	/* In memory elements and nodes are 1-based positions; files use tags. */
	static const struct {
		const char *txt, *needle, *file_needle;
	} cases[] = {
		{ "$MeshFormat\n4.1 1 8\n$EndMeshFormat\n",
		  "binary Gmsh files are not supported", NULL },
		{ "$MeshFormat\n2.2 1 8\n$EndMeshFormat\n\x01\0\0\0\n",
		  "binary Gmsh files are not supported", NULL },
		{ "$MeshFormat\n4.0 0 8\n$EndMeshFormat\n", "format 4 is not supported", NULL },
		{ "$MeshFormat\n3 0 8\n$EndMeshFormat\n", "format 3 is not supported", NULL },
		{ "$NOD\n1\n1 0 0 0\n$ENDNOD\n", "no $MeshFormat", NULL },
		{ "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
		  "$Nodes\n4\n10 0 0 0\n20 1 0 0\n30 0 1 0\n40 0 0 1\n$EndNodes\n"
		  "$Elements\n1\n7 4 2 0 1 10 30 20 40\n$EndElements\n",
		  "t.msh: element 1 is inverted", "t.msh: element 7 is inverted" },
		{ "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
		  "$Nodes\n4\n10 0 0 0\n20 1 0 0\n30 0 1 0\n40 0 0 1\n$EndNodes\n"
		  "$Elements\n1\n7 4 2 0 1 10 20 30 41\n$EndElements\n",
		  "element 7 refers to undefined node 41", NULL },
		{ "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
		  "$Nodes\n4\n10 0 0 0\n20 1 0 0\n30 nan 1 0\n40 0 0 1\n$EndNodes\n"
		  "$Elements\n1\n7 4 2 0 1 10 20 30 40\n$EndElements\n",
		  "node 3 has a non-finite coordinate", "node 30 has a non-finite coordinate" },
		{ "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
		  "$Nodes\n4\n10 0 0 0\n10 1 0 0\n30 0 1 0\n40 0 0 1\n$EndNodes\n"
		  "$Elements\n1\n7 4 2 0 1 10 20 30 40\n$EndElements\n",
		  "node tag 10 is defined twice", NULL },
		{ "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
		  "$Nodes\n3\n10 0 0 0\n20 1 0 0\n30 0 1 0\n$EndNodes\n"
		  "$Elements\n1\n1 2 2 0 1 10 20 30\n$EndElements\n",
		  "no tetrahedra", NULL },
		{ "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n10 0 0 0\n",
		  "truncated inside $Nodes", NULL },
		{ "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n0\n",
		  "missing $EndNodes", NULL },
		{ "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n0\n$EndNodes\n",
		  "missing $Elements", NULL },
		{ "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n0\n$EndNodes\n$Nodes\n",
		  "second $Nodes", NULL },
		{ "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n99999999\n",
		  "too large for this file", NULL },
		{ "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Comments\nhello\n",
		  "unterminated section", NULL },
		{ "$MeshFormat\n2.2 0 8\n$EndMeshFormat\nhello\n", "found 'hello'", NULL },
		{ "$MeshFormat\n2.2 0 8\n$Nodes\n", "expected $EndMeshFormat", NULL },
		{ "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1 2\n0 1 0 3\n1\n2\n"
		  "0 0 0\n0 0 0\n$EndNodes\n",
		  "node block size 3 is too large", NULL },
		{ "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1 2\n0 1 0 1\n1\n"
		  "0 0 0\n$EndNodes\n",
		  "declares 2 nodes but its blocks hold 1", NULL },
		{ "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n0 0 0 0\n$EndNodes\n"
		  "$Elements\n1 2 1 2\n3 1 4 3\n",
		  "element block size 3 is too large", NULL },
		{ "", "missing $MeshFormat", NULL },
		{ "\xff\xfe\x00garbage", "expected a $Section, found '???garbage'", NULL },
	};
	struct irdm_mesh m;
	char err[256], path[128];
	size_t i;

	(void)state;
	scratch_path(path, sizeof(path), "t.msh");
	for (i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		const char *fneedle = cases[i].file_needle ? cases[i].file_needle :
							     cases[i].needle;
		size_t len = strlen(cases[i].txt);
		int ret;

		if (i == 1) /* embedded NULs */
			len = 40;
		if (i == sizeof(cases) / sizeof(cases[0]) - 1)
			len = 10;
		ret = parse_gmsh_str(cases[i].txt, len, &m, err, sizeof(err));
		assert_err(ret, &m, err, "t.msh", cases[i].needle);
		write_file("t.msh", cases[i].txt, len);
		ret = irdm_mesh_read(path, 1.0, NULL, &m, err, sizeof(err));
		assert_err(ret, &m, err, path, fneedle);
	}
}

static void test_gmsh_truncations(void **state)
{
	size_t n = strlen(gmsh22_tet), k;
	struct irdm_mesh m;
	char err[256];

	(void)state;
	for (k = 0; k <= n; k++) {
		int ret = parse_gmsh_str(gmsh22_tet, k, &m, err, sizeof(err));

		assert_int_equal(ret, k >= n - 1 ? IRDM_OK : IRDM_EFORMAT);
		if (ret)
			assert_int_equal(strncmp(err, "t.msh: ", 7), 0);
		else
			assert_true(fabs(irdm_mesh_volume(&m) - 1.0 / 6.0) < 1e-15);
		irdm_mesh_free(&m);
	}
}

/* ---- irdm_mesh_read ---------------------------------------------------- */

static void test_read_tetgen_files(void **state)
{
	struct irdm_mesh a, b;
	char err[256];

	(void)state;
	assert_int_equal(irdm_mesh_read(DATA "cube5.node", 1.0, NULL, &a, err,
					sizeof(err)),
			 0);
	assert_int_equal(irdm_mesh_read(DATA "cube5.ele", 0.001, NULL, &b, err,
					sizeof(err)),
			 0);
	assert_string_equal(a.name, "cube5");
	assert_int_equal(a.n_tets, 5);
	assert_true(fabs(irdm_mesh_volume(&a) - 1.0) < 1e-15);
	assert_true(fabs(irdm_mesh_volume(&b) - 1e-9) < 1e-9 * 1e-12);
	assert_memory_equal(a.tets, b.tets, 20 * sizeof(uint32_t));
	assert_closed_outward(&b, 0.001);
	irdm_mesh_free(&a);
	irdm_mesh_free(&b);
}

static void test_read_errors(void **state)
{
	struct irdm_mesh m;
	char err[256];

	(void)state;
	assert_int_equal(irdm_mesh_read(DATA "missing.node", 1.0, NULL, &m, err, sizeof(err)),
			 IRDM_EIO);
	assert_err(irdm_mesh_read(DATA "missing.node", 1.0, NULL, &m, err,
				  sizeof(err)),
		   &m, err, DATA "missing.node",
		   "cannot open");
	assert_int_equal(irdm_mesh_read(DATA "cube5.vtk", 1.0, NULL, &m, err, sizeof(err)),
			 IRDM_EFORMAT);
	assert_err(irdm_mesh_read(DATA "cube5.vtk", 1.0, NULL, &m, err,
				  sizeof(err)),
		   &m, err, DATA "cube5.vtk",
		   "unknown mesh format");
	assert_err(irdm_mesh_read(DATA "cube5.ele", 0.0, NULL, &m, err,
				  sizeof(err)),
		   &m, err, DATA "cube5.ele",
		   "not a positive number");
	assert_err(irdm_mesh_read(DATA "cube5.ele", NAN, NULL, &m, err,
				  sizeof(err)),
		   &m, err, DATA "cube5.ele",
		   "not a positive number");
	assert_err(irdm_mesh_read("tests/data/mesh", 1.0, NULL, &m, err,
				  sizeof(err)),
		   &m, err, "tests/data/mesh",
		   "unknown mesh format");
}

/* ---- finish on hand-built meshes --------------------------------------- */

static void test_finish_direct(void **state)
{
	struct irdm_mesh m;
	char err[256];

	(void)state;
	memset(&m, 0, sizeof(m));
	assert_err(irdm_mesh_finish(&m, "mem", err, sizeof(err)), &m, err, "mem",
		   "mesh is empty");

	/* an index past the node array: not reachable through the parsers */
	m.n_nodes = 4;
	m.pos_m = calloc(12, sizeof(double));
	m.n_tets = 1;
	m.tets = calloc(4, sizeof(uint32_t));
	assert_non_null(m.pos_m);
	assert_non_null(m.tets);
	m.pos_m[3] = m.pos_m[7] = m.pos_m[11] = 1.0;
	m.tets[0] = 0;
	m.tets[1] = 1;
	m.tets[2] = 2;
	m.tets[3] = 4;
	assert_err(irdm_mesh_finish(&m, "mem", err, sizeof(err)), &m, err, "mem",
		   "element 1 refers to node index 4, but there are only 4 nodes");
}

/* Large mesh: the boundary pass must stay O(n log n). */
static void test_finish_large(void **state)
{
	struct irdm_mesh m;
	char err[256];

	(void)state;
	assert_int_equal(irdm_mesh_gen_box(1, 1, 1, 30, 30, 30, 6, &m, err,
					   sizeof(err)),
			 0);
	assert_int_equal(m.n_tets, 162000);
	assert_int_equal(m.n_tris, 4 * 3 * 900);
	assert_closed_outward(&m, 1.0);
	irdm_mesh_free(&m);
}

/*
 * Mesh statistics: a regular tetrahedron has quality 1 and its volume
 * a^3 / (6 sqrt 2); a Kuhn box (6 equal tets a hex) spans no volume ratio;
 * a box 1000 times too large, and one graded by a tiny tet, are warned of.
 */
static void test_mesh_stats(void **state)
{
	const double a = 0.03;
	double pos[12] = { 0, 0, 0, a, 0, 0, a / 2, a * sqrt(3) / 2, 0,
			   a / 2, a * sqrt(3) / 6, a * sqrt(2.0 / 3.0) };
	uint32_t tet[4] = { 0, 1, 2, 3 };
	struct irdm_mesh m = { .n_nodes = 4, .pos_m = pos, .n_tets = 1, .tets = tet };
	struct irdm_mesh_stats st;
	char lines[3][256], err[256];

	(void)state;
	irdm_mesh_stats(&m, &st);
	assert_true(fabs(st.quality_min - 1) < 1e-12 && fabs(st.quality_max - 1) < 1e-12);
	assert_true(fabs(st.vol_min_m3 - a * a * a / (6 * sqrt(2))) < 1e-12 * a * a * a);
	assert_int_equal(irdm_mesh_stats_text(&m, &st, lines), 1);
	assert_non_null(strstr(lines[0], "mesh stats: 4 nodes, 1 tets, 0.03 m across"));

	assert_int_equal(irdm_mesh_gen_box(0.1, 0.1, 0.2, 2, 2, 4, 6, &m, err, sizeof(err)), 0);
	irdm_mesh_stats(&m, &st);
	assert_true(fabs(st.vol_max_m3 / st.vol_min_m3 - 1) < 1e-12);
	assert_true(fabs(st.vol_min_m3 - 0.05 * 0.05 * 0.05 / 6) < 1e-15);
	assert_int_equal(irdm_mesh_stats_text(&m, &st, lines), 1);
	for (size_t i = 0; i < 3 * m.n_nodes; i++)
		m.pos_m[i] *= 1000; /* drawn in mm, read as m */
	irdm_mesh_stats(&m, &st);
	assert_int_equal(irdm_mesh_stats_text(&m, &st, lines), 2);
	assert_non_null(strstr(lines[1], "warning: the object is 200 m across: is mesh_scale right?"));
	irdm_mesh_free(&m);
	/* the regular tet beside one 1000 times smaller in size: graded */
	{
		double p2[24];
		uint32_t t2[8] = { 0, 1, 2, 3, 4, 5, 6, 7 };
		struct irdm_mesh g = { .n_nodes = 8, .pos_m = p2, .n_tets = 2, .tets = t2 };

		for (int i = 0; i < 12; i++) {
			p2[i] = pos[i];
			p2[12 + i] = pos[i] * 1e-3 + (i % 3 == 0 ? 0.05 : 0);
		}
		irdm_mesh_stats(&g, &st);
		assert_true(fabs(st.vol_max_m3 / st.vol_min_m3 / 1e9 - 1) < 1e-9);
		assert_int_equal(irdm_mesh_stats_text(&g, &st, lines), 2);
		assert_non_null(strstr(lines[1], "warning: tet volumes span a factor 1e+09"));
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_box_paper_cuboid),
		cmocka_unit_test(test_box_cubes),
		cmocka_unit_test(test_box_bad_args),
		cmocka_unit_test(test_mesh_stats),
		cmocka_unit_test(test_hash),
		cmocka_unit_test(test_tetgen_cube),
		cmocka_unit_test(test_tetgen_ten_node),
		cmocka_unit_test(test_tetgen_real_output_orientation),
		cmocka_unit_test(test_tetgen_errors),
		cmocka_unit_test(test_tetgen_error_buffer_small),
		cmocka_unit_test(test_tetgen_truncations),
		cmocka_unit_test(test_gmsh_files_agree),
		cmocka_unit_test(test_gmsh_errors),
		cmocka_unit_test(test_gmsh_truncations),
		cmocka_unit_test(test_read_tetgen_files),
		cmocka_unit_test(test_read_errors),
		cmocka_unit_test(test_finish_direct),
		cmocka_unit_test(test_finish_large),
	};

	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
