/* SPDX-License-Identifier: MIT */
/*
 * The argument-principle modal certificate (stability_modal.c)
 * against the dense eigenvalues of the 2K closed-loop matrix
 * (irdm_stability_modal) on every column of small images: grounded cuboid
 * and floating cube, all modes and truncated, with and without static
 * correction, f64 and f32 storage.  Same verdicts; the bracket [rho_lo,
 * rho] (rho by a winding number, rho_lo by one or a Newton root) holds the
 * dense radius (to the dense solver's own rounding) and is at most 1e-8
 * wide.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cmocka.h>

#include "irdm/image.h"
#include "irdm/posix/image_map.h"
#include "modal/modal.h"
#include "modal/stability.h"
#include "support/engine_fixture.h"
#include "support/stab_cert.h"
#include "support/test_files.h"

static char dir[64];

static double now_s(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void compare_all_columns(const char *what, const char *path, ...)
{
	struct irdm_image img;
	va_list ap;
	const char *kv[16];
	int n = 0;

	va_start(ap, path);
	while (n < 15 && (kv[n] = va_arg(ap, const char *)) != NULL)
		n++;
	va_end(ap);
	kv[n] = NULL;
	efx_image(&img, path, kv[0], kv[1], kv[2], kv[3], kv[4], kv[5], kv[6], kv[7], kv[8], kv[9],
		  kv[10], kv[11], kv[12], kv[13], kv[14], NULL);
	size_t K = img.meta->n_modes, nc = img.meta->n_cols;
	double *phi = malloc(3 * K * sizeof(double)), D[9], worst_hi = 0, worst_lo = 0, t_dense = 0,
	       t_cert = 0, max_rho = 0, worst_stored = 0;
	unsigned circles = 0, unstable = 0;
	assert_non_null(phi);
	for (size_t c = 0; c < nc; c++) {
		const double *d = efx_column_modal(&img, c, phi, D);
		struct irdm_stab_cert cert;
		double t0 = now_s();
		double dense = irdm_stability_modal(img.modes, K, phi, d);
		double t1 = now_s();
		assert_int_equal(irdm_stability_modal_cert(img.modes, K, phi, d, &cert), 0);
		t_dense += t1 - t0;
		t_cert += now_s() - t1;
		dense = stab_cert_check(what, c, dense, &cert);
		/* the precompute's radius (its f64 data, the diagonal block with
		 * the far field) against this one from the image's numbers */
		worst_stored = fmax(worst_stored,
				    fabs((double)img.stability[c].spectral_radius - dense) / dense);
		worst_hi = fmax(worst_hi, cert.rho / dense - 1);
		worst_lo = fmax(worst_lo, fabs(1 - cert.rho_lo / dense));
		max_rho = fmax(max_rho, dense);
		unstable += dense >= 1;
		circles += cert.circles;
	}
	/* the stored float's rounding: 3.2e-8 measured, limit 1e-7 */
	assert_true(worst_stored <= 1e-7);
	print_message("%-34s K %4zu, %3zu columns (%u unstable), max radius %.9f: rho/dense - 1 <= %.1e, "
		      "|1 - rho_lo/dense| <= %.1e, stored %.1e; %.1f circles/column; dense %.3f s, certificate %.3f s\n",
		      what, K, nc, unstable, max_rho, worst_hi, worst_lo, worst_stored,
		      (double)circles / (double)nc, t_dense, t_cert);
	free(phi);
	irdm_image_unmap(&img);
}

static void test_grounded_cuboid(void **state)
{
	char p[128];

	(void)state;
	snprintf(p, sizeof(p), "%s/g1.img", dir);
	compare_all_columns("grounded, all modes, f64", p, "resolution", "3,3,6", "representation",
			    "modal:all", "precision", "f64", "touch", "z>=0.15", NULL);
	compare_all_columns("grounded, 30 modes + static, f32", p, "resolution", "3,3,6",
			    "representation", "modal:30", "static_correction", "yes", "precision", "f32",
			    "touch", "z>=0.15", NULL);
	compare_all_columns("grounded, 30 modes, no static, f64", p, "resolution", "3,3,6",
			    "representation", "modal:30", "static_correction", "no", "precision", "f64",
			    "touch", "z>=0.15", NULL);
	/* 2 ms: the paper's rate, radii closer to 1 */
	compare_all_columns("grounded, all modes, 2 ms", p, "resolution", "3,3,6", "dt", "0.002",
			    "representation", "modal:all", "precision", "f64", "touch", "z>=0.15", NULL);
}

static void test_floating_cube(void **state)
{
	char p[128];

	(void)state;
	snprintf(p, sizeof(p), "%s/f1.img", dir);
	compare_all_columns("floating, all modes, f64", p, "mesh", "cube", "resolution", "3,3,3",
			    "floating", "yes", "representation", "modal:all", "precision", "f64", "touch",
			    "surface", NULL);
	compare_all_columns("floating, 20 modes + static, f32", p, "mesh", "cube", "resolution", "3,3,3",
			    "floating", "yes", "representation", "modal:20", "static_correction", "yes",
			    "precision", "f32", "touch", "surface", NULL);
}

/*
 * A mode the node barely sees (phi 1e-1 .. 1e-4 of the others) and the
 * least damped: its closed-loop pole sits just beside its open-loop pole,
 * and the circle that certifies the radius passes between the two.  The
 * winding number must resolve that pair (the walk's pole rule); skipping
 * it counts poles outside that are not there.  Synthetic modes, 1 ms.
 */
static void test_mode_the_node_barely_sees(void **state)
{
	enum { K = 40 };
	struct irdm_mode zoh[K];
	double phi[3 * K];

	(void)state;
	for (int scale = 1; scale <= 4; scale++) {
		for (int k = 0; k < K; k++) {
			/* 2 .. 80 Hz, the first mode least damped */
			irdm_zoh_mode(2 * M_PI * 2.0 * (k + 1), k == 0 ? 0.002 : 0.02, 1e-3, &zoh[k]);
			for (int i = 0; i < 3; i++)
				phi[i * K + k] = cos(1.0 + 0.7 * k * (i + 1) + i) / (k + 1) * (k == 0 ? pow(10, -scale) : 1);
		}
		struct irdm_stab_cert cert;
		double dense = irdm_stability_modal(zoh, K, phi, NULL);
		assert_int_equal(irdm_stability_modal_cert(zoh, K, phi, NULL, &cert), 0);
		print_message("phi scale 1e-%d: dense %.12f, certificate [%.12f, %.12f]\n", scale, dense,
			      cert.rho_lo, cert.rho);
		assert_true(cert.rho >= dense * (1 - STAB_DENSE_TOL) && cert.rho <= dense * (1 + STAB_CERT_WIDTH));
	}
}

static int setup(void **state)
{
	(void)state;
	return tf_tmpdir(dir, sizeof(dir), "stabm");
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_grounded_cuboid),
		cmocka_unit_test(test_floating_cube),
		cmocka_unit_test(test_mode_the_node_barely_sees),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
