/* SPDX-License-Identifier: MIT */
/*
 * The force engine against a brute-force reference (direct double
 * convolution of responses read back from the image) on the paper's cuboid
 * (10 x 10 x 20 cm, E 2000 Pa, nu 0.49, rho 110, bottom fixed; a coarse
 * 4 x 4 x 8 mesh so the reference stays quick): step, release, two points,
 * stroking; and FIR images (f64, f32, f16) whose tail the engine damps by
 * r^s, against the same convolution with that tail.  Each tolerance is
 * about 5x the largest error measured with gcc -O2, clang and ASan builds,
 * so a regression of ten times fails (dropping the FIR's oldest tap costs
 * 1e-3).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "image/image_response.h"
#include "image/image_writer.h"
#include "replay/replay.h"
#include "support/engine_fixture.h"
#include "irdm/posix/image_map.h"

static char dir[64];
/* modal:all f64; modal:40 + static corr, f32, compressed hard enough to
 * drop blocks (so the tick meets missing ones) */
static struct irdm_image exact, trunc32;
/* modal:300 with the dropped modes' exact head (32 + 32 samples), f32,
 * compressed as trunc32 (a head at every kept block only) */
static struct irdm_image hybrid;
/* modal:40 with the clustered correction (clusters of at most 8 columns,
 * tol 1e-2, the upper half touchable), f32: every block from the clusters, dense and low-rank pairs */
static struct irdm_image clustered;
static struct irdm_image fir[3]; /* fir:200 f64, f32, f16 */
/* modal:37 + static corr, f64: a mode count that is not a whole number of
 * the recursion's groups of four (the padding modes run too) */
static struct irdm_image odd37;
static const char *const fir_prec[3] = { "f64", "f32", "f16" };

#define N_STEP 2000

/*
 * Limits, about 5x the largest relative RMS error measured (gcc -O2, clang
 * -O2, ASan -O1; 2026-11-24): modal f64 3.6e-13, modal 40 f32 5.3e-15,
 * stroke 1.7e-12, FIR 200 (f64, f32, f16) 5.6e-14, hybrid 300 + 32 f32 (step,
 * two points, stroke) 6.7e-13, 1.4e-13, 1.9e-12; FIR 200 f16 with its
 * column scales (2026-11-27) 5.3e-13 at the two triangle points: scaled,
 * the small taps that raw f16 rounded to zero are there, and this unstable
 * FIR's damped recursion amplifies the rounding of more terms.  All are
 * rounding: the engine and the reference read the same numbers from the
 * image.
 */
#define TOL_MODAL_F64 2e-12
#define TOL_MODAL_F32 3e-14
#define TOL_HYBRID 3e-12
#define TOL_STROKE 1e-11
#define TOL_FIR 3e-13
#define TOL_FIR_F16 3e-12

/* The limit of fir[k]: f16's is its own (above). */
static double fir_tol(int k)
{
	return k == 2 ? TOL_FIR_F16 : TOL_FIR;
}

static int setup(void **state)
{
	char p1[128], p2[128];

	(void)state;
	snprintf(dir, sizeof(dir), "/tmp/irdm-engine-XXXXXX");
	if (!mkdtemp(dir))
		return -1;
	snprintf(p1, sizeof(p1), "%s/exact.img", dir);
	snprintf(p2, sizeof(p2), "%s/trunc.img", dir);
	efx_image(&exact, p1, "resolution", "4,4,8", "representation", "modal:all",
		  "precision", "f64", "touch", "z>=0.2", NULL);
	efx_image(&trunc32, p2, "resolution", "4,4,8", "representation", "modal:40",
		  "precision", "f32", "touch", "z>=0.2", "static_correction_tol", "0.05", NULL);
	snprintf(p2, sizeof(p2), "%s/hybrid.img", dir);
	efx_image(&hybrid, p2, "resolution", "4,4,8", "representation", "modal:300",
		  "precision", "f32", "touch", "z>=0.2", "static_correction_tol", "0.05",
		  "exact_head", "32", NULL);
	snprintf(p2, sizeof(p2), "%s/odd37.img", dir);
	efx_image(&odd37, p2, "resolution", "4,4,8", "representation", "modal:37",
		  "precision", "f64", "touch", "z>=0.2", NULL);
	snprintf(p2, sizeof(p2), "%s/clustered.img", dir);
	efx_image(&clustered, p2, "resolution", "4,4,8", "representation", "modal:40",
		  "precision", "f32", "touch", "z>=0.1", "static_correction_tol", "1e-2",
		  "static_correction_cluster", "8", NULL);
	uint32_t n_lowrank = 0, nC = clustered.corr_clusters ? clustered.corr_clusters->n_clusters : 0;
	for (uint32_t a = 0; a < nC; a++)
		for (uint32_t b = a + 1; b < nC; b++)
			n_lowrank += irdm_image_corr_pair(&clustered, a, b)->rank != IRDM_CORR_PAIR_DENSE;
	print_message("clustered: %u clusters, %u low-rank pairs\n", nC, n_lowrank);
	if (!n_lowrank)
		return -1; /* the tick must read low-rank pairs */
	uint32_t nc = trunc32.meta->n_cols;
	print_message("modal 40: %u of %u static-correction blocks kept, far field rank %u\n",
		      trunc32.corr_start[nc], nc * nc, trunc32.corr_rank);
	if (trunc32.corr_start[nc] >= nc * nc || trunc32.corr_rank == 0)
		return -1; /* the tick must meet dropped blocks and the far field */
	for (int k = 0; k < 3; k++) {
		snprintf(p1, sizeof(p1), "%s/fir-%s.img", dir, fir_prec[k]);
		efx_image(&fir[k], p1, "resolution", "4,4,8", "representation", "fir:200", "uncertified", "yes",
			  "precision", fir_prec[k], "touch", "z>=0.2", "display", "z>=0.2", NULL);
	}
	return 0;
}

static int teardown(void **state)
{
	char cmd[128];

	(void)state;
	irdm_image_unmap(&exact);
	irdm_image_unmap(&trunc32);
	irdm_image_unmap(&hybrid);
	irdm_image_unmap(&clustered);
	irdm_image_unmap(&odd37);
	for (int k = 0; k < 3; k++)
		irdm_image_unmap(&fir[k]);
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", dir);
	return system(cmd) ? -1 : 0;
}

/*
 * Run the engine on fixed sites with cfg (its max_contacts set to m here):
 * GRAB contacts begin when their target is first finite; PUSH contacts
 * begin at tick 0, and once the engine lets one go it stays off
 * (*release_tick: the first tick it was off, or N).
 */
