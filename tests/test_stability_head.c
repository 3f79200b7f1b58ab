/* SPDX-License-Identifier: MIT */
/*
 * The hybrid representation: the modal certificate with an exact
 * FIR head of H samples (irdm_stability_modal_cert_head) against the dense
 * eigenvalues of the explicit 2K + 3(H-1) closed-loop matrix
 * (irdm_stability_modal_head), with the tolerances of the modal
 * certificate's own test (support/stab_cert.h).  Heads of 1, 2, 5, 20 (and
 * 40) samples, the exact response of the modes the image drops, on a
 * grounded cuboid's columns and on random small systems, plus heads that a
 * scaled R0 in D_1 or D_{H-1} destabilises.  A head that cuts slow modes
 * short is itself unstable (10 of 288 cuboid modes kept: every H from 2 to
 * 20); the stable realistic cases keep the slow modes and put the fast,
 * damped ones in the head, and those approach the full modal model's
 * radius.  Also: a head alone against the FIR companion matrix, the head
 * terms of H(z) and H'(z) against a direct sum, and H = 1 against the
 * plain certificate bit for bit.
 */
#include <complex.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "irdm/image.h"
#include "irdm/posix/image_map.h"
#include "modal/modal.h"
#include "modal/node_tf.h"
#include "modal/stability.h"
#include "support/engine_fixture.h"
#include "support/stab_cert.h"
#include "support/test_files.h"

#define MAX_HEAD 40
static const size_t head_lengths[] = { 1, 2, 5, 20 };
#define N_LENGTHS (sizeof(head_lengths) / sizeof(head_lengths[0]))

/* H(z), H'(z) of the head against the direct sum: rounding of ~H terms of
 * size up to 2^H |D_s| (|z| >= 1/2); measured below 1e-15, margin 100 */
#define EVAL_TOL 1e-13

static char dir[64];
/* a grounded cuboid, every mode (288), 1 ms, default Rayleigh damping:
 * built once by setup() */
static struct irdm_image img;

/* deterministic uniform in [lo, hi) */
static double uniform(uint64_t *s, double lo, double hi)
{
	*s = *s * 6364136223846793005ull + 1442695040888963407ull;
	return lo + (hi - lo) * (double)(*s >> 11) * 0x1p-53;
}

/* the first K columns of a 3 x n_all shape matrix, 3 x K */
static void kept_shapes(const double *phi, size_t n_all, size_t K, double *phi_c)
{
	for (int i = 0; i < 3; i++)
		memcpy(&phi_c[(size_t)i * K], &phi[(size_t)i * n_all], K * sizeof(double));
}

/* alpha R0 added to D_s: the ring's own recursion f[t] ~ -alpha f[t-s]
 * puts closed-loop poles near |alpha|^(1/s) */
static void add_scaled_r0(const struct irdm_mode *zoh, const double *phi_c, size_t K, double *head,
			  size_t s, double alpha)
{
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) {
			double r0 = head[3 * i + j];
			for (size_t k = 0; k < K; k++)
				r0 += phi_c[(size_t)i * K + k] * phi_c[(size_t)j * K + k] * zoh[k].b[0];
			head[9 * s + 3 * (size_t)i + (size_t)j] += alpha * r0;
		}
}

struct tally {
	unsigned cases, unstable;
	double worst_hi, worst_lo, max_rho;
};

/* a certificate against its reference radius, counted */
static void tally_add(const char *what, struct tally *t, double dense,
		      const struct irdm_stab_cert *cert)
{
	dense = stab_cert_check(what, t->cases, dense, cert);
	t->worst_hi = fmax(t->worst_hi, cert->rho / dense - 1);
	if (cert->rho_lo > 0)
		t->worst_lo = fmax(t->worst_lo, fabs(1 - cert->rho_lo / dense));
	t->max_rho = fmax(t->max_rho, dense);
	t->unstable += dense >= 1;
	t->cases++;
}

/* one case: certificate against the dense reference */
static void check_case(const char *what, struct tally *t, const struct irdm_mode *zoh, size_t K,
		       const double *phi_c, const double *head, size_t n_head)
{
	struct irdm_stab_cert cert;
	double dense = irdm_stability_modal_head(zoh, K, phi_c, head, n_head);

	assert_int_equal(irdm_stability_modal_cert_head(zoh, K, phi_c, head, n_head, &cert), 0);
	assert_true(irdm_stability_modal_ap_head(zoh, K, phi_c, head, n_head) == cert.rho);
	tally_add(what, t, dense, &cert);
}

