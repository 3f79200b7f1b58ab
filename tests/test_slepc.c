/* SPDX-License-Identifier: MIT */
/*
 * eigensolver = slepc: the precompute over MPI ranks gives the image the
 * serial solvers give, and a failure on any rank stops them all.
 *
 * The reference is an independent method: the same scene through ARPACK
 * (shift-invert Lanczos on a CHOLMOD factor) or LAPACK (dense), serially.
 * The provenance names the eigensolver, so the images are compared by
 * content: eigenvalues (relative), responses R[s] of every column at every
 * row (relative to max |R|: invariant under an eigenvector's sign), the
 * static correction and the stability verdicts.  Each scene avoids
 * degenerate modes at the truncation (a non-square box), where the kept
 * subspace, and so the responses, would not be unique.
 *
 * Run with mpirun -np 2 (MPIRUN, default /usr/bin/mpirun) and as a
 * singleton (no mpirun).  A build without PETSc/SLEPc (no irdm-slepc.so)
 * checks the option says it is not built in.
 */
#include <limits.h>
#include <math.h>
#include <stdbool.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "dist/dist.h"
#include "image/image_response.h"
#include "irdm/image.h"
#include "irdm/posix/image_map.h"
#include "support/run_prog.h"
#include "support/test_files.h"

/* Measured: eigenvalues within 3e-13 relative, responses within 2e-12 of
 * max |R| (np = 2, 1); the bounds are 1e-9 and 1e-8. */
#define EIG_REL_TOL 1e-9
#define RESP_REL_TOL 1e-8
/* a run's bound (s): a rank that hangs fails the test, not the suite */
#define RUN_TIMEOUT_S "120"
/* samples of R compared (the modal responses are exact at any s) */
#define N_SAMPLES 64

static char dir[256];
static char out_text[65536], err_text[65536];

static const char *irdm_path(void)
{
	const char *p = getenv("IRDM");

	return p ? p : "build/irdm";
}

static const char *mpirun_path(void)
{
	const char *p = getenv("MPIRUN");

	return p ? p : "/usr/bin/mpirun";
}

/*
 * The sanitizer build: irdm checks for leaks before MPI_Finalize, the MPI
 * libraries' own suppressed (tools/dist/dist.c says why); harmless in the
 * other builds.  Only for the MPI runs: the serial references keep the
 * usual check at exit.
 */
static void mpi_leak_options(bool on)
{
	static char opts[PATH_MAX + 128];
	char supp[PATH_MAX];

	if (!on) {
		unsetenv("LSAN_OPTIONS");
		return;
	}
	assert_non_null(realpath("tests/lsan-mpi.supp", supp));
	snprintf(opts, sizeof(opts), "suppressions=%s:leak_check_at_exit=0:print_suppressions=0",
		 supp);
	setenv("LSAN_OPTIONS", opts, 1);
}

static int setup(void **state)
{
	(void)state;
	return tf_tmpdir(dir, sizeof(dir), "slepc");
}

static int teardown(void **state)
{
	(void)state;
	unsetenv("IRDM_TEST_FAULT");
	unsetenv("OMPI_MCA_orte_tmpdir_base");
	mpi_leak_options(false);
	return tf_rmdir(dir);
}

/* The scenes: args for irdm precompute, NULL-terminated. */
#define GROUNDED "--mesh", "box:0.04,0.05,0.08", "--resolution", "3,3,5", "--fixed", "z<=0", \
		 "--touch", "z>=0.08", "--precision", "f64", "--representation", "modal:20"
#define FLOATING "--mesh", "box:0.04,0.05,0.07", "--resolution", "3,3,4", "--floating", "yes", \
		 "--fixed", "none", "--touch", "z>=0.07", "--precision", "f64", "--representation", "modal:24"
#define FIR "--mesh", "box:0.03,0.04,0.06", "--resolution", "2,3,4", "--fixed", "z<=0", \
	    "--touch", "z>=0.06", "--precision", "f64", "--representation", "fir:48", "--modes", "30", \
	    "--uncertified", "yes", "--fir_tail", "none"

#define TIME_DOMAIN "--mesh", "box:0.03,0.04,0.06", "--resolution", "2,3,4", "--fixed", "z<=0", \
		    "--touch", "z>=0.06", "--precision", "f64", "--representation", "fir:32", "--uncertified", "yes", "--fir_tail", "none", \
		    "--method", "time-domain", "--substeps", "4"