static void run_engine_cfg(const struct irdm_image *img, struct irdm_engine_config cfg,
			   const struct irdm_contact_site *sites, int m, size_t N,
			   const double *target, enum irdm_contact_mode mode, double *F,
			   size_t *release_tick)
{
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	bool begun[IRDM_MAX_CONTACTS] = { false };

	cfg.max_contacts = (unsigned)m;
	struct irdm_session *ses = efx_session(img, &cfg);
	struct irdm_engine *e = ses->eng;
	if (release_tick)
		*release_tick = N;
	for (size_t t = 0; t < N; t++) {
		memset(cmd, 0, sizeof(cmd));
		for (int i = 0; i < m; i++) {
			const double *u = &target[t * 3 * (size_t)m + 3 * (size_t)i];
			bool off = irdm_engine_contact(e, (unsigned)i)->mode == IRDM_CONTACT_OFF;
			if (isnan(u[0]) || (mode == IRDM_CONTACT_PUSH && begun[i] && off))
				continue;
			if (off)
				assert_int_equal(irdm_engine_contact_begin(e, (unsigned)i, &sites[i], mode), 0);
			begun[i] = true;
			cmd[i].mode = mode;
			memcpy(cmd[i].target_m, u, 3 * sizeof(double));
		}
		assert_int_equal(irdm_engine_tick(e, cmd), 0);
		for (int i = 0; i < m; i++) {
			memcpy(&F[t * 3 * (size_t)m + 3 * (size_t)i], irdm_engine_contact(e, (unsigned)i)->force_n,
			       3 * sizeof(double));
			if (release_tick && *release_tick == N && begun[i] &&
			    irdm_engine_contact(e, (unsigned)i)->mode == IRDM_CONTACT_OFF)
				*release_tick = t;
		}
	}
	irdm_session_close(ses);
}

/* Rigid coupling (displacements imposed), coupled solve, grabbed. */
static void run_engine(const struct irdm_image *img, const struct irdm_contact_site *sites, int m,
		       size_t N, const double *target, double *F)
{
	struct irdm_engine_config cfg;

	irdm_engine_config_default(&cfg);
	run_engine_cfg(img, cfg, sites, m, N, target, IRDM_CONTACT_GRAB, F, NULL);
}

static void node_site(const struct irdm_image *img, const double p[3], struct irdm_contact_site *s)
{
	struct irdm_engine_config cfg;

	irdm_engine_config_default(&cfg);
	struct irdm_session *ses = efx_session(img, &cfg);
	struct irdm_engine *e = ses->eng;
	assert_int_equal(irdm_engine_site_node(e, efx_column_row_near(img, p), s), 0);
	irdm_session_close(ses);
}

/* The surface point above p on its triangle: a site of three nodes. */
static void point_site(const struct irdm_image *img, const double p[3],
		       struct irdm_contact_site *s)
{
	struct irdm_engine_config cfg;
	double bary[3];
	uint32_t tri;

	irdm_engine_config_default(&cfg);
	struct irdm_session *ses = efx_session(img, &cfg);
	assert_int_equal(irdm_replay_locate(img, p, &tri, bary), 0);
	assert_int_equal(irdm_engine_site_point(ses->eng, tri, bary, s), 0);
	assert_int_equal(s->n_nodes, 3);
	irdm_session_close(ses);
}

/* How many distinct nodes the sites have (a node they share counts once). */
static unsigned distinct_rows(const struct irdm_contact_site *s, int m)
{
	uint32_t seen[3 * IRDM_MAX_CONTACTS];
	unsigned n = 0;

	for (int i = 0; i < m; i++)
		for (uint32_t v = 0; v < s[i].n_nodes; v++) {
			unsigned k = 0;
			while (k < n && seen[k] != s[i].row[v])
				k++;
			if (k == n)
				seen[n++] = s[i].row[v];
		}
	print_message("%d sites, %u distinct nodes\n", m, n);
	return n;
}

/* The tail weight the engine gives an FIR image (engine.h: an image whose
 * largest recorded radius is >= 1 brought to 0.999), written out again here. */
static double fir_tail_r(const struct irdm_image *img)
{
	double rho = img->meta->max_spectral_radius;

	return rho >= 0.999 ? 0.999 / rho : 1.0;
}

static void compare(const char *what, const struct irdm_image *img,
		    const struct irdm_contact_site *sites, int m, size_t N, const double *target,
		    double tol)
{
	double *F = malloc(N * 3 * (size_t)m * sizeof(double));
	double *R = malloc(N * 3 * (size_t)m * sizeof(double));
	double tail_r = img->meta->representation == IRDM_REPR_FIR ? fir_tail_r(img) : 1.0;

	run_engine(img, sites, m, N, target, F);
	efx_reference_tail(img, sites, m, N, target, tail_r, R);
	double err = efx_rel_rms(F, R, N * 3 * (size_t)m);
	print_message("%-34s relative RMS force error %.2e (limit %.0e)\n", what, err, tol);
	assert_true(err <= tol);
	free(F);
	free(R);
}

/*
 * The hybrid's head summed by the portable loop and, where the processor
 * has AVX2 + FMA, by engine_head_avx2.c: each against the reference, and
 * against each other (they must differ in the last bits: both ran).
 */
static void hybrid_paths(const struct irdm_contact_site *s, const double *u)
{
	struct irdm_engine_config cfg;
	double *Fw = malloc(N_STEP * 3 * sizeof(double)), *Fp = malloc(N_STEP * 3 * sizeof(double));
	double *R = malloc(N_STEP * 3 * sizeof(double));

	assert_non_null(Fw);
	assert_non_null(Fp);
	assert_non_null(R);
	irdm_engine_config_default(&cfg);
	run_engine_cfg(&hybrid, cfg, s, 1, N_STEP, u, IRDM_CONTACT_GRAB, Fw, NULL);
	cfg.fir_portable_sum = true;
	run_engine_cfg(&hybrid, cfg, s, 1, N_STEP, u, IRDM_CONTACT_GRAB, Fp, NULL);
	efx_reference(&hybrid, s, 1, N_STEP, u, R);
	double ew = efx_rel_rms(Fw, R, N_STEP * 3), ep = efx_rel_rms(Fp, R, N_STEP * 3);
	double apart = efx_rel_rms(Fw, Fp, N_STEP * 3);
	print_message("hybrid head sum: default %.2e, portable %.2e (limit %.0e), %.2e apart\n", ew, ep,
		      TOL_HYBRID, apart);
	assert_true(ew <= TOL_HYBRID);
	assert_true(ep <= TOL_HYBRID);
	irdm_engine_config_default(&cfg);
	struct irdm_session *ses = efx_session(&hybrid, &cfg);
	bool wide = !strcmp(irdm_engine_fir_sum_name(ses->eng), "avx2");
	irdm_session_close(ses);
	if (wide)
		assert_true(apart > 0);
	free(Fw);
	free(Fp);
	free(R);
}

