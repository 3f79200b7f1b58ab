/* SPDX-License-Identifier: MIT */
/*
 * Can a hybrid's head come without every mode?  The head is the dropped
 * modes' response over 2H samples (modal/exact_head.h):
 *   D_s = M^-1/2 P h_s(A) P M^-1/2,  A = M^-1/2 K M^-1/2 (lumped M),
 * P the projector off the kept modes, h_s the zero-order-hold response of
 * a mode at sample s as a function of its eigenvalue.  A Lanczos run on A
 * from P M^-1/2 e_j gives h_s(A) for every s at once from m products with
 * K and the kept modes alone (no dense eigensolve), as the paper's scale
 * needs.  This measures, on the default scene (scenes/cuboid-top.scene,
 * 9504 DoFs, the 275 modes auto keeps there, H = 128 at 1 ms), how far
 * each column's own block of that head is from the exact one (summed here
 * from every mode of a dense eigensolve) after m steps, at six columns
 * spread over the touchable face: the largest |D_s - D_s,exact|_F over
 * the 2H samples, relative to the largest |D_s,exact|_F, and the seconds
 * a column's three runs took (full reorthogonalisation: a prototype's
 * cost, not a production one's).  Then what that does to a grab held at
 * each of those columns for 1000 ticks (direct convolution, the kept
 * modes exact at every sample): the relative RMS difference of the
 * forces with the head from m steps against those with the exact head.
 * The head is not tapered here (the image's is, past H): the difference
 * is the Lanczos run's alone.
 *
 * IRDM_BENCH_KEPT (default 275) and IRDM_BENCH_H (default 128) change the
 * split.  Then the same with the plain three-term recurrence, only its
 * start vector projected off the kept modes, to 1000 steps (no
 * reorthogonalisation: a cost linear in m).  Last, what the precompute
 * runs (modal/krylov_head.c): a Chebyshev series in A per axis, cut
 * where the coefficients it drops sum to tol of the largest dropped
 * response, for tol from 1e-2 to 1e-10: its terms, the same two figures
 * and the seconds.  Prints figures ("-": past a way's steps); fails only
 * if the model cannot be built.
 * Run from the repository root.
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "modal/krylov_head.h"
#include "modal/lapack.h"
#include "modal/modal.h"
#include "modal/response.h"
#include "precompute/model.h"
#include "scene/scene.h"
#include "../support/bench_util.h"
#include "../support/solve3.h"

void dstev_(const char *jobz, const int *n, double *d, double *e, double *z, const int *ldz,
	    double *work, int *info);

#define N_COLS 6
#define M_MAX 1000 /* the plain recurrence's steps */
#define M_FULL 600 /* full reorthogonalisation's: its cost grows as m^2 */
static const size_t checkpoints[] = { 200, 400, 600, 800, 1000 };
#define N_CHECK (sizeof(checkpoints) / sizeof(checkpoints[0]))

struct kh {
	struct irdm_model m;
	struct irdm_scene sc;
	size_t n, kept, S;
	int plain;                 /* the three-term recurrence alone, as krylov_head.c runs it */
	double *dinv;              /* M^-1/2 diagonal */
	double *psi;               /* kept modes, M^1/2 phi: n x kept */
	struct irdm_mode *zoh_all; /* every mode discretised */
};

static void *xcalloc(size_t n, size_t size)
{
	void *p = calloc(n, size);

	if (!p) {
		fprintf(stderr, "krylov-head: out of memory\n");
		exit(1);
	}
	return p;
}

static size_t env_size(const char *name, size_t dflt)
{
	const char *v = getenv(name);

	return v ? (size_t)strtoul(v, NULL, 10) : dflt;
}

/* y = A x = M^-1/2 K M^-1/2 x */
static void apply_a(const struct kh *k, const double *x, double *tmp, double *y)
{
	for (size_t i = 0; i < k->n; i++)
		tmp[i] = k->dinv[i] * x[i];
	irdm_csc_matvec(&k->m.fem.K, tmp, y);
	for (size_t i = 0; i < k->n; i++)
		y[i] *= k->dinv[i];
}

