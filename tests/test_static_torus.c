/* SPDX-License-Identifier: MIT */
/*
 * A closed surface with about 2,500 touchable nodes: a torus
 * surface written here as OFF (support/torus.h), floating, modal:300 with
 * the clustered static correction (static_correction_cluster = 256, tol
 * 8e-4), precomputed by `irdm precompute` within a peak memory and image
 * budget (its time is tests/bench/bench_torus.c's, make bench); then the
 * forces of a step at three nodes at once against the same step with the dense static correction of those three columns,
 * solved independently here (irdm_static_correction, the shifted method,
 * on the model rebuilt in this process): the reference replaces the
 * image's whole blocks between the three columns by the dense ones.  Three
 * triples: a node, its neighbour and the farthest node; the same with the
 * nearest node in a low-rank pair with the first (the largest block the
 * truncation approximates); that node with its own nearest low-rank
 * partner; and N_RANDOM triples drawn with a fixed seed.
 *
 * IRDM_TORUS_CLUSTER=0 runs the dropped-block correction instead, with
 * its far node and nearest dropped node.  IRDM_TORUS=small (`make san`)
 * meshes the torus with about 800 nodes instead of 3000; IRDM_TORUS_TOL=T
 * sets static_correction_tol, IRDM_TORUS_RANK=R static_correction_rank
 * (0: the blocks alone), IRDM_TORUS_CLUSTER=N static_correction_cluster.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <cmocka.h>

#include "modal/response.h"
#include "modal/static_sparse.h"
#include "precompute/model.h"
#include "scene/scene.h"
#include "support/engine_fixture.h"
#include "support/run_prog.h"
#include "support/test_files.h"
#include "irdm/posix/image_map.h"
#include "support/torus.h"

/* The budgets for the full torus: memory and size are the program's own.
 * Its time is not a unit test's to hold on a shared machine: the
 * benchmark prints it. */
#define MAX_PEAK_MIB 1024.0
#define MAX_IMAGE_MB 50.0
/*
 * IRDM_TORUS_CLUSTER=0: force error of the compressed correction (kept
 * blocks + the far field of rank 96) vs the dense one, with the far node: 9.3e-4
 * measured, the required 1e-3 the limit (7 % margin; 2.2e-3 with the blocks
 * alone).  It is not monotone in the rank: rank 192 fits that node's
 * blocks better (ratio left 0.0017 against 0.0024) and yet gives 1.6e-3,
 * so the fit itself is held too: the far block's ratio left over the one
 * dropped, 0.73 measured, limit 0.8 (1.0 without a far field).
 * For the nearest dropped node, in units of the tolerance: the force error
 * is about the dropped block's ratio, 0.95 tol measured (1.05 with the
 * blocks alone), limit 1.2 tol.  The required 1e-3 there is out of reach
 * of a low-rank term: that block is local (23 mm away); it needs tol near
 * 1e-3, which keeps most blocks (docs/image-format.md).
 */
#define MAX_FORCE_RMS 1e-3
#define MAX_FAR_LEFT 0.8
#define MAX_TOL_RATIO 1.2

/*
 * The clustered correction (the test's default): at most 256 nodes per
 * cluster, every block within 8e-4 sqrt(|S_aa| |S_bb|) (tighter where the
 * block's ratio is high).  Measured (2520 columns, 16 clusters): the
 * largest block error against the independent dense blocks 0.25 tol
 * (limit 1.01: f32 storage rounds); the force errors of the three chosen
 * triples 2.0e-4, 2.5e-5 and 3.0e-5, of the random ones 4.4e-5 to 8.2e-5;
 * the required 1e-3 the limit (MAX_FORCE_RMS, 4.9x margin).  With 128
 * nodes per cluster on the 2277-column torus, the plain per-block bound
 * (no conditioning share) gave 1.5e-3 for three nodes 3.3 mm apart
 * across two clusters.
 */
#define CLUSTER TORUS_CLUSTER
#define CLUSTER_TOL TORUS_CLUSTER_TOL
#define MAX_BLOCK_ERR 1.01
#define N_RANDOM 4

