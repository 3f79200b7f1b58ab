/* SPDX-License-Identifier: MIT */
/*
 * Sizing a surface's tetrahedralisation on two surfaces built
 * here: a CAD-like part (binary STL in mm: a 60 x 40 x 16 box with 0.5 mm
 * fillets, 972 triangles), whose fillets tetgen's quality bound refines
 * around (-pq1.414: about 36,000 nodes), and a box whose top face has a
 * vertex 0.05 mm from an edge.  With target_nodes, or the default target,
 * the node count lands within the stated factor 2 of the target; explicit
 * tetgen switches win, with a note; bad values are refused naming the key.
 * Needs Debian's tetgen.
 */
#include <math.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "mesh/mesh.h"
#include "precompute/model.h"
#include "scene/scene.h"
#include "support/cad_part.h"
#include "support/test_files.h"

#define FACTOR 2.0 /* the sizing's promise: target / 2 .. target * 2 */

static char dir[64], off_path[128], stl_path[128];

/* The box, its top face a fan around P, 0.05 from the edge y = 60. */
static int write_notched_box(const char *path)
{
	static const double v[9][3] = {
		{ 0, 0, 0 },
		{ 100, 0, 0 },
		{ 100, 60, 0 },
		{ 0, 60, 0 },
		{ 0, 0, 20 },
		{ 100, 0, 20 },
		{ 100, 60, 20 },
		{ 0, 60, 20 },
		{ 50, 59.95, 20 },
	};
	static const int t[14][3] = {
		{ 0, 2, 1 },
		{ 0, 3, 2 }, /* bottom */
		{ 4, 5, 8 },
		{ 5, 6, 8 },
		{ 6, 7, 8 },
		{ 7, 4, 8 }, /* top, fan around P */
		{ 0, 1, 5 },
		{ 0, 5, 4 },
		{ 1, 2, 6 },
		{ 1, 6, 5 },
		{ 2, 3, 7 },
		{ 2, 7, 6 },
		{ 3, 0, 4 },
		{ 3, 4, 7 },
	};
	FILE *f = fopen(path, "w");

	if (!f)
		return -1;
	fprintf(f, "OFF\n9 14 0\n");
	for (int i = 0; i < 9; i++)
		fprintf(f, "%g %g %g\n", v[i][0], v[i][1], v[i][2]);
	for (int i = 0; i < 14; i++)
		fprintf(f, "3 %d %d %d\n", t[i][0], t[i][1], t[i][2]);
	return fclose(f);
}

static void set(struct irdm_scene *sc, const char *k, const char *v)
{
	char err[256];

	assert_int_equal(irdm_scene_set(sc, k, v, "test", err, sizeof(err)), 0);
}

/* The scene's mesh: node count and the sizing's note. */
static size_t scene_nodes(struct irdm_scene *sc, char note[256])
{
	struct irdm_mesh m;
	char err[512];

	int ret = irdm_model_mesh(sc, &m, note, err, sizeof(err));
	if (ret)
		print_message("%s\n", err);
	assert_int_equal(ret, 0);
	size_t n = m.n_nodes;
	irdm_mesh_free(&m);
	print_message("%zu nodes; %s\n", n, note);
	return n;
}