/*
 * Each run its own Open MPI session directory: a singleton's daemon
 * removes the shared one (/tmp/ompi.HOST.UID) as it exits, which can
 * pull it from under the next run's mpirun ("A call to mkdir was unable
 * to create the desired directory"), more often the busier the machine.
 */
static void own_session_dir(void)
{
	static unsigned runs;
	static char base[300];

	snprintf(base, sizeof(base), "%s/ompi.%u", dir, runs++);
	assert_int_equal(mkdir(base, 0700), 0);
	setenv("OMPI_MCA_orte_tmpdir_base", base, 1);
}

/* irdm precompute ARGS... -o OUT, under mpirun -np np (np 0: no mpirun). */
static int precompute(int np, const char *out, const char *const *scene)
{
	const char *args[40];
	char nps[16];
	int n = 0;

	own_session_dir();
	snprintf(nps, sizeof(nps), "%d", np);
	/* a rank left waiting for one that failed would hang: bounded */
	args[n++] = "-k";
	args[n++] = "5";
	args[n++] = RUN_TIMEOUT_S;
	if (np) {
		args[n++] = mpirun_path();
		args[n++] = "--allow-run-as-root";
		args[n++] = "--oversubscribe";
		args[n++] = "-np";
		args[n++] = nps;
	}
	args[n++] = irdm_path();
	args[n++] = "precompute";
	args[n++] = "-q";
	args[n++] = "--max_error";
	args[n++] = "none";
	for (; *scene; scene++)
		args[n++] = *scene;
	args[n++] = "-o";
	args[n++] = out;
	args[n] = NULL;
	return rp_run(dir, "/usr/bin/timeout", args, out_text,
		      sizeof(out_text), err_text, sizeof(err_text));
}

static void map(const char *name, struct irdm_image *img)
{
	char path[300], err[512];

	snprintf(path, sizeof(path), "%s/%s", dir, name);
	if (irdm_image_map(path, 0, img, err, sizeof(err)))
		fail_msg("%s", err);
}

static double max_abs_response(const struct irdm_image *img, double *buf)
{
	double m = 0;

	for (uint32_t c = 0; c < img->meta->n_cols; c++)
		for (uint32_t r = 0; r < img->meta->n_nodes; r++) {
			assert_int_equal(irdm_image_response(img, c, r, N_SAMPLES, buf), 0);
			for (size_t i = 0; i < 9 * N_SAMPLES; i++)
				m = fmax(m, fabs(buf[i]));
		}
	return m;
}

/* The worst |R_a - R_b| over every column, row and sample, / max |R_a|. */
static double response_difference(const struct irdm_image *a, const struct irdm_image *b)
{
	double *ra = malloc(9 * N_SAMPLES * sizeof(double));
	double *rb = malloc(9 * N_SAMPLES * sizeof(double));
	double worst = 0, scale;

	assert_non_null(ra);
	assert_non_null(rb);
	scale = max_abs_response(a, ra);
	assert_true(scale > 0);
	for (uint32_t c = 0; c < a->meta->n_cols; c++)
		for (uint32_t r = 0; r < a->meta->n_nodes; r++) {
			assert_int_equal(irdm_image_response(a, c, r, N_SAMPLES, ra), 0);
			assert_int_equal(irdm_image_response(b, c, r, N_SAMPLES, rb), 0);
			for (size_t i = 0; i < 9 * N_SAMPLES; i++)
				worst = fmax(worst, fabs(ra[i] - rb[i]));
		}
	free(ra);
	free(rb);
	return worst / scale;
}