#define FULL_NODES TORUS_NODES
#define N_TICKS 300
#define SCALE TORUS_SCALE

static char dir[128];

static double frob(const double *b)
{
	double s = 0;

	for (int i = 0; i < 9; i++)
		s += b[i] * b[i];
	return sqrt(s);
}

static int setup(void **state)
{
	(void)state;
	return tf_tmpdir(dir, sizeof(dir), "torus");
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

/* The column nearest to p, other than skip. */
static uint32_t column_near(const struct irdm_image *img, const double p[3], uint32_t skip,
			    bool farthest)
{
	double best = farthest ? -1 : 1e300;
	uint32_t bc = 0;

	for (uint32_t c = 0; c < img->meta->n_cols; c++) {
		const float *q = img->nodes[img->columns[c]].pos_m;
		double d = 0;
		for (int a = 0; a < 3; a++)
			d += pow(q[a] - p[a], 2);
		if (c != skip && (farthest ? d > best : d < best)) {
			best = d;
			bc = c;
		}
	}
	return bc;
}

/* 1 mm towards the tube's centre line at column c. */
static void push_in(const struct irdm_image *img, uint32_t c, double u[3])
{
	const float *p = img->nodes[img->columns[c]].pos_m;
	double rho = hypot(p[0], p[1]), d[3] = { SCALE * p[0] / rho - p[0],
						 SCALE * p[1] / rho - p[1], -p[2] };
	double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);

	for (int a = 0; a < 3; a++)
		u[a] = 1e-3 * d[a] / n;
}

/* Precompute with the CLI; peak memory (the child's and the one it
 * reports) and the image's size within the budgets. */
static void precompute(const char *scene, const char *img)
{
	const char *irdm = getenv("IRDM") ? getenv("IRDM") : "build/irdm";
	char out[8192], err[8192];
	const char *peak_line;
	struct rusage ru;
	struct stat st;
	double peak_mib = 0;

	/* one BLAS thread, as the benchmark runs it: with two, the second
	 * spins whenever the other core is busy (37.8 s of CPU quiet, 44 to
	 * 51 s under .ci/run) */
	assert_int_equal(setenv("OPENBLAS_NUM_THREADS", "1", 1), 0);
	int rc = rp_run(dir, irdm, (const char *[]){ "precompute", "--scene", scene, "--max_error", "none", "-o", img, NULL },
			out, sizeof(out), err, sizeof(err));
	if (rc)
		fail_msg("irdm precompute failed (%d): %s", rc, err);
	assert_int_equal(getrusage(RUSAGE_CHILDREN, &ru), 0);
	peak_line = strstr(out, "memory        peak ");
	assert_non_null(peak_line); /* irdm precompute reports it */
	assert_int_equal(sscanf(peak_line, "memory        peak %lf MiB", &peak_mib), 1);
	assert_int_equal(stat(img, &st), 0);
	print_message("%s", out);
	print_message("precompute peak %.0f MiB (reported %.0f MiB, limit %.0f), image %.1f MB (limit %.0f)\n",
		      (double)ru.ru_maxrss / 1024, peak_mib, MAX_PEAK_MIB,
		      (double)st.st_size / 1e6, MAX_IMAGE_MB);
	assert_true(fabs(peak_mib - (double)ru.ru_maxrss / 1024) <= 0.05 * peak_mib + 1);
	assert_true(peak_mib <= MAX_PEAK_MIB);
	assert_true((double)st.st_size <= MAX_IMAGE_MB * 1e6);
}

/* The model the image was made from, rebuilt here: same mesh, same modes. */
static void rebuild(const char *scene, const struct irdm_image *img, struct irdm_model *m)
{
	struct irdm_scene sc;
	char err[512];

	irdm_scene_defaults(&sc);
	assert_int_equal(irdm_scene_load(&sc, scene, err, sizeof(err)), 0);
	if (irdm_model_build(&sc, sc.modes, NULL, NULL, m, err, sizeof(err)))
		fail_msg("model: %s", err);
	assert_int_equal(m->n_cols, img->meta->n_cols);
	assert_true(irdm_mesh_hash(&m->mesh) == img->meta->mesh_hash);
	assert_int_equal(m->modes.n_modes, img->meta->n_modes);
	for (size_t k = 0; k < m->modes.n_modes; k++)
		assert_true(fabs(sqrt(m->modes.omega2[k]) - img->modes[k].omega_rad_s) <=
			    1e-9 * img->modes[k].omega_rad_s);
}