/* The old default for the record, then the default target and two more. */
static void check_targets(const char *path, unsigned low_target)
{
	struct irdm_scene sc;
	char note[256], err[512];
	struct irdm_mesh m;

	assert_int_equal(irdm_mesh_read(path, 0.001, "pq1.414", &m, err, sizeof(err)), 0);
	size_t old = m.n_nodes;
	irdm_mesh_free(&m);
	irdm_scene_defaults(&sc);
	set(&sc, "mesh", path);
	set(&sc, "mesh_scale", "0.001");
	size_t n_default = scene_nodes(&sc, note);
	print_message("-pq1.414: %zu nodes; default sizing: %zu (target %u)\n", old, n_default,
		      IRDM_SCENE_TARGET_NODES);
	assert_true(n_default >= IRDM_SCENE_TARGET_NODES / FACTOR &&
		    n_default <= IRDM_SCENE_TARGET_NODES * FACTOR);
	assert_non_null(strstr(note, "target_nodes 3000"));
	const unsigned targets[2] = { low_target, 8000 };
	for (int k = 0; k < 2; k++) {
		unsigned target = targets[k];
		char v[16];
		snprintf(v, sizeof(v), "%u", target);
		set(&sc, "target_nodes", v);
		size_t n = scene_nodes(&sc, note);
		assert_true(n >= target / FACTOR && n <= target * FACTOR);
	}
}

static void test_target_nodes_part(void **state)
{
	(void)state;
	check_targets(stl_path, 2000);
}

static void test_target_nodes_notch(void **state)
{
	(void)state;
	check_targets(off_path, 1000);
}

static void test_max_tet_volume(void **state)
{
	struct irdm_scene sc;
	char note[256];

	(void)state;
	irdm_scene_defaults(&sc);
	set(&sc, "mesh", off_path);
	set(&sc, "mesh_scale", "0.001");
	set(&sc, "max_tet_volume", "1e-7"); /* 100 mm^3 in the file's units */
	scene_nodes(&sc, note);
	assert_non_null(strstr(note, "max_tet_volume"));
	assert_non_null(strstr(note, "a100,"));
}

static void test_tetgen_overrides(void **state)
{
	struct irdm_scene sc;
	char note[256];

	(void)state;
	irdm_scene_defaults(&sc);
	set(&sc, "mesh", off_path);
	set(&sc, "mesh_scale", "0.001");
	set(&sc, "target_nodes", "5000");
	set(&sc, "tetgen", "p");
	size_t n = scene_nodes(&sc, note);
	assert_true(n == 9); /* -p adds no point to a box */
	assert_non_null(strstr(note, "overrides target_nodes"));
	irdm_scene_defaults(&sc);
	set(&sc, "mesh", off_path);
	set(&sc, "tetgen", "p");
	scene_nodes(&sc, note);
	assert_string_equal(note, ""); /* nothing to override: no note */
}

static void test_bad_values(void **state)
{
	static const char *const bad[][2] = {
		{ "target_nodes", "0" },
		{ "target_nodes", "99" },
		{ "target_nodes", "3k" },
		{ "target_nodes", "-5" },
		{ "max_tet_volume", "0" },
		{ "max_tet_volume", "-1e-6" },
		{ "max_tet_volume", "nan" },
		{ "max_tet_volume", "big" },
	};
	struct irdm_scene sc;
	char err[256];

	(void)state;
	irdm_scene_defaults(&sc);
	for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
		err[0] = '\0';
		assert_int_not_equal(irdm_scene_set(&sc, bad[i][0], bad[i][1], "s.scene:3", err,
						    sizeof(err)),
				     0);
		print_message("%s = %s: %s\n", bad[i][0], bad[i][1], err);
		assert_non_null(strstr(err, bad[i][0]));
		assert_null(strchr(err, '\n'));
	}
}

static int setup(void **state)
{
	(void)state;
	if (tf_tmpdir(dir, sizeof(dir), "sizing"))
		return -1;
	snprintf(off_path, sizeof(off_path), "%s/notch.off", dir);
	snprintf(stl_path, sizeof(stl_path), "%s/part.stl", dir);
	return write_notched_box(off_path) || cad_part_write_stl(stl_path, "irdm test part: 60 x 40 x 16 mm, 0.5 mm fillets") ? -1 : 0;
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_target_nodes_part),
		cmocka_unit_test(test_target_nodes_notch),
		cmocka_unit_test(test_max_tet_volume),
		cmocka_unit_test(test_tetgen_overrides),
		cmocka_unit_test(test_bad_values),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
