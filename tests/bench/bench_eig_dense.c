/* SPDX-License-Identifier: MIT */
/*
 * The dense all-modes eigensolve (tools/modal/eig_dense.c) and the LAPACK
 * routes it could take, timed on the default scene's model
 * (scenes/cuboid-top.scene: the paper's cuboid, 9504 free DoFs, lumped
 * mass, so the standard matrix is A = M^-1/2 K M^-1/2):
 *
 *   irdm_eig_dense   the solver as built, every mode (densify, reduce,
 *                    solve, back-scale)
 *   dsyevr           MRRR driver, JOBZ = V, RANGE = I over every mode
 *   dsyevd           divide-and-conquer driver, JOBZ = V
 *   phases           dsytrd, then on its tridiagonal dsterf (values),
 *                    dstemr (MRRR vectors, which may fail: dsyevr then
 *                    falls back to dstebz + dstein) and dstedc (divide and
 *                    conquer vectors), then dormtr on dstedc's: where a
 *                    driver's time goes; dsytrd + dsterf is the
 *                    eigenvalues-only ceiling
 *
 * each with OpenBLAS on 2 threads and on 1, the cases alternating within
 * a round (the host is shared: compare rows of one run), IRDM_BENCH_ROUNDS rounds,
 * medians printed.  Each route's eigenpairs are checked against the first
 * dsyevr's: eigenvalues, and on a sample of columns the residual, the
 * orthonormality and the projection on the reference eigenspace.
 *
 * Run from the repository root.  IRDM_BENCH_RES=NX,NY,NZ shrinks the mesh
 * (a quick try); IRDM_BENCH_ROUNDS sets the rounds (default 1:
 * a round of the full model takes tens of minutes);
 * IRDM_BENCH_ONLY=dsyevd,phases selects routes (bench_util.h; dsyevr, the
 * reference, always runs, and irdm_eig_dense only when named there).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "modal/lapack.h"
#include "modal/modal.h"
#include "precompute/model.h"
#include "../support/bench_util.h"

void dsyevd_(const char *jobz, const char *uplo, const int *n, double *a, const int *lda,
	     double *w, double *work, const int *lwork, int *iwork, const int *liwork,
	     int *info);
void dsterf_(const int *n, double *d, double *e, int *info);
void dstemr_(const char *jobz, const char *range, const int *n, double *d, double *e,
	     const double *vl, const double *vu, const int *il, const int *iu, int *m,
	     double *w, double *z, const int *ldz, const int *nzc, int *isuppz, int *tryrac,
	     double *work, const int *lwork, int *iwork, const int *liwork, int *info);

#define MAX_ROUNDS 5
#define N_SAMPLE 64 /* columns whose residuals are checked */

enum route { R_SHIP,
	     R_SYEVR,
	     R_SYEVD,
	     R_PHASES,
	     R_COUNT };
static const char *const route_name[R_COUNT] = { "irdm_eig_dense", "dsyevr", "dsyevd", "phases" };

enum phase { P_TOTAL,
	     P_SYTRD,
	     P_STERF,
	     P_STEMR,
	     P_STEDC,
	     P_ORMTR,
	     P_COUNT };
static const char *const phase_name[P_COUNT] = { "total", "dsytrd", "dsterf", "dstemr", "dstedc",
						 "dormtr" };

static const int threads[2] = { 2, 1 };

struct bench {
	struct irdm_model m;
	int n;
	double *a0;    /* A = M^-1/2 K M^-1/2, kept */
	double *dsqrt; /* M^1/2 diagonal */
	double *a;     /* the working copy a route destroys */
	double *z;     /* its eigenvectors */
	double *w;
	double *wref, *zref; /* the first dsyevr's */
	double t[R_COUNT][2][P_COUNT][MAX_ROUNDS];
	int stemr_info; /* the last dstemr's */
	/* worst over runs: eigenvalue difference to the reference (relative
	 * to the largest and to each), residual, orthonormality, projection */
	double dw_abs[R_COUNT], dw_rel[R_COUNT], res[R_COUNT], orth[R_COUNT], proj[R_COUNT];
};