/* u: all three pushed 1 mm inwards at once and held. */
static void step_target(const struct irdm_image *img, const uint32_t col[3], double *u)
{
	for (size_t t = 0; t < N_TICKS; t++)
		for (int s = 0; s < 3; s++)
			push_in(img, col[s], &u[9 * t + 3 * (size_t)s]);
}

/* Node sites at the three columns. */
static void node_sites(const struct irdm_image *img, const uint32_t col[3],
		       struct irdm_contact_site sites[3])
{
	memset(sites, 0, 3 * sizeof(*sites));
	for (int s = 0; s < 3; s++) {
		sites[s].n_nodes = 1;
		sites[s].col[0] = col[s];
		sites[s].row[0] = img->columns[col[s]];
		sites[s].weight[0] = 1;
	}
}

/*
 * Relative RMS force error of a step at columns col[] with the image's
 * (compressed) static correction against the same with the dense blocks of
 * the three columns solved here; *rho: the largest dropped block's norm
 * over sqrt(|S_aa| |S_bb|), from the dense blocks; *left: what the image's
 * far field leaves of it, in the same units.
 */
static double step_error(const struct irdm_image *img, struct irdm_model *m, const uint32_t col[3],
			 double *rho, double *left)
{
	struct irdm_contact_site sites[3];
	int64_t cd[9];
	double D[81], dn[3];
	char err[256];

	for (int s = 0; s < 3; s++)
		for (int a = 0; a < 3; a++)
			cd[3 * s + a] = m->col_dofs[3 * (size_t)col[s] + (size_t)a];
	assert_int_equal(irdm_static_correction(&m->fem, &m->modes, true, cd, 3, cd, 3, D,
						err, sizeof(err)),
			 0);
	node_sites(img, col, sites);
	double *W = efx_contact_responses(img, sites, 3, N_TICKS, 1.0);
	double *Wd = malloc(N_TICKS * 81 * sizeof(double));
	assert_non_null(Wd);
	memcpy(Wd, W, N_TICKS * 81 * sizeof(double));
	for (int s = 0; s < 3; s++)
		dn[s] = frob(&D[(s * 3 + s) * 9]);
	*rho = *left = 0;
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) {
			const double *d = &D[(j * 3 + i) * 9];
			double sv[9], diff[9];
			irdm_image_corr_value(img, col[j], col[i], sv);
			for (int e = 0; e < 9; e++)
				diff[e] = d[e] - sv[e];
			if (irdm_image_corr_block(img, col[j], col[i]) < 0) {
				*rho = fmax(*rho, frob(d) / sqrt(dn[i] * dn[j]));
				*left = fmax(*left, frob(diff) / sqrt(dn[i] * dn[j]));
			}
			for (int r = 0; r < 3; r++)
				for (int c = 0; c < 3; c++)
					Wd[(3 * i + r) * 9 + 3 * j + c] += diff[3 * r + c];
		}
	double *u = malloc(N_TICKS * 9 * sizeof(double));
	double *F = malloc(N_TICKS * 9 * sizeof(double)), *Fd = malloc(N_TICKS * 9 * sizeof(double));
	assert_non_null(u);
	assert_non_null(F);
	assert_non_null(Fd);
	step_target(img, col, u);
	struct efx_ref_opts o = { .tail_r = 1.0 };
	efx_reference_w(W, 3, N_TICKS, u, &o, F);
	efx_reference_w(Wd, 3, N_TICKS, u, &o, Fd);
	double e = efx_rel_rms(F, Fd, N_TICKS * 9);
	free(u);
	free(F);
	free(Fd);
	free(W);
	free(Wd);
	return e;
}

