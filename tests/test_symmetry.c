/* SPDX-License-Identifier: MIT */
/*
 * The symmetric split of the every-mode eigensolve, end to end: the soft
 * 4 x 4 x 8 cuboid (E 2e3 Pa, nu 0.4999, rho 2e4 kg/m^3, 2 ms; its mesh
 * has the x and the y mirror, tools/modal/symmetry.h) precomputed
 * with symmetry = yes and with symmetry = no (the whole solve, which
 * test_modal holds to K, M and Lanczos).  Every mode, and the hybrid auto
 * chooses at max_error 1e-3 (303 modes and a 32-sample head): the two
 * images' responses agree at every touchable column and every row of the
 * displayed surface (the rows off the touchable face made whole after the
 * solve) to the f32 they are stored in, and so do their measured errors.  (test_modal compares the solvers' eigenpairs
 * themselves.)
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "image/image_response.h"
#include "irdm/posix/image_map.h"
#include "precompute/precompute.h"
#include "scene/scene.h"
#include "support/model_fixture.h"
#include "support/test_files.h"

#define SAMPLES 200

static char dir[64];

static void build(const char *name, const char *const *keys, bool symmetry,
		  struct irdm_precompute_report *rep, struct irdm_image *img)
{
	struct irdm_scene sc;
	struct irdm_precompute_opts o = { 0 };
	char path[128], err[768] = "";

	fixture_soft_scene(&sc, keys);
	sc.symmetry = symmetry;
	snprintf(path, sizeof(path), "%s/%s", dir, name);
	o.out_path = path;
	if (irdm_precompute(&sc, &o, rep, err, sizeof(err)))
		fail_msg("%s: %s", name, err);
	assert_int_equal(irdm_image_map(path, 0, img, err, sizeof(err)), 0);
}

/* max |R_a - R_b| over every column, row and sample, and max |R_a|. */
static void compare(const struct irdm_image *a, const struct irdm_image *b, double *diff,
		    double *peak)
{
	double *ra = malloc(9 * SAMPLES * sizeof(double)), *rb = malloc(9 * SAMPLES * sizeof(double));

	*diff = *peak = 0;
	assert_int_equal(a->meta->n_cols, b->meta->n_cols);
	assert_int_equal(a->meta->n_nodes, b->meta->n_nodes);
	for (uint32_t c = 0; c < a->meta->n_cols; c++)
		for (uint32_t r = 0; r < a->meta->n_nodes; r++) {
			assert_int_equal(irdm_image_response(a, c, r, SAMPLES, ra), 0);
			assert_int_equal(irdm_image_response(b, c, r, SAMPLES, rb), 0);
			for (size_t i = 0; i < 9 * SAMPLES; i++) {
				*diff = fmax(*diff, fabs(ra[i] - rb[i]));
				*peak = fmax(*peak, fabs(ra[i]));
			}
		}
	free(ra);
	free(rb);
}

/* err_tol: how far the measured errors may differ, relative (negative:
 * both within -err_tol, rounding of f32) */
static void same_images(const char *what, const char *const *keys, double tol, double err_tol)
{
	struct irdm_precompute_report ra, rb;
	struct irdm_image a, b;
	char na[64], nb[64];
	double diff, peak;

	snprintf(na, sizeof(na), "%s-split.img", what);
	snprintf(nb, sizeof(nb), "%s-whole.img", what);
	build(na, keys, true, &ra, &a);
	build(nb, keys, false, &rb, &b);
	compare(&a, &b, &diff, &peak);
	print_message("%s: responses within %.2g of their peak %.3g; measured errors %.6g and %.6g; eigensolve in %u blocks\n",
		      what, diff / peak, peak, ra.measured_error, rb.measured_error, ra.eig_blocks);
	assert_true(ra.eig_blocks > 1);
	assert_int_equal(rb.eig_blocks, 1);
	assert_true(diff <= tol * peak);
	if (err_tol < 0)
		assert_true(ra.measured_error <= -err_tol && rb.measured_error <= -err_tol);
	else
		assert_true(fabs(ra.measured_error - rb.measured_error) <= err_tol * rb.measured_error);
	irdm_image_unmap(&a);
	irdm_image_unmap(&b);
}

static void test_every_mode(void **state)
{
	static const char *const keys[] = { "representation", "modal:all", "display", "surface", NULL };

	(void)state;
	same_images("modal-all", keys, 1e-7, -1e-6);
}

static void test_hybrid(void **state)
{
	static const char *const keys[] = { "representation", "modal:303", "exact_head", "32",
					    "static_correction", "yes", "display", "surface", NULL };

	(void)state;
	same_images("hybrid", keys, 1e-7, 1e-4);
}

static int setup(void **state)
{
	(void)state;
	return tf_tmpdir(dir, sizeof(dir), "symmetry");
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_every_mode),
		cmocka_unit_test(test_hybrid),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