static void *xmalloc(size_t bytes)
{
	void *p = malloc(bytes);

	if (!p) {
		fprintf(stderr, "eig-dense: out of memory (%zu bytes)\n", bytes);
		exit(1);
	}
	return p;
}

static double now_s(void)
{
	return bench_now_us() * 1e-6;
}

static int build_model(struct bench *b)
{
	struct irdm_scene sc;
	char err[512], note[256];
	const char *res = getenv("IRDM_BENCH_RES");

	irdm_scene_defaults(&sc);
	if (irdm_scene_load(&sc, "scenes/cuboid-top.scene", err, sizeof(err)))
		goto fail;
	if (res && sscanf(res, "%u,%u,%u", &sc.res[0], &sc.res[1], &sc.res[2]) != 3) {
		fprintf(stderr, "eig-dense: IRDM_BENCH_RES=%s: expected NX,NY,NZ\n", res);
		return -1;
	}
	memset(&b->m, 0, sizeof(b->m));
	if (irdm_model_mesh(&sc, &b->m.mesh, note, err, sizeof(err)))
		goto fail;
	b->m.fixed = calloc(b->m.mesh.n_nodes, sizeof(bool));
	if (!b->m.fixed)
		return -1;
	for (size_t i = 0; i < b->m.mesh.n_nodes; i++)
		b->m.fixed[i] = irdm_region_contains(&sc.fixed, (uint32_t)i, &b->m.mesh.pos_m[3 * i],
						     false);
	if (irdm_fem_assemble(&b->m.mesh, &sc.mat, sc.mass, b->m.fixed, &b->m.fem, err,
			      sizeof(err)))
		goto fail;
	return 0;
fail:
	fprintf(stderr, "eig-dense: %s\n", err);
	return -1;
}

/* A = M^-1/2 K M^-1/2, as the solver forms it for a lumped mass. */
static int reduce(struct bench *b)
{
	const struct irdm_csc *M = &b->m.fem.M;
	size_t n = M->n;

	for (size_t j = 0; j < n; j++)
		for (int64_t p = M->colptr[j]; p < M->colptr[j + 1]; p++) {
			if ((size_t)M->rowind[p] != j && M->val[p] != 0) {
				fprintf(stderr, "eig-dense: the mass is not lumped\n");
				return -1;
			}
			if ((size_t)M->rowind[p] == j)
				b->dsqrt[j] = sqrt(M->val[p]);
		}
	double *k = irdm_csc_to_dense(&b->m.fem.K);
	if (!k)
		return -1;
	for (size_t j = 0; j < n; j++)
		for (size_t i = 0; i < n; i++)
			b->a0[j * n + i] = k[j * n + i] / (b->dsqrt[i] * b->dsqrt[j]);
	free(k);
	return 0;
}

static void lapack_fail(const char *what, int info)
{
	fprintf(stderr, "eig-dense: %s failed (info %d)\n", what, info);
	exit(1);
}

static void run_ship(struct bench *b, double *t)
{
	char err[256];
	size_t n = (size_t)b->n;

	t[P_TOTAL] = now_s();
	if (irdm_eig_dense(&b->m.fem, n, b->w, b->z, err, sizeof(err))) {
		fprintf(stderr, "eig-dense: %s\n", err);
		exit(1);
	}
	t[P_TOTAL] = now_s() - t[P_TOTAL];
	/* back to the standard problem's vectors, y = M^1/2 phi */
	for (size_t j = 0; j < n; j++)
		for (size_t i = 0; i < n; i++)
			b->z[j * n + i] *= b->dsqrt[i];
}