/* Paper Fig. 6a: the top-centre node pushed 1 cm down and held. */
static void test_step(void **state)
{
	const double top[3] = { 0.05, 0.05, 0.2 };
	struct irdm_contact_site s;
	double *u = calloc(N_STEP * 3, sizeof(double));

	(void)state;
	for (size_t t = 0; t < N_STEP; t++)
		u[3 * t + 2] = -0.01;
	node_site(&exact, top, &s);
	compare("step, modal all modes f64", &exact, &s, 1, N_STEP, u, TOL_MODAL_F64);
	node_site(&trunc32, top, &s);
	compare("step, modal 40 + static corr f32", &trunc32, &s, 1, N_STEP, u, TOL_MODAL_F32);
	node_site(&hybrid, top, &s);
	compare("step, hybrid 300 + head 32 f32", &hybrid, &s, 1, N_STEP, u, TOL_HYBRID);
	hybrid_paths(&s, u);
	node_site(&clustered, top, &s);
	compare("step, modal 40 + clustered corr f32", &clustered, &s, 1, N_STEP, u, TOL_MODAL_F32);
	free(u);
}

/* Pushed and held, then let go: free vibration. */
static void test_release(void **state)
{
	const double top[3] = { 0.05, 0.05, 0.2 };
	struct irdm_contact_site s;
	double *u = calloc(N_STEP * 3, sizeof(double));

	(void)state;
	for (size_t t = 0; t < N_STEP; t++)
		for (int a = 0; a < 3; a++)
			u[3 * t + (size_t)a] = t < 700 ? (a == 2 ? -0.01 : 0) : NAN;
	node_site(&exact, top, &s);
	compare("release, modal f64", &exact, &s, 1, N_STEP, u, TOL_MODAL_F64);
	free(u);
}

/* Paper Fig. 6b: one point held still, a neighbouring point pushed in. */
static void test_two_points(void **state)
{
	const double a[3] = { 0.025, 0.05, 0.2 }, b[3] = { 0.075, 0.05, 0.2 };
	struct irdm_contact_site s[2];
	const size_t N = 2000;
	double *u = calloc(N * 6, sizeof(double));

	(void)state;
	for (size_t t = 0; t < N; t++)
		u[6 * t + 5] = -0.01 * fmin(1.0, (double)t / 1000.0); /* b ramps to 1 cm */
	for (int pass = 0; pass < 4; pass++) {
		static const char *const what[4] = { "two points, modal f64", "two points, modal 40 f32",
						     "two points, hybrid 300 + 32 f32",
						     "two points, modal 40 + clustered f32" };
		const struct irdm_image *img = pass == 3 ? &clustered : pass == 2 ? &hybrid :
								pass              ? &trunc32 :
										    &exact;
		node_site(img, a, &s[0]);
		node_site(img, b, &s[1]);
		compare(what[pass], img, s, 2, N, u,
			pass == 2 ? TOL_HYBRID : pass ? TOL_MODAL_F32 :
							TOL_MODAL_F64);
	}
	/* the held point's force grows as the other is pushed (the ring-down
	 * wobbles, so compare averages) */
	double *F = malloc(N * 6 * sizeof(double));
	node_site(&exact, a, &s[0]);
	node_site(&exact, b, &s[1]);
	run_engine(&exact, s, 2, N, u, F);
	double early = 0, late = 0;
	for (size_t t = 200; t < 400; t++)
		early += fabs(F[6 * t + 2]);
	for (size_t t = 1800; t < 2000; t++)
		late += fabs(F[6 * t + 2]);
	print_message("held point |Fz|: %.4f N early, %.4f N late\n", early / 200, late / 200);
	assert_true(late > 2 * early);
	free(F);
	free(u);
}

/*
 * FIR images, the paper's representation (T = 200 here, so the ring wraps
 * many times): pushed 1 cm for 0.5 s, then let go.  Every truncated FIR
 * tried on this cuboid is unstable (radius 1.009-1.021 for 5-50 %
 * damping), so the engine damps its tail by r^s; the reference convolves
 * with the same weighted tail, read back from the image independently of
 * the engine's ring.  Then two points on triangles, their nodes summed
 * several rows a pass (fir_sum.c), against the same reference.
 */
static void test_fir(void **state)
{
	const double top[3] = { 0.05, 0.05, 0.2 };
	const double pa[3] = { 0.03, 0.043, 0.2 }, pb[3] = { 0.068, 0.058, 0.2 };
	const size_t N = 900;
	struct irdm_contact_site s, tri[2];
	double *u = calloc(N * 3, sizeof(double)), *u2 = calloc(N * 6, sizeof(double));
	char what[64];

	(void)state;
	for (size_t t = 0; t < N; t++)
		for (int a = 0; a < 3; a++)
			u[3 * t + (size_t)a] = t < 500 ? (a == 2 ? -0.01 : 0) : NAN;
	for (size_t t = 0; t < N; t++)
		for (int a = 0; a < 6; a++)
			u2[6 * t + (size_t)a] = t < 500 ? (a == 2 ? -0.01 : a == 5 ? -0.006 :
										     0) :
							  NAN;
	for (int k = 0; k < 3; k++) {
		assert_int_equal(fir[k].meta->representation, IRDM_REPR_FIR);
		assert_true(fir_tail_r(&fir[k]) < 1.0); /* the damped path runs */
		node_site(&fir[k], top, &s);
		snprintf(what, sizeof(what), "step + release, FIR 200 %s", fir_prec[k]);
		compare(what, &fir[k], &s, 1, N, u, fir_tol(k));
		/* six site nodes: the history summed several rows a pass
		 * (fir_sum.c: a pass of four, then one of two) */
		point_site(&fir[k], pa, &tri[0]);
		point_site(&fir[k], pb, &tri[1]);
		assert_true(distinct_rows(tri, 2) > 4); /* more than one pass */
		snprintf(what, sizeof(what), "two triangle points, FIR 200 %s", fir_prec[k]);
		compare(what, &fir[k], tri, 2, N, u2, fir_tol(k));
	}
	free(u);
	free(u2);
}

/*
 * The FIR history sum's two paths (fir_sum.c, portable; fir_sum_avx2.c,
 * AVX2 + FMA where the processor has them) on the same runs: one node
 * (one row), a triangle point beside one of its own nodes (three rows:
 * one wide pass of three) and two triangle points (five rows: wide passes
 * of three and two; portable ones of four and one).  Each against the reference, and the two
 * against each other: they sum in different orders, so they agree to
 * rounding but not bit for bit, which shows that both ran.
 */