/*
 * Every head length on one node, K of n_all modes kept and the others in
 * the head: their exact response, and for H > 1 the same with alpha R0
 * added to D_1 and to D_{H-1} (0.7: stable for D_1; +-1.3: a pole
 * outside).
 */
static void node_cases(const char *what, struct tally *t, const struct irdm_mode *zoh,
		       const double *phi, size_t n_all, size_t K)
{
	static const double alpha[] = { 0.7, -1.3, 1.3 };
	double *phi_c = malloc(3 * K * sizeof(double)), head[9 * MAX_HEAD];

	assert_non_null(phi_c);
	kept_shapes(phi, n_all, K, phi_c);
	for (size_t l = 0; l < N_LENGTHS; l++) {
		size_t H = head_lengths[l];
		stab_dropped_head(zoh, phi, n_all, K, n_all, H, head);
		check_case(what, t, zoh, K, phi_c, head, H);
		for (size_t a = 0; H > 1 && a < sizeof(alpha) / sizeof(alpha[0]); a++)
			for (size_t s = 1; s<H; s += H - 1> 1 ? H - 2 : 1) {
				stab_dropped_head(zoh, phi, n_all, K, n_all, H, head);
				add_scaled_r0(zoh, phi_c, K, head, s, alpha[a]);
				check_case(what, t, zoh, K, phi_c, head, H);
			}
	}
	free(phi_c);
}

static void report(const char *what, const struct tally *t)
{
	print_message("%-28s %u cases (%u unstable), max radius %.9f: rho/dense - 1 <= %.1e, "
		      "|1 - rho_lo/dense| <= %.1e\n",
		      what, t->cases, t->unstable, t->max_rho, t->worst_hi, t->worst_lo);
}

/*
 * 10 modes kept, the other 278 in the head, every 4th column.  A head this
 * short truncates the slow dropped modes long before they decay: the
 * exact heads of 2 .. 20 samples are unstable here, H = 1 is not.
 */
static void test_cuboid_short_heads(void **state)
{
	struct tally t = { 0 };

	(void)state;
	size_t n_all = img.meta->n_modes;
	double *phi = malloc(3 * n_all * sizeof(double)), D[9];
	assert_non_null(phi);
	for (size_t c = 0; c < img.meta->n_cols; c += 4) {
		assert_null(efx_column_modal(&img, c, phi, D));
		node_cases("cuboid, 10 kept", &t, img.modes, phi, n_all, 10);
	}
	report("cuboid, 10 kept", &t);
	assert_true(t.unstable > 0 && t.unstable < t.cases);
	free(phi);
}

/*
 * The realistic hybrid: the slow modes kept (KEEP_SLOW of 288), the fast
 * ones, which decay within tens of samples, in the head.  Against the
 * dense reference (up to 2 KEEP_SLOW + 117 states) and, for the longest
 * head, against the full modal model's dense radius, which the hybrid
 * approaches as the head grows (the head's truncation: measured 2e-9 at
 * 40 samples, 0.5 % at 20).
 */
#define KEEP_SLOW 250
#define FULL_TOL 2e-8 /* measured 2.5e-9 over the columns, margin 8 */
static void test_cuboid_fast_modes_in_head(void **state)
{
	static const size_t lengths[] = { 1, 5, 20, MAX_HEAD };
	struct tally t = { 0 };
	double worst_full = 0, head[9 * MAX_HEAD], D[9];

	(void)state;
	size_t n_all = img.meta->n_modes;
	double *phi = malloc(3 * n_all * sizeof(double)), *phi_c = malloc(3 * KEEP_SLOW * sizeof(double));
	assert_true(phi && phi_c);
	for (size_t c = 0; c < img.meta->n_cols; c += 14) {
		assert_null(efx_column_modal(&img, c, phi, D));
		kept_shapes(phi, n_all, KEEP_SLOW, phi_c);
		for (size_t l = 0; l < sizeof(lengths) / sizeof(lengths[0]); l++) {
			stab_dropped_head(img.modes, phi, n_all, KEEP_SLOW, n_all, lengths[l], head);
			check_case("cuboid, 250 kept", &t, img.modes, KEEP_SLOW, phi_c, head, lengths[l]);
		}
		double full = irdm_stability_modal(img.modes, n_all, phi, NULL);
		double hybrid = irdm_stability_modal_ap_head(img.modes, KEEP_SLOW, phi_c, head, MAX_HEAD);
		worst_full = fmax(worst_full, fabs(hybrid / full - 1));
	}
	report("cuboid, 250 kept", &t);
	print_message("head of %d: |rho / rho of all 288 modes - 1| <= %.1e\n", MAX_HEAD, worst_full);
	assert_true(worst_full < FULL_TOL);
	assert_true(t.unstable > 0 && t.unstable < t.cases);
	free(phi);
	free(phi_c);
}