/* x -= B (B^T x) for B n x nb column-major */
static void orth_against(const double *B, size_t n, size_t nb, double *x)
{
	for (size_t j = 0; j < nb; j++) {
		const double *b = &B[j * n];
		double d = 0;

		for (size_t i = 0; i < n; i++)
			d += b[i] * x[i];
		for (size_t i = 0; i < n; i++)
			x[i] -= d * b[i];
	}
}

/* out[s][i] (3 x S): rows dof[0..2] of M^-1/2 beta0 V f_s(T_m) e1. */
static int ritz_head(const struct kh *k, const double *V, const double *alpha, const double *beta,
		     size_t m, double beta0, const int64_t *dof, double *out)
{
	int mi = (int)m, info;
	double *d = xcalloc(m, sizeof(double)), *e = xcalloc(m, sizeof(double));
	double *z = xcalloc(m * m, sizeof(double)), *work = xcalloc(2 * m + 2, sizeof(double));
	double *h = xcalloc(m * k->S, sizeof(double));
	struct irdm_modes ritz = { .n = 0, .n_modes = m };
	struct irdm_mode *zoh = xcalloc(m, sizeof(*zoh));
	bool *spurious = xcalloc(m, sizeof(bool));

	memcpy(d, alpha, m * sizeof(double));
	memcpy(e, beta, (m - 1) * sizeof(double));
	dstev_("V", &mi, d, e, z, &mi, work, &info);
	if (info) {
		fprintf(stderr, "krylov-head: dstev info %d\n", info);
		goto out;
	}

	/* a Ritz value below the highest kept mode is one of the kept modes
	 * that rounding brought back: no weight (as modal/krylov_head.c) */
	for (size_t l = 0; l < m; l++) {
		spurious[l] = d[l] <= (1 - 1e-6) * k->m.modes.omega2[k->kept - 1];
		d[l] = spurious[l] ? k->m.modes.omega2[k->kept - 1] : d[l];
	}
	ritz.omega2 = d;
	irdm_modes_discretise(&ritz, &k->m.damping, k->sc.dt_s, zoh);
	for (size_t l = 0; l < m; l++)
		irdm_zoh_response(&zoh[l], k->S, &h[l * k->S]);
	for (int i = 0; i < 3; i++) {
		/* (V Q)_{dof,l} Q_{0,l} */
		for (size_t l = 0; l < m; l++) {
			double vq = 0;

			for (size_t t = 0; t < m; t++)
				vq += V[t * k->n + (size_t)dof[i]] * z[l * m + t];
			vq *= spurious[l] ? 0.0 : z[l * m] * beta0 * k->dinv[dof[i]];
			for (size_t s = 0; s < k->S; s++)
				out[s * 3 + (size_t)i] += vq * h[l * k->S + s];
		}
	}
out:
	free(spurious);
	free(d);
	free(e);
	free(z);
	free(work);
	free(h);
	free(zoh);
	return info;
}

#define T_RUN 1000 /* ticks of the step run */

/* out[s][i][j], s < T: modes first .. first + count - 1's response at
 * column dof (irdm_fir_from_modes() on a view of those modes). */
static void blocks_of(const struct kh *k, size_t first, size_t count, const int64_t *dof, size_t T,
		      double *out)
{
	struct irdm_modes v = k->m.modes;

	v.n_modes = count;
	v.omega2 += first;
	v.phi += first * k->n;
	if (irdm_fir_from_modes(&v, &k->zoh_all[first], dof, 1, dof, 1, T, NULL, out, NULL, NULL)) {
		fprintf(stderr, "krylov-head: out of memory\n");
		exit(1);
	}
}

/* |B|_F of a 3x3 block, or of a - b. */
static double frob(const double *a, const double *b)
{
	double f = 0;

	for (int q = 0; q < 9; q++)
		f += (a[q] - (b ? b[q] : 0)) * (a[q] - (b ? b[q] : 0));
	return sqrt(f);
}

/*
 * The grab's forces f[t] (3 each) for a displacement held at x from tick
 * 0: sum_{s <= t} R[s] f[t - s] = x, R[s] = kept[s] + head[s] (head zero
 * from S on), solved by direct convolution.
 */