static void test_fir_sum_paths(void **state)
{
	const double top[3] = { 0.05, 0.05, 0.2 };
	const double pa[3] = { 0.03, 0.043, 0.2 }, pb[3] = { 0.068, 0.058, 0.2 };
	const size_t N = 700;
	bool wide;
	double *u = calloc(N * 6, sizeof(double));
	double *F[2] = { malloc(N * 6 * sizeof(double)), malloc(N * 6 * sizeof(double)) };
	double *R = malloc(N * 6 * sizeof(double));
	struct irdm_contact_site s[2];
	struct irdm_engine_config cfg;

	(void)state;
	irdm_engine_config_default(&cfg);
	struct irdm_session *ses = efx_session(&fir[0], &cfg);
	wide = !strcmp(irdm_engine_fir_sum_name(ses->eng), "avx2");
	print_message("FIR history sum by default on this processor: %s\n",
		      irdm_engine_fir_sum_name(ses->eng));
	irdm_session_close(ses);
	cfg.fir_portable_sum = true;
	ses = efx_session(&fir[0], &cfg);
	assert_string_equal(irdm_engine_fir_sum_name(ses->eng), "portable");
	irdm_session_close(ses);
	for (size_t t = 0; t < N; t++)
		for (int a = 0; a < 6; a++)
			u[6 * t + (size_t)a] = t < 400 ? (a == 2 ? -0.01 : a == 5 ? -0.006 :
										    0) :
							 NAN;
	for (int k = 0; k < 3; k++) {
		for (int layout = 0; layout < 3; layout++) {
			int m = layout ? 2 : 1;
			if (layout == 0)
				node_site(&fir[k], top, &s[0]);
			else
				point_site(&fir[k], pa, &s[0]);
			if (layout == 1)
				node_site(&fir[k], top, &s[1]);
			else if (layout == 2)
				point_site(&fir[k], pb, &s[1]);
			double *um = u;
			double *u1 = NULL;
			if (m == 1) {
				u1 = malloc(N * 3 * sizeof(double));
				for (size_t t = 0; t < N; t++)
					memcpy(&u1[3 * t], &u[6 * t], 3 * sizeof(double));
				um = u1;
			}
			size_t n = N * 3 * (size_t)m;
			efx_reference_tail(&fir[k], s, m, N, um, fir_tail_r(&fir[k]), R);
			for (int portable = 0; portable < 2; portable++) {
				irdm_engine_config_default(&cfg);
				cfg.fir_portable_sum = portable;
				run_engine_cfg(&fir[k], cfg, s, m, N, um, IRDM_CONTACT_GRAB, F[portable],
					       NULL);
				double err = efx_rel_rms(F[portable], R, n);
				print_message("FIR 200 %s, %d row(s), %-8s sum: error %.2e (limit %.0e)\n",
					      fir_prec[k], distinct_rows(s, m), portable ? "portable" : "wide",
					      err, fir_tol(k));
				assert_true(err <= fir_tol(k));
			}
			double diff = efx_rel_rms(F[0], F[1], n);
			print_message("  wide vs portable: %.2e\n", diff);
			assert_true(diff <= TOL_FIR);
			if (wide)
				assert_true(memcmp(F[0], F[1], n * sizeof(double)) != 0);
			free(u1);
		}
	}
	free(u);
	free(F[0]);
	free(F[1]);
	free(R);
}

/*
 * The engine in a non-default mode against efx_reference_opts (the same
 * mode written from its physics); returns the error, prints it.
 */
static double compare_mode(const char *what, struct irdm_engine_config cfg,
			   const struct irdm_contact_site *sites, int m, size_t N,
			   const double *target, enum irdm_contact_mode mode,
			   const struct efx_ref_opts *o, double *F, double *R, size_t *rel)
{
	run_engine_cfg(&exact, cfg, sites, m, N, target, mode, F, rel);
	efx_reference_opts(&exact, sites, m, N, target, o, R);
	double err = efx_rel_rms(F, R, N * 3 * (size_t)m);
	print_message("%-34s relative RMS force error %.2e\n", what, err);
	return err;
}

/* Fig. 6b's two points with the paper's per-vertex solve (eq. 10-11). */
static void test_per_vertex(void **state)
{
	const double a[3] = { 0.025, 0.05, 0.2 }, b[3] = { 0.075, 0.05, 0.2 };
	const size_t N = 1200;
	struct irdm_contact_site s[2];
	struct irdm_engine_config cfg;
	struct efx_ref_opts pv = { .tail_r = 1.0, .per_vertex = 1 }, co = { .tail_r = 1.0 };
	double *u = calloc(N * 6, sizeof(double)), *F = malloc(N * 6 * sizeof(double));
	double *R = malloc(N * 6 * sizeof(double)), *Rc = malloc(N * 6 * sizeof(double));

	(void)state;
	for (size_t t = 0; t < N; t++)
		u[6 * t + 5] = -0.01 * fmin(1.0, (double)t / 600.0);
	node_site(&exact, a, &s[0]);
	node_site(&exact, b, &s[1]);
	irdm_engine_config_default(&cfg);
	cfg.solve = IRDM_SOLVE_PER_VERTEX;
	double err = compare_mode("two points, per-vertex solve", cfg, s, 2, N, u,
				  IRDM_CONTACT_GRAB, &pv, F, R, NULL);
	/* the two solves must differ here, or this test could not tell them apart */
	efx_reference_opts(&exact, s, 2, N, u, &co, Rc);
	double apart = efx_rel_rms(R, Rc, N * 6);
	print_message("per-vertex vs coupled solve: %.2e apart\n", apart);
	assert_true(err <= TOL_MODAL_F64);
	assert_true(apart > 1e3 * TOL_MODAL_F64);
	free(u);
	free(F);
	free(R);
	free(Rc);
}

/* A device pushes the top 1 cm through the haptic coupling (K, B). */
static void test_coupling(void **state)
{
	const double top[3] = { 0.05, 0.05, 0.2 };
	const size_t N = 1500;
	struct irdm_contact_site s;
	struct irdm_engine_config cfg;
	double *u = calloc(N * 3, sizeof(double)), *F = malloc(N * 3 * sizeof(double));
	double *R = malloc(N * 3 * sizeof(double));

	(void)state;
	for (size_t t = 0; t < N; t++)
		u[3 * t + 2] = -0.01 * fmin(1.0, (double)t / 100.0);
	node_site(&exact, top, &s);
	irdm_engine_config_default(&cfg);
	cfg.coupling_k_n_per_m = 1000;
	cfg.coupling_b_ns_per_m = 2.25;
	struct efx_ref_opts o = { .tail_r = 1.0, .k_n_per_m = 1000, .b_ns_per_m = 2.25, .dt_s = exact.meta->dt_s };
	double err = compare_mode("step through the coupling", cfg, &s, 1, N, u,
				  IRDM_CONTACT_GRAB, &o, F, R, NULL);
	print_message("coupled force after 1.5 s: %.4f N\n", F[3 * (N - 1) + 2]);
	assert_true(err <= TOL_MODAL_F64);
	free(u);
	free(F);
	free(R);
}