/*
 * Random shapes and modes, 1 ms: the first K slow (1 .. 300 Hz, zeta 0.2 %
 * .. 10 %), the others fast and damped as a stiffness-proportional
 * damping makes them (0.5 .. 5 kHz, zeta 0.2 .. 1.5, overdamped ones too).
 */
static void random_system(uint64_t *seed, size_t n_all, size_t K, struct irdm_mode *zoh,
			  double *phi)
{
	for (size_t k = 0; k < n_all; k++) {
		if (k < K)
			irdm_zoh_mode(2 * M_PI * uniform(seed, 1, 300), uniform(seed, 0.002, 0.1), 1e-3,
				      &zoh[k]);
		else
			irdm_zoh_mode(2 * M_PI * uniform(seed, 500, 5000), uniform(seed, 0.2, 1.5), 1e-3,
				      &zoh[k]);
		for (int i = 0; i < 3; i++)
			phi[(size_t)i * n_all + k] = uniform(seed, -1, 1) / sqrt((double)k + 1);
	}
}

static void test_random_heads(void **state)
{
	enum { N_SYSTEMS = 12,
	       MAX_ALL = 30 };
	struct irdm_mode zoh[MAX_ALL];
	double phi[3 * MAX_ALL];
	struct tally t = { 0 };
	uint64_t seed = 20261124;

	(void)state;
	for (int n = 0; n < N_SYSTEMS; n++) {
		size_t K = 2 + (size_t)uniform(&seed, 0, 10), n_all = K + 3 + (size_t)uniform(&seed, 0, 15);
		random_system(&seed, n_all, K, zoh, phi);
		node_cases("random", &t, zoh, phi, n_all, K);
	}
	report("random systems", &t);
	assert_true(t.unstable > 0 && t.unstable < t.cases);
}

/*
 * No kept mode at all: the head is a plain FIR image, and the certificate
 * must agree with the FIR reference, the eigenvalues of the 3(H-1) block
 * companion matrix (irdm_stability_fir_companion), as the modal dense
 * reference at K = 0 must.  Unstable FIR heads have more closed-loop poles
 * outside than the 2K = 0 modes could account for.
 */
static void test_head_alone_is_an_fir(void **state)
{
	enum { N_SYSTEMS = 6,
	       MAX_ALL = 20 };
	struct irdm_mode zoh[MAX_ALL];
	double phi[3 * MAX_ALL], head[9 * MAX_HEAD];
	struct tally t = { 0 };
	uint64_t seed = 99;

	(void)state;
	for (int n = 0; n < N_SYSTEMS; n++) {
		size_t n_all = 3 + (size_t)uniform(&seed, 0, MAX_ALL - 3);
		random_system(&seed, n_all, n % 2 ? 0 : n_all, zoh, phi);
		for (size_t l = 1; l < N_LENGTHS; l++) {
			size_t H = head_lengths[l];
			struct irdm_stab_cert cert;
			stab_dropped_head(zoh, phi, n_all, 0, n_all, H, head);
			double fir = irdm_stability_fir_companion(head, H);
			assert_int_equal(irdm_stability_modal_cert_head(zoh, 0, NULL, head, H, &cert), 0);
			assert_true(fabs(irdm_stability_modal_head(zoh, 0, NULL, head, H) - fir) <= STAB_DENSE_TOL * fir);
			tally_add("head alone", &t, fir, &cert);
		}
	}
	report("head alone (FIR companion)", &t);
	assert_true(t.unstable > 0 && t.unstable < t.cases);
}

/*
 * The head terms of H(z) and H'(z) (node_tf.c's Horner in 1/z) against the
 * direct sums D_s z^-s and -s D_s z^(-s-1) over the same modes without a
 * head, on circles 0.5 .. 2; the head's pole at 0 in the pole distance.
 * A non-symmetric head: every entry counts.
 */