/* Squared distance between two columns' rest positions. */
static double dist2(const struct irdm_image *img, uint32_t a, uint32_t b)
{
	const float *p = img->nodes[img->columns[a]].pos_m, *q = img->nodes[img->columns[b]].pos_m;

	return pow(q[0] - p[0], 2) + pow(q[1] - p[1], 2) + pow(q[2] - p[2], 2);
}

/* The column nearest to A whose block with A is a low-rank pair's (other
 * than skip): the largest block the truncation approximates. */
static uint32_t nearest_lowrank(const struct irdm_image *img, uint32_t a, uint32_t skip)
{
	uint32_t la, lc, ca = irdm_image_corr_cluster(img, a, &la), best_c = a;
	double best = 1e300;

	for (uint32_t c = 0; c < img->meta->n_cols; c++) {
		uint32_t cc = irdm_image_corr_cluster(img, c, &lc);
		if (irdm_image_corr_pair(img, ca, cc)->rank != IRDM_CORR_PAIR_DENSE &&
		    c != skip && dist2(img, a, c) < best) {
			best = dist2(img, a, c);
			best_c = c;
		}
	}
	return best_c;
}

/*
 * The clustered correction: no block is dropped, every one is within tol
 * of the dense one (the precompute measured it; here against blocks solved
 * independently).  Steps at A, its neighbour B and (1) the farthest
 * column, (2) the nearest column in a low-rank pair with A, (3) with B
 * replaced by the nearest low-rank column of C: three truncated blocks.
 */
static void clustered_steps(const struct irdm_image *img, struct irdm_model *m, uint32_t col[3],
			    double tol)
{
	static const char *const what[3] = { "A, its neighbour B and the farthest C",
					     "A, B and the nearest C in a low-rank pair with A",
					     "A, C and C's nearest D in a low-rank pair with C" };
	double rho, left, worst = 0;

	for (int k = 0; k < 3; k++) {
		if (k == 1)
			col[2] = nearest_lowrank(img, col[0], col[1]);
		if (k == 2)
			col[1] = nearest_lowrank(img, col[2], col[0]);
		double e = step_error(img, m, col, &rho, &left);
		print_message("step at %s (columns %u, %u, %u; %.1f and %.1f mm from A): relative RMS force error %.2e (limit %.0e); largest off-diagonal block %.3g, off by %.3g (tol %g)\n",
			      what[k], col[0], col[1], col[2], 1e3 * sqrt(dist2(img, col[0], col[1])),
			      1e3 * sqrt(dist2(img, col[0], col[2])), e, MAX_FORCE_RMS, rho, left, tol);
		assert_true(left <= MAX_BLOCK_ERR * tol);
		assert_true(e <= MAX_FORCE_RMS);
		worst = fmax(worst, e);
	}
	/* and N_RANDOM triples drawn with a fixed seed: no hand-picked case */
	uint64_t state = 0x70a5u;
	for (int k = 0; k < N_RANDOM; k++) {
		for (int s = 0; s < 3; s++) {
			state = state * 6364136223846793005ull + 1442695040888963407ull;
			col[s] = (uint32_t)((state >> 33) % img->meta->n_cols);
		}
		if (col[0] == col[1] || col[1] == col[2] || col[0] == col[2])
			continue;
		double e = step_error(img, m, col, &rho, &left);
		print_message("step at random columns %u, %u, %u: relative RMS force error %.2e, blocks off by %.3g\n",
			      col[0], col[1], col[2], e, left);
		assert_true(left <= MAX_BLOCK_ERR * tol);
		assert_true(e <= MAX_FORCE_RMS);
		worst = fmax(worst, e);
	}
	print_message("clustered: %u clusters, largest rank %u; worst force error %.2e\n",
		      img->corr_clusters->n_clusters, img->corr_clusters->max_rank, worst);
}