/* Same content: geometry, modes, responses, certificate. */
static void assert_same_content(const char *ref_name, const char *name)
{
	struct irdm_image a, b;
	double d, worst_w2 = 0;

	map(ref_name, &a);
	map(name, &b);
	assert_int_equal(a.meta->n_nodes, b.meta->n_nodes);
	assert_int_equal(a.meta->n_cols, b.meta->n_cols);
	assert_int_equal(a.meta->n_modes, b.meta->n_modes);
	assert_int_equal(a.meta->flags, b.meta->flags);
	assert_memory_equal(a.columns, b.columns, a.meta->n_cols * sizeof(uint32_t));
	assert_true(fabs(a.meta->first_elastic_hz - b.meta->first_elastic_hz) <=
		    EIG_REL_TOL * a.meta->first_elastic_hz);
	for (uint32_t k = 0; k < a.meta->n_modes; k++) {
		double wa = a.modes[k].omega_rad_s, wb = b.modes[k].omega_rad_s;
		/* omega^2 to EIG_REL_TOL relative: omega to half of it */
		if (!(fabs(wa * wa - wb * wb) <= EIG_REL_TOL * wa * wa))
			fail_msg("%s: mode %u: w^2 %.17g, serial %.17g", name, k, wb * wb, wa * wa);
		worst_w2 = fmax(worst_w2, fabs(wa * wa - wb * wb) / (wa * wa));
	}
	if (a.meta->flags & IRDM_META_FLOATING)
		assert_true(fabs(a.rigid->mass_kg - b.rigid->mass_kg) <= 1e-12 * a.rigid->mass_kg);
	d = response_difference(&a, &b);
	print_message("%s vs %s: w^2 differ by %.1e relative, responses by %.1e of max |R|\n",
		      name, ref_name, worst_w2, d);
	if (!(d <= RESP_REL_TOL))
		fail_msg("%s: responses differ from the serial image's by %.3g of max |R|", name, d);
	for (uint32_t c = 0; c < a.meta->n_cols; c++) {
		assert_int_equal(a.stability[c].flags, b.stability[c].flags);
		assert_true(fabs(a.stability[c].spectral_radius - b.stability[c].spectral_radius) <= 1e-6);
	}
	irdm_image_unmap(&a);
	irdm_image_unmap(&b);
}

/* ref with the serial solver, then slepc alone and over 2 ranks. */
static void compare_scene(const char *const *scene_ref, const char *const *scene_slepc)
{
	char ref[300], s1[300], s2[300];

	snprintf(ref, sizeof(ref), "%s/ref.img", dir);
	snprintf(s1, sizeof(s1), "%s/np1.img", dir);
	snprintf(s2, sizeof(s2), "%s/np2.img", dir);
	assert_int_equal(precompute(0, ref, scene_ref), 0);
	mpi_leak_options(true);
	if (precompute(0, s1, scene_slepc))
		fail_msg("slepc, no mpirun: %s", err_text);
	if (precompute(2, s2, scene_slepc))
		fail_msg("slepc, mpirun -np 2: %s", err_text);
	mpi_leak_options(false);
	assert_same_content("ref.img", "np1.img");
	assert_same_content("ref.img", "np2.img");
}

static void test_grounded_matches_lanczos(void **state)
{
	const char *const ref[] = { GROUNDED, "--eigensolver", "lanczos", NULL };
	const char *const sl[] = { GROUNDED, "--eigensolver", "slepc", NULL };

	(void)state;
	compare_scene(ref, sl);
}

/* Floating: the six rigid modes found and set apart as the serial path does. */
static void test_floating_matches_lanczos(void **state)
{
	const char *const ref[] = { FLOATING, "--eigensolver", "lanczos", NULL };
	const char *const sl[] = { FLOATING, "--eigensolver", "slepc", NULL };

	(void)state;
	compare_scene(ref, sl);
}

/* FIR synthesised from modes, with the static correction, against LAPACK. */
static void test_fir_matches_dense(void **state)
{
	const char *const ref[] = { FIR, "--eigensolver", "dense", NULL };
	const char *const sl[] = { FIR, "--eigensolver", "slepc", NULL };

	(void)state;
	compare_scene(ref, sl);
}

/* Time-domain inputs split over the ranks, gathered on rank 0: the serial
 * image's responses (the serial run took all 36 inputs itself). */
static void test_time_domain_split_over_ranks(void **state)
{
	const char *const ref[] = { TIME_DOMAIN, "--eigensolver", "lanczos", NULL };
	const char *const sl[] = { TIME_DOMAIN, "--eigensolver", "slepc", NULL };

	(void)state;
	compare_scene(ref, sl);
}

/* Nothing of the image is left behind: no IMAGE, no IMAGE.tmp.* */
static void assert_no_image(void)
{
	DIR *d = opendir(dir);
	struct dirent *e;

	assert_non_null(d);
	while ((e = readdir(d)))
		if (!strncmp(e->d_name, "out.img", 7))
			fail_msg("%s/%s left behind", dir, e->d_name);
	closedir(d);
}

