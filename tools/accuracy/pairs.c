/* SPDX-License-Identifier: MIT */
/* Two contacts at once against the exact model (pairs.h). */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy/col_resp.h"
#include "accuracy/measure.h"
#include "accuracy/pairs.h"
#include "accuracy/run.h"
#include "modal/lapack.h"
#include "util/clock.h"

/* R[(s D + r) D + q], D = 3n: the exact response at the n columns,
 * every pair of them, summed mode by mode. */
static int exact_blocks(const struct irdm_modes *m, const struct irdm_mode *zoh,
			const int64_t *col_dofs, const uint32_t *cols, size_t n, size_t N, double *R)
{
	size_t D = 3 * n;
	double *h = malloc(N * sizeof(double)), p[3 * IRDM_PAIRS_COLS];

	if (!h)
		return IRDM_ENOMEM;
	memset(R, 0, N * D * D * sizeof(double));
	for (size_t d = 0; d < m->n_modes; d++) {
		size_t L;

		for (size_t r = 0; r < D; r++) {
			int64_t dof = col_dofs[3 * (size_t)cols[r / 3] + r % 3];
			p[r] = dof < 0 ? 0.0 : m->phi[d * m->n + (size_t)dof];
		}
		irdm_zoh_response(&zoh[d], N, h);
		L = irdm_col_resp_alive_len(h, N);
		for (size_t s = 0; s < L; s++)
			for (size_t r = 0; r < D; r++) {
				double ph = p[r] * h[s];
				double *row = &R[(s * D + r) * D];
				for (size_t q = 0; q < D; q++)
					row[q] += ph * p[q];
			}
	}
	free(h);
	return IRDM_OK;
}

/* The pair (i, j)'s 6x6 R[s] out of the n columns' R. */
static void pair_sample(const double *R, size_t D, size_t s, size_t i, size_t j, double out[36])
{
	size_t at[6] = { 3 * i, 3 * i + 1, 3 * i + 2, 3 * j, 3 * j + 1, 3 * j + 2 };

	for (int r = 0; r < 6; r++)
		for (int q = 0; q < 6; q++)
			out[6 * r + q] = R[(s * D + at[r]) * D + at[q]];
}

/*
 * The exact forces of pair (i, j), both grabbed and pushed alike: F
 * (N x 6) solved tick by tick from the history.  Rp: scratch, N x 36.
 */
static bool exact_forces(const double *R, size_t D, size_t i, size_t j, size_t N, bool release,
			 double *Rp, double *F)
{
	double inv[36] = { 0 }, A[36];
	int six = 6, ipiv[6], info;

	for (size_t s = 0; s < N; s++)
		pair_sample(R, D, s, i, j, &Rp[36 * s]);
	memcpy(A, Rp, sizeof(A));
	for (int k = 0; k < 6; k++)
		inv[7 * k] = 1;
	/* column-major: A is R[0]^T, so inv[6 a + q] = R[0]^-1 [a][q] */
	dgesv_(&six, &six, A, &six, ipiv, inv, &six, &info);
	if (info)
		return false;
	for (size_t t = 0; t < N; t++) {
		double b[6];

		memset(&F[6 * t], 0, 6 * sizeof(double));
		if (!irdm_measure_active(release, t, N))
			continue;
		for (int a = 0; a < 6; a++)
			b[a] = irdm_measure_held(release, t, N) ? irdm_measure_push_m[a % 3] : 0;
		for (size_t s = 1; s <= t; s++) {
			const double *r = &Rp[36 * s], *f = &F[6 * (t - s)];
			for (int a = 0; a < 6; a++)
				for (int q = 0; q < 6; q++)
					b[a] -= r[6 * a + q] * f[q];
		}
		for (int a = 0; a < 6; a++)
			for (int q = 0; q < 6; q++)
				F[6 * t + (size_t)a] += inv[6 * a + q] * b[q];
	}
	return true;
}

struct work {
	double *R, *Rp, *Fref, *F;
	struct irdm_report_cmd *one, *two;
	struct irdm_report_runner *run;
};

/* Pair (i, j), both runs, into res. */
static int measure_pair(const struct irdm_image *img, struct work *w, const uint32_t *cols,
			size_t n, size_t i, size_t j, size_t N, struct irdm_pairs *res, char *err,
			size_t errlen)
{
	for (int release = 0; release < 2; release++) {
		uint32_t c[2] = { cols[i], cols[j] };
		bool faulted;
		double e;
		int ret;

		if (!exact_forces(w->R, 3 * n, i, j, N, release, w->Rp, w->Fref)) {
			snprintf(err, errlen, "pairs: the exact R[0] of mesh nodes %u and %u is singular",
				 img->nodes[img->columns[c[0]]].mesh_node,
				 img->nodes[img->columns[c[1]]].mesh_node);
			return IRDM_EINVAL;
		}
		for (int k = 0; k < 2; k++) {
			irdm_measure_cmds(release, img->columns[c[k]], N, w->one);
			for (size_t t = 0; t < N; t++)
				w->two[2 * t + (size_t)k] = w->one[t];
		}
		ret = irdm_report_runner_run(w->run, w->two, N, w->F, &faulted, err, errlen);
		if (ret)
			return ret;
		e = faulted ? INFINITY : irdm_measure_rel_rms(w->F, w->Fref, 6 * N);
		if (!(e <= res->worst)) {
			res->worst = e;
			res->run = release ? "release" : "step";
			for (int k = 0; k < 2; k++)
				res->nodes[k] = img->nodes[img->columns[c[k]]].mesh_node;
		}
	}
	res->n_pairs++;
	return IRDM_OK;
}

int irdm_pairs_measure(const struct irdm_image *img, const struct irdm_modes *m,
		       const struct irdm_mode *zoh, const int64_t *col_dofs, const uint32_t *cols,
		       size_t n, struct irdm_pairs *res, char *err, size_t errlen)
{
	size_t N = irdm_measure_ticks(img->meta->dt_s), D = 3 * n;
	struct work w = { 0 };
	double t0 = irdm_now_s();
	int ret = IRDM_EINVAL;

	memset(res, 0, sizeof(*res));
	res->worst = -1;
	res->ticks = N;
	if (img->rigid || n < 2 || n > IRDM_PAIRS_COLS) {
		snprintf(err, errlen, "pairs: %s", img->rigid ? "a floating object's exact model has rigid motion: not measured" : "2 to 8 columns are measured by pairs");
		return ret;
	}
	ret = IRDM_ENOMEM;
	w.R = malloc(N * D * D * sizeof(double));
	w.Rp = malloc(N * 36 * sizeof(double));
	w.Fref = malloc(N * 6 * sizeof(double));
	w.F = malloc(N * 6 * sizeof(double));
	w.one = malloc(N * sizeof(*w.one));
	w.two = malloc(2 * N * sizeof(*w.two));
	if (!w.R || !w.Rp || !w.Fref || !w.F || !w.one || !w.two ||
	    exact_blocks(m, zoh, col_dofs, cols, n, N, w.R)) {
		snprintf(err, errlen, "pairs: out of memory");
		goto out;
	}
	ret = irdm_report_runner_open(&w.run, img, 2, err, errlen);
	for (size_t i = 0; i < n && !ret; i++)
		for (size_t j = i + 1; j < n && !ret; j++)
			ret = measure_pair(img, &w, cols, n, i, j, N, res, err, errlen);
	irdm_report_runner_close(w.run);
out:
	free(w.R);
	free(w.Rp);
	free(w.Fref);
	free(w.F);
	free(w.one);
	free(w.two);
	res->seconds = irdm_now_s() - t0;
	return ret;
}