static void grab(const double *kept, const double *head, size_t S, double *f)
{
	static const double x[3] = { 0.3e-3, 0.2e-3, -0.93e-3 };

	for (size_t t = 0; t < T_RUN; t++) {
		double r[3] = { x[0], x[1], x[2] }, R0[9];

		for (size_t s = 1; s <= t; s++)
			for (int i = 0; i < 3; i++)
				for (int j = 0; j < 3; j++)
					r[i] -= (kept[s * 9 + 3 * i + j] + (s < S ? head[s * 9 + 3 * i + j] : 0)) *
						f[(t - s) * 3 + (size_t)j];
		for (int q = 0; q < 9; q++)
			R0[q] = kept[q] + head[q];
		ts_solve3(R0, r, &f[t * 3]);
	}
}

/* Relative RMS difference of two runs' forces. */
static double rel_rms(const double *f, const double *ref)
{
	double num = 0, den = 0;

	for (size_t i = 0; i < 3 * T_RUN; i++) {
		num += (f[i] - ref[i]) * (f[i] - ref[i]);
		den += ref[i] * ref[i];
	}
	return sqrt(num / den);
}

/* ferr[i]: the grab at dof through head i of the n_heads in ap against
 * the one through the exact head (ex), the kept modes exact. */
static void force_errors(const struct kh *k, const int64_t *dof, const double *ex,
			 const double *ap, size_t n_heads, double *ferr)
{
	double *kept = xcalloc(T_RUN * 9, sizeof(double));
	double *f_ex = xcalloc(T_RUN * 3, sizeof(double)), *f_ap = xcalloc(T_RUN * 3, sizeof(double));

	blocks_of(k, 0, k->kept, dof, T_RUN, kept);
	grab(kept, ex, k->S, f_ex);
	for (size_t i = 0; i < n_heads; i++) {
		grab(kept, &ap[i * k->S * 9], k->S, f_ap);
		ferr[i] = rel_rms(f_ap, f_ex);
	}
	free(kept);
	free(f_ex);
	free(f_ap);
}

/*
 * Axis j of column dof: m Lanczos steps on A from P M^-1/2 e_j, and at
 * each checkpoint ci the head's column j into ap[ci][s][i][j].  V holds
 * M_MAX + 1 vectors of n, w and tmp n each.
 */
static void lanczos_axis(const struct kh *k, const int64_t *dof, int j, double *V, double *w,
			 double *tmp, double *ap)
{
	size_t n = k->n, S = k->S, ci = 0;
	double alpha[M_MAX], beta[M_MAX], beta0 = 0;

	memset(V, 0, n * sizeof(double));
	V[dof[j]] = k->dinv[dof[j]];
	orth_against(k->psi, n, k->kept, V);
	orth_against(k->psi, n, k->kept, V); /* twice, as the precompute */
	for (size_t i = 0; i < n; i++)
		beta0 += V[i] * V[i];
	beta0 = sqrt(beta0);
	for (size_t i = 0; i < n; i++)
		V[i] /= beta0;
	for (size_t t = 0; t < (k->plain ? M_MAX : M_FULL); t++) {
		double *v = &V[t * n], *vn = &V[(t + 1) * n], a = 0, b = 0;

		apply_a(k, v, tmp, w);
		for (size_t i = 0; i < n; i++)
			a += w[i] * v[i];
		alpha[t] = a;
		memcpy(vn, w, n * sizeof(double));
		if (k->plain) {
			/* the three-term recurrence: only the start vector was
			 * projected off the kept modes (modal/krylov_head.c) */
			for (size_t i = 0; i < n; i++)
				vn[i] -= a * v[i] + (t ? beta[t - 1] * V[(t - 1) * n + i] : 0);
		} else {
			/* full: against the kept modes and every earlier vector, twice */
			for (int pass = 0; pass < 2; pass++) {
				orth_against(k->psi, n, k->kept, vn);
				orth_against(V, n, t + 1, vn);
			}
		}
		for (size_t i = 0; i < n; i++)
			b += vn[i] * vn[i];
		beta[t] = sqrt(b);
		for (size_t i = 0; i < n; i++)
			vn[i] /= beta[t];
		if (ci < N_CHECK && t + 1 == checkpoints[ci]) {
			double *o = xcalloc(S * 3, sizeof(double));

			if (!ritz_head(k, V, alpha, beta, t + 1, beta0, dof, o))
				for (size_t s = 0; s < S; s++)
					for (int i = 0; i < 3; i++)
						ap[(ci * S + s) * 9 + 3 * i + j] = o[s * 3 + i];
			free(o);
			ci++;
		}
	}
}