static void run_syevr(struct bench *b, double *t)
{
	int n = b->n, il = 1, m = 0, info = 0, lwork = -1, liwork = -1, iwq = 0;
	double vl = 0, vu = 0, abstol = 0, wq = 0;
	int *isuppz = xmalloc(2 * (size_t)n * sizeof(int));

	dsyevr_("V", "I", "L", &n, b->a, &n, &vl, &vu, &il, &n, &abstol, &m, b->w, b->z, &n,
		isuppz, &wq, &lwork, &iwq, &liwork, &info);
	lwork = (int)wq;
	liwork = iwq;
	double *work = xmalloc((size_t)lwork * sizeof(double));
	int *iwork = xmalloc((size_t)liwork * sizeof(int));
	t[P_TOTAL] = now_s();
	dsyevr_("V", "I", "L", &n, b->a, &n, &vl, &vu, &il, &n, &abstol, &m, b->w, b->z, &n,
		isuppz, work, &lwork, iwork, &liwork, &info);
	t[P_TOTAL] = now_s() - t[P_TOTAL];
	if (info || m != n)
		lapack_fail("dsyevr", info);
	free(isuppz);
	free(work);
	free(iwork);
}

static void run_syevd(struct bench *b, double *t)
{
	int n = b->n, info = 0, lwork = -1, liwork = -1, iwq = 0;
	double wq = 0;

	dsyevd_("V", "L", &n, b->a, &n, b->w, &wq, &lwork, &iwq, &liwork, &info);
	lwork = (int)wq;
	liwork = iwq;
	double *work = xmalloc((size_t)lwork * sizeof(double));
	int *iwork = xmalloc((size_t)liwork * sizeof(int));
	t[P_TOTAL] = now_s();
	dsyevd_("V", "L", &n, b->a, &n, b->w, work, &lwork, iwork, &liwork, &info);
	t[P_TOTAL] = now_s() - t[P_TOTAL];
	if (info)
		lapack_fail("dsyevd", info);
	memcpy(b->z, b->a, (size_t)n * (size_t)n * sizeof(double));
	free(work);
	free(iwork);
}

/* The drivers' steps one by one on one reduction. */
static void run_phases(struct bench *b, double *t)
{
	int n = b->n, info = 0, lwork = -1, liwork = -1, iwq = 0, m = 0, il = 1, tryrac = 1;
	double wq = 0, vl = 0, vu = 0;
	size_t nn = (size_t)n;
	double *d = xmalloc(nn * sizeof(double)), *e = xmalloc(nn * sizeof(double));
	double *dc = xmalloc(nn * sizeof(double)), *ec = xmalloc(nn * sizeof(double));
	double *tau = xmalloc(nn * sizeof(double));
	int *isuppz = xmalloc(2 * nn * sizeof(int));
	double t0;

	dsytrd_("L", &n, b->a, &n, d, e, tau, &wq, &lwork, &info);
	lwork = (int)wq;
	double *work = xmalloc((size_t)lwork * sizeof(double));
	t0 = now_s();
	dsytrd_("L", &n, b->a, &n, d, e, tau, work, &lwork, &info);
	t[P_SYTRD] = now_s() - t0;
	if (info)
		lapack_fail("dsytrd", info);
	free(work);

	memcpy(dc, d, nn * sizeof(double));
	memcpy(ec, e, nn * sizeof(double));
	t0 = now_s();
	dsterf_(&n, dc, ec, &info);
	t[P_STERF] = now_s() - t0;
	if (info)
		lapack_fail("dsterf", info);

	/* dstemr, dsyevr's step for every mode: it may fail on this
	 * spectrum's clusters, and dsyevr then falls back to bisection and
	 * inverse iteration (dstebz, dstein) */
	lwork = liwork = -1;
	dstemr_("V", "A", &n, dc, ec, &vl, &vu, &il, &n, &m, b->w, b->z, &n, &n, isuppz, &tryrac,
		&wq, &lwork, &iwq, &liwork, &info);
	lwork = (int)wq;
	liwork = iwq;
	work = xmalloc((size_t)lwork * sizeof(double));
	int *iwork = xmalloc((size_t)liwork * sizeof(int));
	memcpy(dc, d, nn * sizeof(double));
	memcpy(ec, e, nn * sizeof(double));
	tryrac = 1;
	t0 = now_s();
	dstemr_("V", "A", &n, dc, ec, &vl, &vu, &il, &n, &m, b->w, b->z, &n, &n, isuppz, &tryrac,
		work, &lwork, iwork, &liwork, &info);
	t[P_STEMR] = now_s() - t0;
	b->stemr_info = info;
	free(work);
	free(iwork);

	/* dstedc, whose vectors go on through dormtr and are checked */
	lwork = liwork = -1;
	dstedc_("I", &n, d, e, b->z, &n, &wq, &lwork, &iwq, &liwork, &info);
	lwork = (int)wq;
	liwork = iwq;
	work = xmalloc((size_t)lwork * sizeof(double));
	iwork = xmalloc((size_t)liwork * sizeof(int));
	t0 = now_s();
	dstedc_("I", &n, d, e, b->z, &n, work, &lwork, iwork, &liwork, &info);
	t[P_STEDC] = now_s() - t0;
	if (info)
		lapack_fail("dstedc", info);
	memcpy(b->w, d, nn * sizeof(double));
	free(work);
	free(iwork);

	lwork = -1;
	dormtr_("L", "L", "N", &n, &n, b->a, &n, tau, b->z, &n, &wq, &lwork, &info);
	lwork = (int)wq;
	work = xmalloc((size_t)lwork * sizeof(double));
	t0 = now_s();
	dormtr_("L", "L", "N", &n, &n, b->a, &n, tau, b->z, &n, work, &lwork, &info);
	t[P_ORMTR] = now_s() - t0;
	if (info)
		lapack_fail("dormtr", info);
	t[P_TOTAL] = t[P_SYTRD] + t[P_STEDC] + t[P_ORMTR];
	free(work);
	free(d);
	free(e);
	free(dc);
	free(ec);
	free(tau);
	free(isuppz);
}