/*
 * A push contact lets go when holding the surface would pull the tool:
 * pressed 1 cm through the haptic coupling (a rigid one rings every tick,
 * docs/architecture.md, and lets go at once), held, then the tool lifts at
 * 0.1 m/s; the reference decides the release tick on its own force.
 */
static void test_push_release(void **state)
{
	const double top[3] = { 0.05, 0.05, 0.2 };
	const size_t N = 1200;
	struct irdm_contact_site s;
	struct irdm_engine_config cfg;
	double *u = calloc(N * 3, sizeof(double)), *F = malloc(N * 3 * sizeof(double));
	double *R = malloc(N * 3 * sizeof(double));
	size_t rel, ref_rel = N;

	(void)state;
	for (size_t t = 0; t < N; t++) {
		double z = -0.01 * fmin(1.0, (double)t / 200.0);
		if (t > 600)
			z = fmin(0.0, -0.01 + 1e-4 * (double)(t - 600));
		u[3 * t + 2] = z;
	}
	node_site(&exact, top, &s);
	irdm_engine_config_default(&cfg);
	cfg.coupling_k_n_per_m = 1000;
	cfg.coupling_b_ns_per_m = 2.25;
	struct efx_ref_opts o = { .tail_r = 1.0, .push = 1, .normal = s.normal, .k_n_per_m = 1000, .b_ns_per_m = 2.25, .dt_s = exact.meta->dt_s };
	double err = compare_mode("push, lifted off", cfg, &s, 1, N, u, IRDM_CONTACT_PUSH, &o, F,
				  R, &rel);
	for (size_t t = 0; t < N && ref_rel == N; t++)
		if (t > 0 && R[3 * t] == 0 && R[3 * t + 1] == 0 && R[3 * t + 2] == 0)
			ref_rel = t;
	print_message("released at tick %zu (reference: %zu), the tool at z = %.2f mm\n", rel,
		      ref_rel, 1e3 * u[3 * rel + 2]);
	assert_true(rel > 600 && rel < N);
	assert_int_equal(rel, ref_rel);
	assert_true(err <= TOL_MODAL_F64);
	free(u);
	free(F);
	free(R);
}

/* ---- stroking: a contact sliding across triangles ---- */

#define N_STROKE 1500

/* R[s] of (column, row) pairs, read from the image on first use */
struct pair_cache {
	uint32_t n_rows;
	double **R; /* n_cols x n_rows table of N_STROKE x 9 */
};

static const double *pair(struct pair_cache *pc, const struct irdm_image *img, uint32_t col, uint32_t row)
{
	double **slot = &pc->R[(size_t)col * pc->n_rows + row];

	if (!*slot) {
		*slot = malloc(N_STROKE * 9 * sizeof(double));
		assert_int_equal(irdm_image_response(img, col, row, N_STROKE, *slot), 0);
	}
	return *slot;
}

/*
 * Reference: forces f_e[t] recorded per node; the contact point's
 * displacement u(t) = sum_v a_v(t) sum_{s>=0} sum_e R[s](e -> v) f_e[t-s]
 * is imposed; the unknown F spreads as f_w = a_w(t) F.
 */
static void stroke_reference(const struct irdm_image *img, const struct irdm_contact_site *sites,
			     const double *target, double *F)
{
	struct pair_cache pc = { img->meta->n_nodes,
				 calloc((size_t)img->meta->n_cols * img->meta->n_nodes, sizeof(double *)) };
	uint32_t(*col)[3] = malloc(N_STROKE * sizeof(*col));
	double(*fv)[3][3] = malloc(N_STROKE * sizeof(*fv));

	for (size_t t = 0; t < N_STROKE; t++) {
		const struct irdm_contact_site *st = &sites[t];
		double hist[3] = { 0, 0, 0 }, W[9] = { 0 };
		for (uint32_t v = 0; v < 3; v++) {
			if (st->weight[v] == 0)
				continue;
			for (size_t s = 1; s <= t; s++)
				for (int w = 0; w < 3; w++) {
					if (sites[t - s].weight[w] == 0)
						continue;
					const double *R = pair(&pc, img, col[t - s][w], st->row[v]);
					for (int i = 0; i < 3; i++)
						for (int j = 0; j < 3; j++)
							hist[i] += st->weight[v] * R[9 * s + 3 * (size_t)i + (size_t)j] * fv[t - s][w][j];
				}
			for (uint32_t w = 0; w < 3; w++) {
				if (st->weight[w] == 0)
					continue;
				const double *R = pair(&pc, img, st->col[w], st->row[v]);
				for (int k = 0; k < 9; k++)
					W[k] += st->weight[v] * st->weight[w] * R[k];
			}
		}
		double rhs[3];
		for (int i = 0; i < 3; i++)
			rhs[i] = target[3 * t + (size_t)i] - hist[i];
		/* 3x3 solve by Cramer's rule */
		double d = W[0] * (W[4] * W[8] - W[5] * W[7]) - W[1] * (W[3] * W[8] - W[5] * W[6]) + W[2] * (W[3] * W[7] - W[4] * W[6]);
		double *f = &F[3 * t];
		f[0] = (rhs[0] * (W[4] * W[8] - W[5] * W[7]) - W[1] * (rhs[1] * W[8] - W[5] * rhs[2]) + W[2] * (rhs[1] * W[7] - W[4] * rhs[2])) / d;
		f[1] = (W[0] * (rhs[1] * W[8] - W[5] * rhs[2]) - rhs[0] * (W[3] * W[8] - W[5] * W[6]) + W[2] * (W[3] * rhs[2] - rhs[1] * W[6])) / d;
		f[2] = (W[0] * (W[4] * rhs[2] - rhs[1] * W[7]) - W[1] * (W[3] * rhs[2] - rhs[1] * W[6]) + rhs[0] * (W[3] * W[7] - W[4] * W[6])) / d;
		for (int w = 0; w < 3; w++) {
			col[t][w] = st->col[w];
			for (int j = 0; j < 3; j++)
				fv[t][w][j] = st->weight[w] * f[j];
		}
	}
	for (size_t k = 0; k < (size_t)img->meta->n_cols * img->meta->n_nodes; k++)
		free(pc.R[k]);
	free(pc.R);
	free(col);
	free(fv);
}