/* Column c: the relative error at each checkpoint and the seconds. */
static void column(const struct kh *k, size_t c, double err[N_CHECK], double ferr[N_CHECK],
		   double *secs)
{
	const int64_t *dof = &k->m.col_dofs[3 * c];
	size_t n = k->n, S = k->S;
	double *V = xcalloc(n * (M_MAX + 1), sizeof(double)), *w = xcalloc(n, sizeof(double));
	double *tmp = xcalloc(n, sizeof(double));
	double *ex = xcalloc(S * 9, sizeof(double)), *ap = xcalloc(N_CHECK * S * 9, sizeof(double));
	double peak = 0, t0;

	blocks_of(k, k->kept, k->m.modes.n_modes - k->kept, dof, S, ex); /* exact: every dropped mode */
	for (size_t s = 0; s < S; s++)
		peak = fmax(peak, frob(&ex[s * 9], NULL));
	t0 = bench_now_us();
	for (int j = 0; j < 3; j++)
		lanczos_axis(k, dof, j, V, w, tmp, ap);
	*secs = (bench_now_us() - t0) * 1e-6;
	force_errors(k, dof, ex, ap, N_CHECK, ferr);
	for (size_t ci = 0; ci < N_CHECK; ci++) {
		double worst = 0;

		for (size_t s = 0; s < S; s++)
			worst = fmax(worst, frob(&ap[(ci * S + s) * 9], &ex[s * 9]));
		err[ci] = worst / peak;
	}
	free(V);
	free(w);
	free(tmp);
	free(ex);
	free(ap);
}

static int build(struct kh *k)
{
	char err[512];
	size_t n;

	irdm_scene_defaults(&k->sc);
	if (irdm_scene_load(&k->sc, "scenes/cuboid-top.scene", err, sizeof(err)) ||
	    irdm_model_build(&k->sc, 0, NULL, NULL, &k->m, err, sizeof(err))) {
		fprintf(stderr, "krylov-head: %s\n", err);
		return -1;
	}
	n = k->n = k->m.modes.n;
	if (!k->kept || k->kept >= k->m.modes.n_modes) {
		fprintf(stderr, "krylov-head: IRDM_BENCH_KEPT=%zu: expected 1 to %zu\n", k->kept,
			k->m.modes.n_modes - 1);
		return -1;
	}
	{
		int64_t *all = xcalloc(n, sizeof(int64_t));

		for (size_t i = 0; i < n; i++)
			all[i] = (int64_t)i;
		/* every mode whole: the exact head and the kept projector read them */
		if (irdm_modes_complete(&k->m.modes, 0, k->m.modes.n_modes, all, n, err,
					sizeof(err))) {
			fprintf(stderr, "krylov-head: %s\n", err);
			free(all);
			return -1;
		}
		free(all);
	}
	if (k->m.fem.M.nnz != n) {
		fprintf(stderr, "krylov-head: the scene's mass is not lumped\n");
		return -1;
	}
	k->dinv = xcalloc(n, sizeof(double));
	for (size_t i = 0; i < n; i++)
		k->dinv[i] = 1 / sqrt(k->m.fem.M.val[k->m.fem.M.colptr[i]]);
	k->psi = xcalloc(n * k->kept, sizeof(double));
	for (size_t d = 0; d < k->kept; d++)
		for (size_t i = 0; i < n; i++)
			k->psi[d * n + i] = k->m.modes.phi[d * n + i] / k->dinv[i];
	k->zoh_all = xcalloc(k->m.modes.n_modes, sizeof(*k->zoh_all));
	irdm_modes_discretise(&k->m.modes, &k->m.damping, k->sc.dt_s, k->zoh_all);
	return 0;
}