/* IRDM_TEST_FAULT=fault on mpirun -np 2: non-zero exit, the failing rank
 * and its reason on stderr (unless it was killed), no image. */
static void fault_case(const char *fault, const char *says)
{
	const char *const sl[] = { GROUNDED, "--eigensolver", "slepc", NULL };
	char out[300];
	int rc;

	snprintf(out, sizeof(out), "%s/out.img", dir);
	setenv("IRDM_TEST_FAULT", fault, 1);
	mpi_leak_options(true);
	rc = precompute(2, out, sl);
	unsetenv("IRDM_TEST_FAULT");
	if (rc == 0)
		fail_msg("%s: exit 0", fault);
	if (says && !strstr(err_text, says))
		fail_msg("%s: stderr lacks '%s':\n%s", fault, says, err_text);
	assert_no_image();
}

static void test_rank_cannot_read_mesh(void **state)
{
	(void)state;
	fault_case("1:mesh", "rank 1 of 2: EIO: box:0.04,0.05,0.08: cannot read the mesh");
	fault_case("0:mesh", "rank 0 of 2: EIO: box:0.04,0.05,0.08: cannot read the mesh");
}

static void test_rank_out_of_memory(void **state)
{
	(void)state;
	fault_case("1:oom", "rank 1 of 2: ENOMEM: slepc: out of memory");
}

static void test_rank_killed(void **state)
{
	(void)state;
	/* mpirun reports the death itself; what matters: everyone stops */
	fault_case("1:kill", NULL);
	fault_case("0:kill", NULL);
}

/* Without mpirun a failure is the usual one-line error, no rank named. */
static void test_singleton_failure(void **state)
{
	const char *const sl[] = { GROUNDED, "--eigensolver", "slepc", NULL };
	char out[300];

	(void)state;
	snprintf(out, sizeof(out), "%s/out.img", dir);
	setenv("IRDM_TEST_FAULT", "0:oom", 1);
	mpi_leak_options(true);
	assert_int_equal(precompute(0, out, sl), 1);
	unsetenv("IRDM_TEST_FAULT");
	assert_non_null(strstr(err_text, "irdm precompute: ENOMEM: slepc: out of memory"));
	assert_null(strstr(err_text, "rank"));
	assert_no_image();
}

/* Without the plugin (a build without PETSc/SLEPc, or the plugin not
 * beside irdm): the option exists and says why it fails. */
static void test_not_built_in(void **state)
{
	const char *const sl[] = { GROUNDED, "--eigensolver", "slepc", NULL };
	char out[300];

	(void)state;
	snprintf(out, sizeof(out), "%s/out.img", dir);
	setenv("IRDM_SLEPC_PLUGIN", "/nonexistent/irdm-slepc.so", 1);
	assert_int_equal(precompute(0, out, sl), 1);
	unsetenv("IRDM_SLEPC_PLUGIN");
	if (!strstr(err_text, "irdm precompute: EINVAL: slepc: not built in ("))
		fail_msg("%s", err_text);
	assert_no_image();
}

int main(void)
{
	const struct CMUnitTest with_slepc[] = {
		cmocka_unit_test_setup_teardown(test_grounded_matches_lanczos, setup, teardown),
		cmocka_unit_test_setup_teardown(test_floating_matches_lanczos, setup, teardown),
		cmocka_unit_test_setup_teardown(test_fir_matches_dense, setup, teardown),
		cmocka_unit_test_setup_teardown(test_time_domain_split_over_ranks, setup, teardown),
		cmocka_unit_test_setup_teardown(test_rank_cannot_read_mesh, setup, teardown),
		cmocka_unit_test_setup_teardown(test_rank_out_of_memory, setup, teardown),
		cmocka_unit_test_setup_teardown(test_rank_killed, setup, teardown),
		cmocka_unit_test_setup_teardown(test_singleton_failure, setup, teardown),
		cmocka_unit_test_setup_teardown(test_not_built_in, setup, teardown),
	};
	const struct CMUnitTest without[] = {
		cmocka_unit_test_setup_teardown(test_not_built_in, setup, teardown),
	};

	if (!irdm_dist_built_in())
		return cmocka_run_group_tests(without, NULL, NULL);
	return cmocka_run_group_tests(with_slepc, NULL, NULL);
}