/* Paper Fig. 6c: stroking along the top, 5 mm deep, sliding 6 cm in 1.5 s. */
static void stroke(const struct irdm_image *img, const char *what)
{
	struct irdm_engine_config cfg;
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	struct irdm_contact_site *sites = malloc(N_STROKE * sizeof(*sites));
	double *u = calloc(N_STROKE * 3, sizeof(double));
	double *F = malloc(N_STROKE * 3 * sizeof(double)), *R = malloc(N_STROKE * 3 * sizeof(double));

	irdm_engine_config_default(&cfg);
	cfg.max_contacts = 1;
	struct irdm_session *ses = efx_session(img, &cfg);
	struct irdm_engine *e = ses->eng;
	unsigned changes = 0;
	for (size_t t = 0; t < N_STROKE; t++) {
		double p[3] = { 0.02 + 0.06 * (double)t / N_STROKE, 0.043, 0.2 }, bary[3];
		uint32_t tri;
		assert_int_equal(irdm_replay_locate(img, p, &tri, bary), 0);
		assert_int_equal(irdm_engine_site_point(e, tri, bary, &sites[t]), 0);
		changes += t > 0 && memcmp(sites[t].row, sites[t - 1].row, sizeof(sites[t].row)) != 0;
		u[3 * t + 2] = -0.005 * fmin(1.0, (double)t / 100.0);
		assert_int_equal(irdm_engine_contact_begin(e, 0, &sites[t], IRDM_CONTACT_PUSH), 0);
		memset(cmd, 0, sizeof(cmd));
		cmd[0].mode = IRDM_CONTACT_PUSH;
		memcpy(cmd[0].target_m, &u[3 * t], 3 * sizeof(double));
		assert_int_equal(irdm_engine_tick(e, cmd), 0);
		assert_int_equal(irdm_engine_contact(e, 0)->mode, IRDM_CONTACT_PUSH);
		memcpy(&F[3 * t], irdm_engine_contact(e, 0)->force_n, 3 * sizeof(double));
	}
	irdm_session_close(ses);
	stroke_reference(img, sites, u, R);
	double err = efx_rel_rms(F, R, N_STROKE * 3);
	/*
	 * Smooth (Fig. 6c): crossing an edge adds no jump of its own.  With the
	 * displacement imposed rigidly the force rings every tick
	 * (docs/architecture.md, "Numerical hazards"; in the reference just
	 * the same); the change across a crossing must look like any other
	 * tick's.
	 */
	double at_cross = 0, elsewhere = 0, mean = 0;
	for (size_t t = 200; t < N_STROKE; t++) {
		double d = fabs(F[3 * t + 2] - F[3 * t - 1]);
		bool cross = memcmp(sites[t].row, sites[t - 1].row, sizeof(sites[t].row)) != 0;
		if (cross)
			at_cross = fmax(at_cross, d);
		else
			elsewhere = fmax(elsewhere, d);
		mean += fabs(F[3 * t + 2]) / (N_STROKE - 200);
	}
	print_message("stroke, %s: %u triangle changes, relative RMS force error %.2e; largest tick-to-tick |dFz| %.2e N at a crossing, %.2e N elsewhere (mean |Fz| %.3f N)\n",
		      what, changes, err, at_cross, elsewhere, mean);
	assert_true(changes >= 4);
	assert_true(err <= TOL_STROKE);
	assert_true(at_cross <= elsewhere);
	free(sites);
	free(u);
	free(F);
	free(R);
}

static void test_stroke(void **state)
{
	(void)state;
	stroke(&exact, "modal f64");
	stroke(&hybrid, "hybrid 300 + 32 f32");
	stroke(&clustered, "modal 40 + clustered f32");
}

/*
 * A hybrid's head keeps each force column's history apart (a lane a
 * column) for as many columns as two ticks can hold; more columns within
 * one head send the sum back to its ring of ticks until they are older
 * than the head.  A contact that hops to another top triangle every tick
 * for N_HOP ticks (every top node within one head), then holds still:
 * the sum from the ring, then from lanes that start afresh.
 */
#define N_HOP 300

static void hop_sites(const struct irdm_image *img, struct irdm_engine *e,
		      struct irdm_contact_site *sites)
{
	static const double bary[3] = { 0.5, 0.3, 0.2 };
	uint32_t top[256], n_top = 0;

	for (uint32_t t = 0; t < img->meta->n_tris && n_top < 256; t++) {
		const uint32_t *v = &img->tris[3 * t];
		bool all = true;
		for (int a = 0; a < 3; a++)
			all &= img->nodes[v[a]].pos_m[2] >= 0.2 - 1e-9;
		if (all)
			top[n_top++] = t;
	}
	assert_true(n_top >= 16);
	for (size_t t = 0; t < N_STROKE; t++) {
		uint32_t tri = top[t < N_HOP ? (7 * t) % n_top : 0];
		assert_int_equal(irdm_engine_site_point(e, tri, bary, &sites[t]), 0);
	}
}

/* Forces of the hop; ask: every site node's free displacement read
 * before each tick, one node at a time (as the proxy reads them). */
static void hop_run(const struct irdm_image *img, bool portable, bool ask,
		    struct irdm_contact_site *sites, const double *u, double *F)
{
	struct irdm_engine_config cfg;
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];

	irdm_engine_config_default(&cfg);
	cfg.max_contacts = 1;
	cfg.fir_portable_sum = portable;
	struct irdm_session *ses = efx_session(img, &cfg);
	struct irdm_engine *e = ses->eng;
	hop_sites(img, e, sites);
	for (size_t t = 0; t < N_STROKE; t++) {
		assert_int_equal(irdm_engine_contact_begin(e, 0, &sites[t], IRDM_CONTACT_GRAB), 0);
		for (uint32_t v = 0; ask && v < 3; v++) {
			double un[3];
			irdm_engine_node_disp(e, sites[t].row[v], un);
		}
		memset(cmd, 0, sizeof(cmd));
		cmd[0].mode = IRDM_CONTACT_GRAB;
		memcpy(cmd[0].target_m, &u[3 * t], 3 * sizeof(double));
		assert_int_equal(irdm_engine_tick(e, cmd), 0);
		memcpy(&F[3 * t], irdm_engine_contact(e, 0)->force_n, 3 * sizeof(double));
	}
	irdm_session_close(ses);
}