static size_t steps_of(const struct kh *k)
{
	return k->plain ? M_MAX : M_FULL;
}

/* One row's figures, "-" past the way's steps; worst[] takes them in. */
static void print_row(const struct kh *k, const double *e, double *worst)
{
	for (size_t ci = 0; ci < N_CHECK; ci++) {
		if (checkpoints[ci] > steps_of(k)) {
			printf("  %-10s", "-");
			continue;
		}
		printf("  %-10.3g", e[ci]);
		if (worst)
			worst[ci] = fmax(worst[ci], e[ci]);
	}
}

/* Both tables for one way of running Lanczos (k->plain). */
static void run(struct kh *k)
{
	double worst[N_CHECK] = { 0 }, fworst[N_CHECK] = { 0 }, ferrs[N_COLS][N_CHECK];
	double secs_sum = 0;

	printf("krylov-head  %s: per column, max_s |D_s - D_s,exact|_F / max_s |D_s,exact|_F of its own block after m Lanczos steps per axis\n",
	       k->plain ? "plain three-term recurrence, the start vector projected off the kept modes" :
			  "full reorthogonalisation");
	printf("krylov-head  %-8s %-10s", "column", "mesh node");
	for (size_t ci = 0; ci < N_CHECK; ci++)
		printf("  m = %-6zu", checkpoints[ci]);
	printf("  seconds (3 x %zu steps)\n", steps_of(k));
	for (int q = 0; q < N_COLS; q++) {
		size_t c = (size_t)q * (k->m.n_cols - 1) / (N_COLS - 1);
		double e[N_CHECK], secs;

		column(k, c, e, ferrs[q], &secs);
		secs_sum += secs;
		printf("krylov-head  %-8zu %-10u", c, k->m.rows[k->m.cols[c]]);
		print_row(k, e, worst);
		printf("  %.2f\n", secs);
		fflush(stdout);
	}
	printf("krylov-head  %-19s", "worst");
	print_row(k, worst, NULL);
	printf("  %.2f per column\n", secs_sum / N_COLS);
	printf("krylov-head  the same columns' grab (held 1 mm along (0.3, 0.2, -0.93), %d ticks, the kept modes exact at every sample): relative RMS force difference, the head from m steps against the exact head\n",
	       T_RUN);
	for (int q = 0; q < N_COLS; q++) {
		size_t c = (size_t)q * (k->m.n_cols - 1) / (N_COLS - 1);

		printf("krylov-head  %-8zu %-10u", c, k->m.rows[k->m.cols[c]]);
		print_row(k, ferrs[q], fworst);
		printf("\n");
	}
	printf("krylov-head  %-19s", "worst");
	print_row(k, fworst, NULL);
	printf("\n");
	fflush(stdout);
}

/* The precompute's way at tol: the six columns' own blocks over 2H
 * samples, all computed exactly (the library tapers past its H: asked
 * for a head of 2H, 2H samples computed). */
static const double cheb_tols[] = { 1e-2, 1e-4, 1e-6, 1e-8, 1e-10 };
#define N_TOL (sizeof(cheb_tols) / sizeof(cheb_tols[0]))

static void cheb_run(const struct kh *k, double tol, const int64_t *dofs, double *head,
		     struct irdm_krylov_head_stats *st, double *secs)
{
	uint32_t index[2 * N_COLS + 1];
	struct irdm_corr_sparse corr = { .n_cols = N_COLS, .n_blocks = N_COLS, .start = index, .rows = &index[N_COLS + 1] };
	struct irdm_modes kept = k->m.modes;
	struct irdm_krylov_head_opts o = { tol, IRDM_KRYLOV_HEAD_MAX_TERMS, 1, k->S };
	double *target = xcalloc(N_COLS * 9, sizeof(double));
	char err[256];
	double t0 = bench_now_us();