static void test_head_terms(void **state)
{
	enum { K = 5,
	       N_HEAD = 9 };
	struct irdm_mode zoh[K];
	struct irdm_node_tf plain, hybrid;
	double phi[3 * K], head[9 * N_HEAD];
	uint64_t seed = 7;

	(void)state;
	random_system(&seed, K, K, zoh, phi);
	for (size_t e = 0; e < 9 * N_HEAD; e++)
		head[e] = uniform(&seed, -1, 1) * 1e-3;
	assert_int_equal(irdm_node_tf_init(&plain, zoh, K, phi, head), 0);
	assert_int_equal(irdm_node_tf_init_head(&hybrid, zoh, K, phi, head, N_HEAD), 0);
	double worst = 0;
	for (int i = 0; i < 64; i++) {
		double complex z = uniform(&seed, 0.5, 2) * cexp(I * uniform(&seed, -M_PI, M_PI));
		double complex H0[9], dH0[9], H[9], dH[9];
		double d0, d;
		irdm_node_tf_eval(&plain, z, H0, dH0, &d0);
		irdm_node_tf_eval(&hybrid, z, H, dH, &d);
		for (int e = 0; e < 9; e++) {
			double complex sum = 0, dsum = 0, scale = 0;
			for (int s = 1; s < N_HEAD; s++) {
				sum += head[9 * s + e] * cpow(z, -s);
				dsum += -s * head[9 * s + e] * cpow(z, -s - 1);
				scale += fabs(head[9 * s + e]) * (s + 1) * pow(cabs(z), -s - 1);
			}
			double err = fmax(cabs(H[e] - (H0[e] + sum)), cabs(dH[e] - (dH0[e] + dsum)));
			worst = fmax(worst, err / creal(scale));
		}
		assert_true(d == fmin(d0, cabs(z)));
	}
	print_message("head terms against the direct sum: worst %.1e of the terms' size\n", worst);
	assert_true(worst < EVAL_TOL);
	irdm_node_tf_free(&plain);
	irdm_node_tf_free(&hybrid);
}

/*
 * H = 1 is today's certificate with D = head[0], bit for bit (the dense
 * reference too), and zero blocks appended to the head change H(z) and
 * H'(z) by nothing at all.
 */
static void test_one_sample_head(void **state)
{
	enum { K = 8,
	       N_PAD = 4 };
	struct irdm_mode zoh[K];
	struct irdm_node_tf one, padded;
	double phi[3 * K], head[9 * N_PAD] = { 0 };
	uint64_t seed = 11;

	(void)state;
	for (int n = 0; n < 8; n++) {
		random_system(&seed, K, K, zoh, phi);
		for (int e = 0; e < 9; e++)
			head[e] = uniform(&seed, -1, 1) * 1e-4;
		struct irdm_stab_cert a, b;
		assert_int_equal(irdm_stability_modal_cert(zoh, K, phi, head, &a), 0);
		assert_int_equal(irdm_stability_modal_cert_head(zoh, K, phi, head, 1, &b), 0);
		assert_memory_equal(&a, &b, sizeof(a));
		assert_int_equal(irdm_stability_modal_cert(zoh, K, phi, NULL, &a), 0);
		assert_int_equal(irdm_stability_modal_cert_head(zoh, K, phi, NULL, 0, &b), 0);
		assert_memory_equal(&a, &b, sizeof(a));
		double d1 = irdm_stability_modal(zoh, K, phi, head);
		double d2 = irdm_stability_modal_head(zoh, K, phi, head, 1);
		assert_memory_equal(&d1, &d2, sizeof(d1));
		assert_int_equal(irdm_node_tf_init_head(&one, zoh, K, phi, head, 1), 0);
		assert_int_equal(irdm_node_tf_init_head(&padded, zoh, K, phi, head, N_PAD), 0);
		double complex z = 0.9 * cexp(I * uniform(&seed, 0, M_PI)), H1[9], dH1[9], Hp[9], dHp[9];
		double p1, pp;
		irdm_node_tf_eval(&one, z, H1, dH1, &p1);
		irdm_node_tf_eval(&padded, z, Hp, dHp, &pp);
		assert_memory_equal(H1, Hp, sizeof(H1));
		assert_memory_equal(dH1, dHp, sizeof(dH1));
		irdm_node_tf_free(&one);
		irdm_node_tf_free(&padded);
	}
}

static int setup(void **state)
{
	char p[128];

	(void)state;
	if (tf_tmpdir(dir, sizeof(dir), "stabh"))
		return -1;
	snprintf(p, sizeof(p), "%s/g.img", dir);
	efx_image(&img, p, "resolution", "3,3,6", "representation", "modal:all", "precision", "f64",
		  "touch", "z>=0.15", NULL);
	return img.meta->n_modes == 288 ? 0 : -1;
}

static int teardown(void **state)
{
	(void)state;
	irdm_image_unmap(&img);
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_head_terms),
		cmocka_unit_test(test_one_sample_head),
		cmocka_unit_test(test_cuboid_short_heads),
		cmocka_unit_test(test_cuboid_fast_modes_in_head),
		cmocka_unit_test(test_random_heads),
		cmocka_unit_test(test_head_alone_is_an_fir),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