/* Sampled columns of Y (n x N_SAMPLE), spread over the spectrum. */
static void gather(const struct bench *b, const double *y, double *ys, int *cols)
{
	size_t n = (size_t)b->n;

	for (int s = 0; s < N_SAMPLE; s++) {
		cols[s] = (int)((n - 1) * (size_t)s / (N_SAMPLE - 1));
		memcpy(&ys[(size_t)s * n], &y[(size_t)cols[s] * n], n * sizeof(double));
	}
}

static void check(struct bench *b, enum route r)
{
	int n = b->n, ns = N_SAMPLE, cols[N_SAMPLE];
	size_t nn = (size_t)n;
	double one = 1, zero = 0, wmax = 0;
	double *ys = xmalloc(nn * N_SAMPLE * sizeof(double)), *g = xmalloc(nn * N_SAMPLE * sizeof(double));

	for (size_t i = 0; i < nn; i++)
		wmax = fmax(wmax, fabs(b->wref[i]));
	for (size_t i = 0; i < nn; i++) {
		double d = fabs(b->w[i] - b->wref[i]);
		b->dw_abs[r] = fmax(b->dw_abs[r], d / wmax);
		b->dw_rel[r] = fmax(b->dw_rel[r], d / fabs(b->wref[i]));
	}
	gather(b, b->z, ys, cols);
	/* residual A y - w y, relative to |A|_2 = max |w| */
	dgemm_("N", "N", &n, &ns, &n, &one, b->a0, &n, ys, &n, &zero, g, &n);
	for (int s = 0; s < ns; s++)
		for (size_t i = 0; i < nn; i++) {
			double v = g[(size_t)s * nn + i] - b->w[cols[s]] * ys[(size_t)s * nn + i];
			b->res[r] = fmax(b->res[r], fabs(v) / wmax);
		}
	/* Y^T y_s = e_s */
	dgemm_("T", "N", &n, &ns, &n, &one, b->z, &n, ys, &n, &zero, g, &n);
	for (int s = 0; s < ns; s++)
		for (size_t i = 0; i < nn; i++)
			b->orth[r] = fmax(b->orth[r], fabs(g[(size_t)s * nn + i] - ((int)i == cols[s])));
	/* y_s in the reference's eigenspace of its eigenvalue (sign, and any
	 * rotation within a cluster, are free) */
	dgemm_("T", "N", &n, &ns, &n, &one, b->zref, &n, ys, &n, &zero, g, &n);
	for (int s = 0; s < ns; s++) {
		double p = 0, ws = b->w[cols[s]];
		for (size_t i = 0; i < nn; i++)
			if (fabs(b->wref[i] - ws) <= 1e-6 * fabs(ws) + 1e-12 * wmax)
				p += g[(size_t)s * nn + i] * g[(size_t)s * nn + i];
		b->proj[r] = fmax(b->proj[r], fabs(1 - p));
	}
	free(ys);
	free(g);
}