	for (uint32_t c = 0; c <= N_COLS; c++)
		index[c] = c;
	for (uint32_t c = 0; c < N_COLS; c++)
		corr.rows[c] = c;
	kept.n_modes = k->kept;
	if (irdm_krylov_head(&k->m.fem, &kept, &k->m.damping, k->sc.dt_s, dofs, &corr, target, k->S,
			     &o, NULL, NULL, head, st, err, sizeof(err))) {
		fprintf(stderr, "krylov-head: %s\n", err);
		exit(1);
	}
	*secs = (bench_now_us() - t0) * 1e-6;
	free(target);
}

static void cheb_table(const struct kh *k)
{
	int64_t dofs[3 * N_COLS];
	double *head = xcalloc(N_COLS * 2 * k->S * 9, sizeof(double));
	double *ex = xcalloc(k->S * 9, sizeof(double)), lam_up = 0;

	for (int q = 0; q < N_COLS; q++)
		memcpy(&dofs[3 * q], &k->m.col_dofs[3 * ((size_t)q * (k->m.n_cols - 1) / (N_COLS - 1))],
		       3 * sizeof(int64_t));
	printf("krylov-head  Chebyshev series, the precompute's way (modal/krylov_head.c): per tol, its terms, the worst of the six columns' own-block error and grab difference as above, and the seconds per column (six columns in one batch, one thread)\n");
	printf("krylov-head  %-8s %-8s %-12s %-12s %-12s %s\n", "tol", "terms", "left at most",
	       "own block", "grab", "seconds");
	for (size_t ti = 0; ti < N_TOL; ti++) {
		struct irdm_krylov_head_stats st;
		double secs, worst = 0, fworst = 0;

		cheb_run(k, cheb_tols[ti], dofs, head, &st, &secs);
		lam_up = st.lam_up;
		for (int q = 0; q < N_COLS; q++) {
			double peak = 0, e = 0, ferr;

			blocks_of(k, k->kept, k->m.modes.n_modes - k->kept, &dofs[3 * q], k->S, ex);
			for (size_t s = 0; s < k->S; s++) {
				peak = fmax(peak, frob(&ex[s * 9], NULL));
				e = fmax(e, frob(&head[((size_t)q * 2 * k->S + s) * 9], &ex[s * 9]));
			}
			force_errors(k, &dofs[3 * q], ex, &head[(size_t)q * 2 * k->S * 9], 1, &ferr);
			worst = fmax(worst, e / peak);
			fworst = fmax(fworst, ferr);
		}
		printf("krylov-head  %-8.0e %-8zu %-12.2g %-12.3g %-12.3g %.2f\n", cheb_tols[ti],
		       st.terms, st.tail, worst, fworst, secs / N_COLS);
		fflush(stdout);
	}
	printf("krylov-head  the series' interval: up to w = %.5g rad/s (Gershgorin's bound); the highest mode of the dense eigensolve: %.5g rad/s\n",
	       sqrt(lam_up), sqrt(k->m.modes.omega2[k->m.modes.n_modes - 1]));
	free(head);
	free(ex);
}

int main(void)
{
	struct kh k = { .kept = env_size("IRDM_BENCH_KEPT", 275) };
	size_t H = env_size("IRDM_BENCH_H", 128);
	double t0 = bench_now_us();

	k.S = 2 * H;
	if (!H || H > 4096) {
		fprintf(stderr, "krylov-head: IRDM_BENCH_H=%zu: expected 1 to 4096\n", H);
		return 1;
	}
	if (build(&k))
		return 1;
	printf("krylov-head  scenes/cuboid-top.scene: %zu free DoFs, %zu modes, %zu kept (the lowest: under Rayleigh damping the longest ringing), head H = %zu (2H = %zu samples compared), dt %g s; model and dense eigensolve %.1f s\n",
	       k.n, k.m.modes.n_modes, k.kept, H, k.S, k.sc.dt_s, (bench_now_us() - t0) * 1e-6);
	for (k.plain = 0; k.plain < 2; k.plain++)
		run(&k);
	cheb_table(&k);
	return 0;
}