static void test_torus(void **state)
{
	const char *size = getenv("IRDM_TORUS"), *tol = getenv("IRDM_TORUS_TOL");
	const char *rank = getenv("IRDM_TORUS_RANK"), *cluster = getenv("IRDM_TORUS_CLUSTER");
	bool small = size && !strcmp(size, "small");
	char off[192], scene[192], path[192], text[512];
	struct irdm_image img;
	struct irdm_model m;
	char err[512];
	double rho, left;

	(void)state;
	snprintf(off, sizeof(off), "%s/torus.off", dir);
	snprintf(scene, sizeof(scene), "%s/torus.scene", dir);
	snprintf(path, sizeof(path), "%s/torus.img", dir);
	assert_int_equal(torus_write_off(off, TORUS_NU, TORUS_NV), 0);
	if (!cluster)
		cluster = CLUSTER;
	if (!tol)
		tol = strcmp(cluster, "0") ? CLUSTER_TOL : NULL;
	snprintf(text, sizeof(text),
		 "name = torus\nmesh = %s\nmesh_scale = %g\nfloating = yes\ntarget_nodes = %d\n"
		 "static_correction_cluster = %s\n%s%s%s%s%s%s",
		 off, SCALE, small ? 800 : FULL_NODES, cluster, tol ? "static_correction_tol = " : "",
		 tol ? tol : "", tol ? "\n" : "", rank ? "static_correction_rank = " : "",
		 rank ? rank : "", rank ? "\n" : "");
	tf_write_text(scene, text);
	precompute(scene, path);
	assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)), 0);
	assert_true(img.meta->n_cols >= (small ? 400u : 2000u));
	assert_non_null(img.corr_start);
	rebuild(scene, &img, &m);

	/* A on the outer equator, B its nearest column, C the farthest */
	const double pa[3] = { 1.4 * SCALE, 0, 0 };
	uint32_t col[3];
	col[0] = column_near(&img, pa, UINT32_MAX, false);
	const float *qa = img.nodes[img.columns[col[0]]].pos_m;
	const double pa_f[3] = { qa[0], qa[1], qa[2] };
	col[1] = column_near(&img, pa_f, col[0], false);
	col[2] = column_near(&img, pa_f, col[0], true);
	if (img.corr_clusters) {
		clustered_steps(&img, &m, col, strtod(tol, NULL));
		irdm_model_free(&m);
		irdm_image_unmap(&img);
		return;
	}
	assert_true(irdm_image_corr_block(&img, col[0], col[1]) >= 0); /* neighbours kept */
	double e_far = step_error(&img, &m, col, &rho, &left);
	print_message("step at A, its neighbour B and the farthest C (columns %u, %u, %u of %u): relative RMS force error %.2e (limit %.0e), largest dropped block %.3g, %.3g left with the far field of rank %u\n",
		      col[0], col[1], col[2], img.meta->n_cols, e_far, MAX_FORCE_RMS, rho, left,
		      img.corr_rank);
	assert_true(e_far <= MAX_FORCE_RMS);
	if (img.corr_rank)
		assert_true(left <= MAX_FAR_LEFT * rho);

	/* C the column nearest to A whose block was dropped: the worst case
	 * the tolerance allows, whose force error it states */
	double best = 1e300;
	for (uint32_t c = 0; c < img.meta->n_cols; c++) {
		const float *q = img.nodes[img.columns[c]].pos_m;
		double d = pow(q[0] - qa[0], 2) + pow(q[1] - qa[1], 2) + pow(q[2] - qa[2], 2);
		if (d < best && irdm_image_corr_block(&img, col[0], c) < 0) {
			best = d;
			col[2] = c;
		}
	}
	if (best < 1e300) {
		double t = tol ? strtod(tol, NULL) : IRDM_STATIC_CORR_TOL_DEFAULT;
		double e_near = step_error(&img, &m, col, &rho, &left);
		print_message("step at A, B and the nearest dropped C (column %u, %.1f mm away): relative RMS force error %.2e, largest dropped block %.3g, %.3g left (tol %g, limit %.2g)\n",
			      col[2], 1e3 * sqrt(best), e_near, rho, left, t, MAX_TOL_RATIO * t);
		assert_true(rho < t);
		assert_true(e_near <= MAX_TOL_RATIO * t);
	}
	irdm_model_free(&m);
	irdm_image_unmap(&img);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_torus),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