static void run(struct bench *b, enum route r, int ti, int round)
{
	size_t bytes = (size_t)b->n * (size_t)b->n * sizeof(double);
	double *t = &b->t[r][ti][0][0];
	double ph[P_COUNT] = { 0 };

	openblas_set_num_threads(threads[ti]);
	memcpy(b->a, b->a0, bytes);
	if (r == R_SHIP)
		run_ship(b, ph);
	else if (r == R_SYEVR)
		run_syevr(b, ph);
	else if (r == R_SYEVD)
		run_syevd(b, ph);
	else
		run_phases(b, ph);
	for (int p = 0; p < P_COUNT; p++)
		t[p * MAX_ROUNDS + round] = ph[p];
	printf("eig-dense  round %d, %d thread%s: %-15s %8.2f s", round + 1, threads[ti],
	       threads[ti] > 1 ? "s" : "", route_name[r], ph[P_TOTAL]);
	if (r == R_PHASES)
		printf(" (dsytrd %.2f, dsterf %.2f, dstemr %.2f%s, dstedc %.2f, dormtr %.2f)",
		       ph[P_SYTRD], ph[P_STERF], ph[P_STEMR], b->stemr_info ? " failed" : "",
		       ph[P_STEDC], ph[P_ORMTR]);
	printf("\n");
	fflush(stdout);
	if (!b->wref) {
		b->wref = xmalloc((size_t)b->n * sizeof(double));
		b->zref = xmalloc(bytes);
		memcpy(b->wref, b->w, (size_t)b->n * sizeof(double));
		memcpy(b->zref, b->z, bytes);
	}
	check(b, r);
}

static double median(const double *x, int k)
{
	double s[MAX_ROUNDS];

	memcpy(s, x, (size_t)k * sizeof(double));
	for (int i = 1; i < k; i++)
		for (int j = i; j > 0 && s[j] < s[j - 1]; j--) {
			double v = s[j];
			s[j] = s[j - 1];
			s[j - 1] = v;
		}
	return k % 2 ? s[k / 2] : 0.5 * (s[k / 2 - 1] + s[k / 2]);
}

