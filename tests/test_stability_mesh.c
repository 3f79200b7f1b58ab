/* SPDX-License-Identifier: MIT */
/*
 * Degenerate and sliver elements.  The unit cube as 5 tets
 * (tests/test_mesh.c), scaled to 10 cm, with its top corner node moved onto
 * the plane of its three neighbours (x + y + z = 2: the corner tet is
 * flat) or just off it (a sliver of relative volume 3e-4).  Flat: the
 * precompute refuses with one line naming the element ("zero volume").
 * Sliver: accepted,
 * and a push on the sliver's node stays bounded and passive and holds the
 * static force of the summed responses.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "precompute/precompute.h"
#include "support/stab_harness.h"
#include "support/test_files.h"

static void write_cube(const char *stem, double corner)
{
	char path[256], text[512];

	snprintf(text, sizeof(text),
		 "8 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 1 1 0\n5 0 0 1\n6 1 0 1\n7 0 1 1\n"
		 "8 %.17g %.17g %.17g\n",
		 corner, corner, corner);
	snprintf(path, sizeof(path), "%s.node", stem);
	tf_write_text(path, text);
	snprintf(path, sizeof(path), "%s.ele", stem);
	tf_write_text(path, "5 4 0\n1 1 4 7 6\n2 2 1 6 4\n3 3 4 7 1\n4 5 6 1 7\n5 8 7 4 6\n");
}

static void test_flat_tet_refused(void **state)
{
	struct irdm_scene sc;
	struct irdm_precompute_opts o;
	struct irdm_precompute_report rep;
	char stem[128], mesh[160], out[160], err[1024];

	(void)state;
	snprintf(stem, sizeof(stem), "%s/flat", stab_dir);
	write_cube(stem, 2.0 / 3.0);
	snprintf(mesh, sizeof(mesh), "%s.ele", stem);
	snprintf(out, sizeof(out), "%s.img", stem);
	memset(&o, 0, sizeof(o));
	o.out_path = out;
	irdm_scene_defaults(&sc);
	assert_int_equal(irdm_scene_set(&sc, "mesh", mesh, "test", err, sizeof(err)), 0);
	assert_int_equal(irdm_scene_set(&sc, "mesh_scale", "0.1", "test", err, sizeof(err)), 0);
	err[0] = 0;
	assert_int_not_equal(irdm_precompute(&sc, &o, &rep, err, sizeof(err)), 0);
	print_message("flat corner tet: %s\n", err);
	assert_null(strchr(err, '\n'));
	assert_non_null(strstr(err, "zero volume"));
	assert_non_null(strstr(err, "5"));          /* the element */
	assert_int_not_equal(access(out, F_OK), 0); /* nothing half-written */
}

static void test_sliver_stable(void **state)
{
	char stem[128], mesh[160];

	(void)state;
	snprintf(stem, sizeof(stem), "%s/sliver", stab_dir);
	write_cube(stem, 2.0 / 3.0 + 1e-4);
	snprintf(mesh, sizeof(mesh), "%s.ele", stem);
	const char *const image[] = { "mesh", mesh, "mesh_scale", "0.1", "representation", "modal:all",
				      "touch", "surface", "display", "surface", NULL };
	struct stab_case c = {
		.name = "sliver tet, 1 mm push on its node",
		.image = image,
		.at_m = { 0.2 / 3 + 1e-5, 0.2 / 3 + 1e-5, 0.2 / 3 + 1e-5 },
		.mode = IRDM_CONTACT_PUSH,
		.depth_m = { 1e-3 },
		.ticks = 5000,
		.static_rel_tol = 1e-4,
		/* measured 0.7706 N, + 10 % */
		.max_f_limit_n = 0.85,
		.energy_tol_j = 1e-12,
	};
	struct stab_record r;

	stab_run(stab_dir, &c, &r);
	stab_check(&c, &r);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_flat_tet_refused),
		cmocka_unit_test(test_sliver_stable),
	};

	return cmocka_run_group_tests(tests, stab_setup, stab_teardown);
}
