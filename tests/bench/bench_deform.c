/* SPDX-License-Identifier: MIT */
/*
 * Deformation benchmark: irdm_deform_update() over the whole displayed
 * surface of paper-scale scenes (300 modes), one BLAS thread as in the
 * deformation thread; and the cost of a publish (what the force tick pays).
 * Prints figures, never fails on time.  Run from the repository root:
 * images are made in out/bench/ if missing.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "irdm/deform.h"
#include "precompute/precompute.h"

void openblas_set_num_threads(int n);

#define N_CALLS 2000
#define N_WARMUP 50

static double now_us(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec * 1e-3;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;

	return (x > y) - (x < y);
}

static int file_exists(const char *path)
{
	struct stat st;

	return !stat(path, &st);
}

/* scene file -> image, with the precompute library (no subprocess) */
static int make_image(const char *scene, const char *precision, const char *img, char *err,
		      size_t errlen)
{
	struct irdm_scene sc;
	struct irdm_precompute_opts o = { .out_path = img };
	struct irdm_precompute_report rep;

	if (mkdir("out", 0777) && errno != EEXIST)
		return -1;
	if (mkdir("out/bench", 0777) && errno != EEXIST)
		return -1;
	irdm_scene_defaults(&sc);
	if (irdm_scene_load(&sc, scene, err, errlen))
		return -1;
	if (precision && irdm_scene_set(&sc, "precision", precision, "bench", err, errlen))
		return -1;
	if (irdm_scene_check(&sc, err, errlen))
		return -1;
	printf("deform  precomputing %s -> %s\n", scene, img);
	fflush(stdout);
	if (irdm_precompute(&sc, &o, &rep, err, errlen))
		return -1;
	return 0;
}

static void report(const char *name, uint32_t rows, const char *what, double *t, size_t n,
		   double unit, const char *uname)
{
	qsort(t, n, sizeof(*t), cmp_double);
	printf("deform  %s  rows=%u  %s median %.3f %s  p99 %.3f %s  max %.3f %s\n", name, rows,
	       what, t[n / 2] / unit, uname, t[n * 99 / 100] / unit, uname, t[n - 1] / unit,
	       uname);
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

static int bench_image(const char *name, const struct irdm_image *img)
{
	size_t sz = irdm_deform_mem_size(img), n3 = 3 * (size_t)img->meta->n_nodes;
	void *mem = malloc(sz);
	double *pos = malloc(n3 * sizeof(double)), *t_up = malloc(N_CALLS * sizeof(double));
	double *t_pub = malloc(N_CALLS * sizeof(double));
	double *x = malloc(2 * (size_t)img->meta->n_modes * sizeof(double));
	struct irdm_force_tick f;
	struct irdm_deform *d;
	char err[256];
	int rc = -1;

	if (!mem || !pos || !t_up || !t_pub || !x)
		goto out;
	if (irdm_deform_init(&d, img, mem, sz, err, sizeof(err))) {
		fprintf(stderr, "deform  %s: %s\n", name, err);
		goto out;
	}
	fill_state(img, x, &f);
	for (int i = -N_WARMUP; i < N_CALLS; i++) {
		uint64_t tick;
		double t0, t1, t2;
		x[0] = 1e-4 * i;
		t0 = now_us();
		irdm_deform_publish_modal(d, (uint64_t)(i + N_WARMUP), x, &f, NULL);
		t1 = now_us();
		if (!irdm_deform_update(d, pos, &tick))
			goto out;
		t2 = now_us();
		if (i >= 0) {
			t_pub[i] = t1 - t0;
			t_up[i] = t2 - t1;
		}
	}
	report(name, img->meta->n_nodes, "update ", t_up, N_CALLS, 1e3, "ms");
	report(name, img->meta->n_nodes, "publish", t_pub, N_CALLS, 1, "us");
	rc = 0;
out:
	free(mem);
	free(pos);
	free(t_up);
	free(t_pub);
	free(x);
	return rc;
}

static int bench_scene(const char *name, const char *scene, const char *precision,
		       const char *path)
{
	struct irdm_image img;
	char err[1024];
	int rc;

	if (!file_exists(path) && make_image(scene, precision, path, err, sizeof(err))) {
		fprintf(stderr, "deform  %s: %s\n", name, err);
		return -1;
	}
	if (irdm_image_map(path, 0, &img, err, sizeof(err))) {
		fprintf(stderr, "deform  %s: %s\n", name, err);
		return -1;
	}
	if (img.meta->representation != IRDM_REPR_MODAL) {
		printf("deform  %s: %s is not modal, skipped\n", name, path);
		irdm_image_unmap(&img);
		return 0;
	}
	printf("deform  %s  %s: %u modes, %s, %u columns\n", name, path, img.meta->n_modes,
	       img.meta->precision == IRDM_ELEM_F64 ? "f64" :
	       img.meta->precision == IRDM_ELEM_F32 ? "f32" : "f16", img.meta->n_cols);
	rc = bench_image(name, &img);
	irdm_image_unmap(&img);
	return rc;
}

int main(void)
{
	int rc = 0;

	/* the deformation thread's setting: one BLAS thread */
	openblas_set_num_threads(IRDM_DEFORM_BLAS_THREADS);
	rc |= bench_scene("cuboid-300modes", "scenes/cuboid-top.scene", NULL,
			  "out/bench/cuboid-top.img");
	/* the same in f64: the dgemv path, twice the bytes to stream */
	rc |= bench_scene("cuboid-300modes-f64", "scenes/cuboid-top.scene", "f64",
			  "out/bench/cuboid-top-f64.img");
	if (!file_exists("out/bench/bunny.img") && !file_exists("build/data/bunny.off"))
		printf("deform  bunny-300modes: skipped (no build/data/bunny.off: "
		       "tools/scripts/bunny-off.sh build/data/bunny.off)\n");
	else
		rc |= bench_scene("bunny-300modes", "scenes/bunny.scene", NULL,
				  "out/bench/bunny.img");
	return rc ? 1 : 0;
}