static void report(const struct bench *b, const bool *sel, int rounds)
{
	char title[64];

	snprintf(title, sizeof(title), "-- medians of %d round%s (s) --", rounds, rounds > 1 ? "s" : "");
	printf("eig-dense  %-36s %9s  %9s\n", title, "2 threads", "1 thread");
	for (int r = 0; r < R_COUNT; r++) {
		if (!sel[r])
			continue;
		for (int p = 0; p < P_COUNT; p++) {
			char what[64];

			if (r != R_PHASES && p != P_TOTAL)
				continue;
			if (r != R_PHASES)
				snprintf(what, sizeof(what), "%s", route_name[r]);
			else if (p == P_TOTAL)
				snprintf(what, sizeof(what), "dsytrd + dstedc + dormtr");
			else
				snprintf(what, sizeof(what), "  %s%s", phase_name[p],
					 p == P_STEMR && b->stemr_info ? " (failed)" : "");
			printf("eig-dense  %-36s %9.2f  %9.2f\n", what, median(b->t[r][0][p], rounds),
			       median(b->t[r][1][p], rounds));
		}
		if (r == R_PHASES) {
			double v[2][MAX_ROUNDS];
			for (int ti = 0; ti < 2; ti++)
				for (int k = 0; k < rounds; k++)
					v[ti][k] = b->t[r][ti][P_SYTRD][k] + b->t[r][ti][P_STERF][k];
			printf("eig-dense  %-36s %9.2f  %9.2f\n", "eigenvalues only (dsytrd + dsterf)",
			       median(v[0], rounds), median(v[1], rounds));
		}
	}
	if (sel[R_PHASES] && b->stemr_info)
		printf("eig-dense  dstemr failed (info %d): dsyevr then computes the vectors again by\n"
		       "eig-dense  bisection and inverse iteration (dstebz, dstein)\n",
		       b->stemr_info);
	printf("eig-dense  -- eigenpairs against the first dsyevr's, worst over runs --\n"
	       "eig-dense  dw: eigenvalue difference, relative to the largest eigenvalue and to\n"
	       "eig-dense  its own; on %d columns y_s spread over the spectrum: the residual\n"
	       "eig-dense  max|A y_s - w_s y_s| / max w, the orthonormality max|Y^T y_s - e_s|,\n"
	       "eig-dense  and 1 - |projection of y_s on the reference's eigenspace of w_s|^2\n"
	       "eig-dense  (eigenvalues within 1e-6: a sign or a rotation in a cluster is free)\n",
	       N_SAMPLE);
	printf("eig-dense  %-16s %10s %10s %10s %10s %10s\n", "route", "dw/max w", "dw/w", "residual",
	       "orthonorm", "1 - proj");
	for (int r = 0; r < R_COUNT; r++)
		if (sel[r])
			printf("eig-dense  %-16s %10.1e %10.1e %10.1e %10.1e %10.1e\n", route_name[r],
			       b->dw_abs[r], b->dw_rel[r], b->res[r], b->orth[r], b->proj[r]);
}

int main(void)
{
	static struct bench b;
	const char *rs = getenv("IRDM_BENCH_ROUNDS");
	int rounds = rs ? atoi(rs) : 1;
	bool sel[R_COUNT];

	if (rounds < 1 || rounds > MAX_ROUNDS) {
		fprintf(stderr, "eig-dense: IRDM_BENCH_ROUNDS: 1 to %d\n", MAX_ROUNDS);
		return 1;
	}
	for (int r = 0; r < R_COUNT; r++)
		sel[r] = bench_selected(route_name[r]);
	sel[R_SYEVR] = true; /* the reference */
	/* the solver as built repeats one of the routes: on request only */
	sel[R_SHIP] = sel[R_SHIP] && getenv("IRDM_BENCH_ONLY");
	if (build_model(&b))
		return 1;
	b.n = (int)b.m.fem.K.n;
	size_t bytes = (size_t)b.n * (size_t)b.n * sizeof(double);
	b.a0 = xmalloc(bytes);
	b.a = xmalloc(bytes);
	b.z = xmalloc(bytes);
	b.w = xmalloc((size_t)b.n * sizeof(double));
	b.dsqrt = xmalloc((size_t)b.n * sizeof(double));
	if (reduce(&b))
		return 1;
	printf("eig-dense  every mode of %s (scenes/cuboid-top.scene): %zu nodes, %d free DoFs\n"
	       "eig-dense  OpenBLAS on 2 and 1 threads, the routes alternating; %d round%s\n",
	       b.m.mesh.name, b.m.mesh.n_nodes, b.n, rounds, rounds > 1 ? "s" : "");
	for (int k = 0; k < rounds; k++)
		for (int ti = 0; ti < 2; ti++)
			for (int i = 0; i < R_COUNT; i++) {
				/* dsyevr first in the first round: the reference */
				int r = (i + (k ? k + ti : 1)) % R_COUNT;
				if (sel[r])
					run(&b, (enum route)r, ti, k);
			}
	report(&b, sel, rounds);
	free(b.a0);
	free(b.a);
	free(b.z);
	free(b.w);
	free(b.dsqrt);
	free(b.wref);
	free(b.zref);
	irdm_model_free(&b.m);
	return 0;
}
