/* SPDX-License-Identifier: MIT */
/*
 * Deformation benchmark: irdm_deform_update() over the whole displayed
 * surface of paper-scale scenes (300 modes), one BLAS thread as in the
 * deformation thread; and the cost of a publish (what the force tick pays).
 * Prints figures, never fails on time.  Run from the repository root:
 * images are made in out/bench/ if missing.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/posix/deform_worker.h"
#include "irdm/posix/session.h"
#include "irdm/session.h"
#include "../support/bench_util.h"

void openblas_set_num_threads(int n);

#define N_CALLS 2000
#define N_WARMUP 50

static void report(const char *name, uint32_t rows, const char *what, double *t, size_t n,
		   double unit, const char *uname)
{
	struct bench_stats st;

	bench_stats(t, n, &st);
	printf("deform  %s  rows=%u  %s median %.3f %s  p99 %.3f %s  max %.3f %s\n", name, rows,
	       what, st.median / unit, uname, st.p99 / unit, uname, st.max / unit, uname);
}

/* A plausible state: random mode amplitudes, forces at three columns. */
static void fill_state(const struct irdm_image *img, double *x, struct irdm_force_tick *f)
{
	uint32_t K = img->meta->n_modes, nc = img->meta->n_cols;

	for (uint32_t k = 0; k < 2 * K; k++)
		x[k] = 1e-3 * ((double)rand() / RAND_MAX - 0.5);
	memset(f, 0, sizeof(*f));
	f->n = 3;
	for (uint32_t e = 0; e < 3; e++) {
		f->col[e] = (uint32_t)rand() % nc;
		for (int j = 0; j < 3; j++)
			f->f_n[e][j] = (double)rand() / RAND_MAX - 0.5;
	}
}

/* Publish and update, each timed, on a session with the deformation worker. */
static int bench_session(const char *name, struct irdm_session *ses)
{
	const struct irdm_image *img = ses->img;
	size_t n3 = 3 * (size_t)img->meta->n_nodes;
	double *pos = malloc(n3 * sizeof(double)), *t_up = malloc(N_CALLS * sizeof(double));
	double *t_pub = malloc(N_CALLS * sizeof(double));
	double *x = malloc(2 * (size_t)img->meta->n_modes * sizeof(double));
	struct irdm_force_tick f;
	int rc = -1;

	if (!pos || !t_up || !t_pub || !x)
		goto out;
	fill_state(img, x, &f);
	for (int i = -N_WARMUP; i < N_CALLS; i++) {
		uint64_t tick;
		double t0, t1, t2;
		x[0] = 1e-4 * i;
		t0 = bench_now_us();
		irdm_deform_publish_modal(ses->deform, (uint64_t)(i + N_WARMUP), x, &f, NULL);
		t1 = bench_now_us();
		if (!irdm_deform_update(ses->worker, pos, &tick))
			goto out;
		t2 = bench_now_us();
		if (i >= 0) {
			t_pub[i] = t1 - t0;
			t_up[i] = t2 - t1;
		}
	}
	report(name, img->meta->n_nodes, "update ", t_up, N_CALLS, 1e3, "ms");
	report(name, img->meta->n_nodes, "publish", t_pub, N_CALLS, 1, "us");
	rc = 0;
out:
	free(pos);
	free(t_up);
	free(t_pub);
	free(x);
	return rc;
}

/* kv: scene keys over the scene's, NULL-terminated pairs, or NULL */
static int bench_scene(const char *name, const char *scene, const char *const *kv,
		       const char *path)
{
	struct irdm_session_config sc = { .deform = true };
	const struct irdm_meta *m;
	struct irdm_session *ses;
	char err[1024];
	int rc = 0;

	if (bench_ensure_image("deform", path, scene, kv))
		return -1;
	irdm_engine_config_default(&sc.engine);
	if (irdm_session_open(&ses, path, &sc, err, sizeof(err))) {
		fprintf(stderr, "deform  %s: %s\n", name, err);
		return -1;
	}
	m = ses->img->meta;
	if (m->representation != IRDM_REPR_MODAL) {
		printf("deform  %s: %s is not modal, skipped\n", name, path);
		goto out;
	}
	printf("deform  %s  %s: %u modes, %s, %u columns", name, path, m->n_modes,
	       m->precision == IRDM_ELEM_F64 ? "f64" : m->precision == IRDM_ELEM_F32 ? "f32" :
										       "f16",
	       m->n_cols);
	if (ses->img->corr_clusters)
		printf(", correction in %u clusters (max rank %u)", ses->img->corr_clusters->n_clusters,
		       ses->img->corr_clusters->max_rank);
	printf("\n");
	rc = irdm_session_deform_open(ses, err, sizeof(err));
	if (rc)
		fprintf(stderr, "deform  %s: %s\n", name, err);
	else
		rc = bench_session(name, ses);
out:
	irdm_session_close(ses);
	return rc;
}

int main(void)
{
	/* the default scene pinned to 300 modes and the static correction:
	 * the deformation's cost is per mode */
#define PIN_300 "representation", "modal:300", "static_correction", "yes", "max_error", "none"
	static const char *const pinned[] = { PIN_300, NULL };
	static const char *const f64[] = { PIN_300, "precision", "f64", NULL };
	static const char *const clustered[] = { PIN_300, "static_correction_cluster", "16", NULL };
	int rc = 0;

	/* the deformation thread's setting: one BLAS thread */
	openblas_set_num_threads(IRDM_DEFORM_BLAS_THREADS);
	rc |= bench_scene("cuboid-300modes", "scenes/cuboid-top.scene", pinned,
			  "out/bench/cuboid-top.img");
	/* the same in f64: the dgemv path, twice the bytes to stream */
	rc |= bench_scene("cuboid-300modes-f64", "scenes/cuboid-top.scene", f64,
			  "out/bench/cuboid-top-f64.img");
	/* the correction between every pair of touchable nodes, clustered */
	rc |= bench_scene("cuboid-300modes-clustered", "scenes/cuboid-top.scene", clustered,
			  "out/bench/cuboid-top-clustered.img");
	if (!bench_file_exists("out/bench/bunny.img") && !bench_file_exists("build/data/bunny.off"))
		printf("deform  bunny-300modes: skipped (no build/data/bunny.off: "
		       "tools/scripts/bunny-off.sh build/data/bunny.off)\n");
	else
		rc |= bench_scene("bunny-300modes", "scenes/bunny.scene", NULL,
				  "out/bench/bunny.img");
	return rc ? 1 : 0;
}