static void test_hop(void **state)
{
	struct irdm_contact_site *sites = malloc(N_STROKE * sizeof(*sites));
	double *u = calloc(N_STROKE * 3, sizeof(double)), *R = malloc(N_STROKE * 3 * sizeof(double));
	double *F[2][2];

	(void)state;
	for (int p = 0; p < 2; p++)
		for (int a = 0; a < 2; a++)
			F[p][a] = malloc(N_STROKE * 3 * sizeof(double));
	for (size_t t = 0; t < N_STROKE; t++)
		u[3 * t + 2] = -0.002 * fmin(1.0, (double)t / 50.0);
	for (int p = 0; p < 2; p++)
		for (int a = 0; a < 2; a++)
			hop_run(&hybrid, p, a, sites, u, F[p][a]);
	stroke_reference(&hybrid, sites, u, R);
	for (int p = 0; p < 2; p++) {
		double err = efx_rel_rms(F[p][0], R, N_STROKE * 3);
		double hop_err = efx_rel_rms(F[p][0], R, N_HOP * 3);
		print_message("hop, hybrid 300 + 32 f32, %s sum: relative RMS force error %.2e (hops alone %.2e)\n",
			      p ? "portable" : "default", err, hop_err);
		assert_true(err <= TOL_STROKE);
		assert_true(hop_err <= TOL_STROKE);
		/* a node summed alone or with the site's others: the same figure */
		assert_memory_equal(F[p][0], F[p][1], N_STROKE * 3 * sizeof(double));
	}
	for (int p = 0; p < 2; p++)
		for (int a = 0; a < 2; a++)
			free(F[p][a]);
	free(sites);
	free(u);
	free(R);
}

/*
 * The modes' recursion and kept-modes sums four modes at a time
 * (engine_modal_avx2.c) against the portable loops: the hop's forces on
 * modal images without a head (40 modes f32, 37 modes f64), equal to the
 * bit.  Where the processor has no AVX2 both runs are
 * portable and the test says so.
 */
static void test_modal_paths(void **state)
{
	const struct irdm_image *imgs[] = { &trunc32, &odd37 };
	struct irdm_contact_site *sites = malloc(N_STROKE * sizeof(*sites));
	double *u = calloc(N_STROKE * 3, sizeof(double));
	double *F[2] = { malloc(N_STROKE * 3 * sizeof(double)), malloc(N_STROKE * 3 * sizeof(double)) };
	struct irdm_engine_config cfg;

	(void)state;
	assert_true(sites && u && F[0] && F[1]);
	for (size_t t = 0; t < N_STROKE; t++)
		u[3 * t + 2] = -0.002 * fmin(1.0, (double)t / 50.0);
	for (size_t i = 0; i < sizeof(imgs) / sizeof(imgs[0]); i++) {
		irdm_engine_config_default(&cfg);
		struct irdm_session *ses = efx_session(imgs[i], &cfg);
		const char *sum = irdm_engine_fir_sum_name(ses->eng);
		irdm_session_close(ses);
		for (int p = 0; p < 2; p++)
			hop_run(imgs[i], p, true, sites, u, F[p]);
		size_t differ = 0;
		double fbig = 0;
		for (size_t j = 0; j < N_STROKE * 3; j++) {
			differ += F[0][j] != F[1][j];
			fbig = fmax(fbig, fabs(F[0][j]));
		}
		print_message("hop, modal:%u: %s sum vs portable: %zu of %d force values differ (max |F| %.3f N)\n",
			      imgs[i]->meta->n_modes, sum, differ, N_STROKE * 3, fbig);
		assert_true(fbig > 0.05);
		assert_int_equal(differ, 0);
	}
	free(F[0]);
	free(F[1]);
	free(sites);
	free(u);
}

/*
 * The hybrid's head by pairs (HEAD_PAIRS: a block read as its mirror's run
 * transposed) against the same image with every block's run written out
 * here from the format's rule: the hop's forces, both sums, to the bit
 * (the same numbers in the same order).
 */
static void *whole_head(const struct irdm_image *img, uint64_t *bytes)
{
	uint32_t n_blocks = img->corr_start[img->meta->n_cols], S = img->meta->head_samples;
	const float *runs = img->exact_head;
	float *out = malloc((size_t)n_blocks * S * 9 * sizeof(float));

	assert_non_null(out);
	assert_int_equal(img->meta->precision, IRDM_ELEM_F32);
	for (size_t k = 0; k < n_blocks; k++) {
		uint32_t v = img->head_index[k];
		bool tr = v & IRDM_HEAD_TRANSPOSED;
		const float *src = &runs[(size_t)(v & IRDM_HEAD_RUN_MASK) * S * 9];
		for (size_t s = 0; s < S; s++)
			for (size_t i = 0; i < 9; i++)
				out[(k * S + s) * 9 + i] = src[s * 9 + (tr ? 3 * (i % 3) + i / 3 : i)];
	}
	*bytes = (uint64_t)n_blocks * S * 9 * sizeof(float);
	return out;
}

static void write_whole(const struct irdm_image *img, const char *path)
{
	const struct irdm_image_header *h = (const void *)img->base;
	const struct irdm_image_section *sec = (const void *)(img->base + h->section_table_offset);
	struct irdm_meta meta = *img->meta;
	struct irdm_image_writer w;
	uint64_t head_bytes;
	void *head = whole_head(img, &head_bytes);
	char err[256];

	meta.flags &= ~IRDM_META_HEAD_PAIRS;
	irdm_iw_init(&w);
	for (uint32_t i = 0; i < h->section_count; i++) {
		const void *data = img->base + sec[i].offset;
		uint64_t size = sec[i].size;
		if (sec[i].kind == IRDM_SEC_EXACT_HEAD_INDEX)
			continue;
		if (sec[i].kind == IRDM_SEC_META)
			data = &meta;
		if (sec[i].kind == IRDM_SEC_EXACT_HEAD)
			data = head, size = head_bytes;
		assert_int_equal(irdm_iw_add(&w, sec[i].kind, sec[i].elem, data, size), 0);
	}
	assert_int_equal(irdm_iw_write(&w, path, err, sizeof(err)), 0);
	free(head);
}

