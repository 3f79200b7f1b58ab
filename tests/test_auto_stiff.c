/* SPDX-License-Identifier: MIT */
/*
 * representation = auto on a stiff material (E 2e9 Pa, nu 0.3, rho 1000
 * kg/m^3: first mode 525 Hz) on the paper cuboid at 4 x 4 x 8 hexes (600
 * elastic modes), 1 ms, top face touchable.  Its stiffness-damped modes
 * die within a tick or two, so the cheapest hybrid within max_error =
 * 1e-3 has a head of a sample or two, not the 16 or more a soft object
 * needs:
 *  - auto writes a hybrid whose head is at most 2 samples long (H = 1),
 *    certified, its measured error within max_error and recorded in the
 *    image;
 *  - measured again against an exact model precomputed on its own (every
 *    mode, f64), the error is the one recorded;
 *  - the same modes with a 16-sample head (the shortest auto once tried)
 *    hold a head 16 times larger, for an error (2.6e-8) far below what
 *    the target asks;
 *  - with static_correction_cluster set, auto tries no hybrid (its head
 *    needs the dropped-block correction) and keeps the cluster in the
 *    truncated candidate it writes: 300 modes and the clustered static
 *    correction, within max_error.
 */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "accuracy/measure.h"
#include "irdm/posix/image_map.h"
#include "irdm/precision.h"
#include "precompute/precompute.h"
#include "scene/scene.h"
#include "support/model_fixture.h"
#include "support/test_files.h"

static char dir[64];

static const char *const stiff[] = { "young", "2e9", "poisson", "0.3", "density", "1000", "dt",
				     "0.001", NULL };

/* The stiff scene with keys on top. */
static void stiff_scene(struct irdm_scene *sc, const char *const *keys)
{
	char err[256];

	fixture_soft_scene(sc, stiff);
	for (const char *const *kv = keys; kv && *kv; kv += 2)
		assert_int_equal(irdm_scene_set(sc, kv[0], kv[1], "test", err, sizeof(err)), 0);
}

static int build(const char *name, struct irdm_precompute_report *rep, const char *const *keys)
{
	struct irdm_scene sc;
	struct irdm_precompute_opts o = { 0 };
	char path[128], err[768] = "";
	int ret;

	stiff_scene(&sc, keys);
	snprintf(path, sizeof(path), "%s/%s", dir, name);
	o.out_path = path;
	ret = irdm_precompute(&sc, &o, rep, err, sizeof(err));
	if (ret)
		print_message("%s: %s\n", name, err);
	return ret;
}

static void map(const char *name, struct irdm_image *img)
{
	char path[128], err[256];

	snprintf(path, sizeof(path), "%s/%s", dir, name);
	assert_int_equal(irdm_image_map(path, 0, img, err, sizeof(err)), 0);
}

/* The head's stored values: blocks x samples x 9. */
static size_t head_values(const struct irdm_image *img)
{
	return (size_t)img->corr_start[img->meta->n_cols] * img->meta->head_samples * 9;
}

static void test_short_head(void **state)
{
	struct irdm_precompute_report rep;
	struct irdm_image img, h16;
	struct irdm_scene sc;
	struct irdm_measure res;
	char err[256], ref[128], modes[32];
	double measured;

	(void)state;
	assert_int_equal(build("auto.img", &rep, (const char *const[]){ NULL }), 0);
	print_message("auto: %s, measured %.3g\n", rep.representation, rep.measured_error);
	assert_true(rep.error_measured);
	assert_true(rep.measured_error <= 1e-3);
	assert_int_equal(rep.unstable_cols, 0);
	map("auto.img", &img);
	assert_true(img.meta->head_samples >= 1 && img.meta->head_samples <= 2);
	assert_true(img.meta->n_modes < 600);
	assert_true(img.meta->flags & IRDM_META_ERROR_MEASURED);
	measured = img.meta->measured_error;
	assert_float_equal(measured, rep.measured_error, 1e-6 * measured);

	snprintf(ref, sizeof(ref), "%s/exact.img", dir);
	stiff_scene(&sc, NULL);
	assert_int_equal(irdm_measure_error(&sc, &img, ref, fixture_exact_by_precompute, NULL, NULL, NULL,
					    &res, err, sizeof(err)),
			 0);
	print_message("measured again against its own exact model: %.3g\n", res.error);
	assert_float_equal(res.error, measured, 0.01 * measured + 1e-9);

	snprintf(modes, sizeof(modes), "modal:%u", img.meta->n_modes);
	assert_int_equal(build("h16.img", &rep,
			       (const char *const[]){ "representation", modes, "static_correction",
						      "yes", "exact_head", "16", NULL }),
			 0);
	map("h16.img", &h16);
	print_message("%s + exact_head 16: measured %.3g, head %zu values (auto's: %zu)\n", modes,
		      rep.measured_error, head_values(&h16), head_values(&img));
	assert_true(head_values(&h16) >= 16 * head_values(&img));
	irdm_image_unmap(&h16);
	irdm_image_unmap(&img);
}

static void test_cluster_kept(void **state)
{
	struct irdm_precompute_report rep;
	struct irdm_image img;

	(void)state;
	assert_int_equal(build("cluster.img", &rep,
			       (const char *const[]){ "static_correction_cluster", "16", NULL }),
			 0);
	print_message("auto with static_correction_cluster = 16: %s, measured %.3g\n",
		      rep.representation, rep.measured_error);
	assert_true(rep.error_measured && rep.measured_error <= 1e-3);
	map("cluster.img", &img);
	assert_int_equal(img.meta->n_modes, 300);
	assert_int_equal(img.meta->head_samples, 0);
	assert_non_null(img.corr_clusters);
	irdm_image_unmap(&img);
}

static int setup(void **state)
{
	(void)state;
	return tf_tmpdir(dir, sizeof(dir), "auto-stiff");
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_short_head),
		cmocka_unit_test(test_cluster_kept),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