static void test_head_pairs(void **state)
{
	struct irdm_contact_site *sites = malloc(N_STROKE * sizeof(*sites));
	double *u = calloc(N_STROKE * 3, sizeof(double));
	double *F = malloc(N_STROKE * 3 * sizeof(double)), *W = malloc(N_STROKE * 3 * sizeof(double));
	uint32_t n_blocks = hybrid.corr_start[hybrid.meta->n_cols], n_tr = 0;
	struct irdm_image whole;
	char path[128], err[256];

	(void)state;
	assert_true(sites && u && F && W);
	assert_non_null(hybrid.head_index);
	for (uint32_t k = 0; k < n_blocks; k++)
		n_tr += (hybrid.head_index[k] & IRDM_HEAD_TRANSPOSED) != 0;
	snprintf(path, sizeof(path), "%s/hybrid-whole.img", dir);
	write_whole(&hybrid, path);
	assert_int_equal(irdm_image_map(path, 0, &whole, err, sizeof(err)), 0);
	assert_null(whole.head_index);
	print_message("hybrid head: %u blocks in %u runs (%u read transposed); whole: %llu bytes more\n",
		      n_blocks, n_blocks - n_tr, n_tr,
		      (unsigned long long)(irdm_image_find(&whole, IRDM_SEC_EXACT_HEAD)->size -
					   irdm_image_find(&hybrid, IRDM_SEC_EXACT_HEAD)->size));
	assert_true(2 * n_tr + hybrid.meta->n_cols == n_blocks);
	for (size_t t = 0; t < N_STROKE; t++)
		u[3 * t + 2] = -0.002 * fmin(1.0, (double)t / 50.0);
	for (int p = 0; p < 2; p++) {
		hop_run(&hybrid, p, false, sites, u, F);
		hop_run(&whole, p, false, sites, u, W);
		assert_memory_equal(F, W, N_STROKE * 3 * sizeof(double));
	}
	irdm_image_unmap(&whole);
	free(sites);
	free(u);
	free(F);
	free(W);
}

/* Each error the engine's header documents, from the call that returns it. */
static void test_errors(void **state)
{
	static _Alignas(16) unsigned char small[64];
	const double bary[3] = { 0.5, 0.3, 0.2 }, bad_bary[3] = { 0.5, 0.5, 0.5 };
	struct irdm_engine_config cfg, bad;
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	struct irdm_contact_site site;
	struct irdm_session *ses;
	struct irdm_engine *e;
	char err[256];

	(void)state;
	irdm_engine_config_default(&cfg);
	bad = cfg;
	bad.max_contacts = IRDM_MAX_CONTACTS + 1;
	assert_int_equal(irdm_engine_init(&e, &exact, &bad, small, sizeof(small), err, sizeof(err)),
			 IRDM_EINVAL);
	assert_null(e);
	assert_int_equal(irdm_engine_init(&e, &exact, &cfg, small, sizeof(small), err, sizeof(err)),
			 IRDM_ENOMEM);
	assert_null(e);

	ses = efx_session(&exact, &cfg);
	e = ses->eng;
	assert_int_equal(irdm_engine_site_node(e, exact.meta->n_nodes, &site), IRDM_ECONTACT);
	uint32_t row = 0; /* a displayed node nobody may touch */
	while (row < exact.meta->n_nodes && irdm_engine_site_node(e, row, &site) == IRDM_OK)
		row++;
	assert_true(row < exact.meta->n_nodes);
	assert_int_equal(irdm_engine_site_node(e, row, &site), IRDM_ECONTACT);
	assert_int_equal(irdm_engine_site_point(e, exact.meta->n_tris, bary, &site), IRDM_ECONTACT);
	assert_int_equal(irdm_engine_site_point(e, 0, bad_bary, &site), IRDM_EINVAL);
	assert_int_equal(irdm_engine_site_node(e, exact.columns[0], &site), IRDM_OK);
	assert_int_equal(irdm_engine_contact_begin(e, cfg.max_contacts, &site, IRDM_CONTACT_GRAB),
			 IRDM_EINVAL);
	assert_int_equal(irdm_engine_contact_begin(e, 0, &site, IRDM_CONTACT_OFF), IRDM_EINVAL);
	assert_int_equal(irdm_engine_contact_begin(e, 0, &site, IRDM_CONTACT_GRAB), IRDM_OK);

	memset(cmd, 0, sizeof(cmd));
	cmd[0].mode = IRDM_CONTACT_GRAB;
	cmd[0].target_m[2] = NAN;
	assert_int_equal(irdm_engine_tick(e, cmd), IRDM_EFAULT);
	cmd[0].target_m[2] = -0.001;
	assert_int_equal(irdm_engine_tick(e, cmd), IRDM_EFAULT); /* held until reset */
	irdm_engine_reset(e);
	assert_int_equal(irdm_engine_contact_begin(e, 0, &site, IRDM_CONTACT_GRAB), IRDM_OK);
	assert_int_equal(irdm_engine_tick(e, cmd), IRDM_OK);
	irdm_session_close(ses);
}

/*
 * A node's displacement read between ticks (the proxy's surface) is the
 * free displacement the next tick starts from, remembered only until the
 * state changes: an engine read at every tick ends, bit for bit, where one
 * never read does; a reset reads zero at once.
 */
static void one_run(struct irdm_engine *e, const struct irdm_contact_site *site, uint32_t row,
		    bool read, double *u)
{
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];

	memset(cmd, 0, sizeof(cmd));
	cmd[0].mode = IRDM_CONTACT_GRAB;
	assert_int_equal(irdm_engine_contact_begin(e, 0, site, IRDM_CONTACT_GRAB), IRDM_OK);
	for (int t = 0; t < 50; t++) {
		cmd[0].target_m[2] = -0.0002 * t;
		if (read)
			irdm_engine_node_disp(e, row, u);
		assert_int_equal(irdm_engine_tick(e, cmd), IRDM_OK);
	}
	irdm_engine_node_disp(e, row, u);
}

static void test_node_disp_between_ticks(void **state)
{
	const double top[3] = { 0.05, 0.05, 0.2 };
	struct irdm_engine_config cfg;
	struct irdm_contact_site site;
	struct irdm_image *imgs[2] = { &exact, &hybrid };
	double ur[3], un[3], z[3];

	(void)state;
	irdm_engine_config_default(&cfg);
	for (int i = 0; i < 2; i++) {
		struct irdm_session *a = efx_session(imgs[i], &cfg), *b = efx_session(imgs[i], &cfg);
		uint32_t row;

		node_site(imgs[i], top, &site);
		row = site.row[0];
		one_run(a->eng, &site, row, true, ur);
		one_run(b->eng, &site, row, false, un);
		assert_true(ur[2] < 0);
		assert_memory_equal(ur, un, sizeof(ur));
		irdm_engine_reset(a->eng);
		irdm_engine_node_disp(a->eng, row, z);
		assert_true(z[0] == 0 && z[1] == 0 && z[2] == 0);
		irdm_session_close(a);
		irdm_session_close(b);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_step),
		cmocka_unit_test(test_release),
		cmocka_unit_test(test_two_points),
		cmocka_unit_test(test_fir),
		cmocka_unit_test(test_fir_sum_paths),
		cmocka_unit_test(test_per_vertex),
		cmocka_unit_test(test_coupling),
		cmocka_unit_test(test_push_release),
		cmocka_unit_test(test_stroke),
		cmocka_unit_test(test_hop),
		cmocka_unit_test(test_modal_paths),
		cmocka_unit_test(test_head_pairs),
		cmocka_unit_test(test_errors),
		cmocka_unit_test(test_node_disp_between_ticks),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
