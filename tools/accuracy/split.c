/* SPDX-License-Identifier: MIT */
/* A hybrid's force error predicted from the modes (split.h). */
#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy/measure.h"
#include "accuracy/split.h"
#include "irdm/error.h"
#include "modal/mat3c.h"
#include "modal/window.h"

void irdm_split_probe_free(struct irdm_split_probe *p)
{
	free(p->phi);
	free(p->R);
	free(p->F);
	free(p->Rh);
	free(p->Rt);
	free(p->Fh);
	free(p->h);
	free(p->e);
	memset(p, 0, sizeof(*p));
}

/* inv = R0^-1 of a 3x3 (row-major); false when singular. */
static bool inverse3(const double *a, double *inv)
{
	double complex ac[9], adj[9], det;

	for (int i = 0; i < 9; i++)
		ac[i] = a[i];
	det = irdm_det3c(ac);
	if (!(fabs(creal(det)) > 0))
		return false;
	irdm_adj3c(ac, adj);
	for (int i = 0; i < 9; i++)
		inv[i] = creal(adj[i]) / creal(det);
	return true;
}

bool irdm_split_forces(const double *R, size_t N, bool release, double *F)
{
	double inv[9];

	if (!inverse3(R, inv))
		return false;
	for (size_t t = 0; t < N; t++) {
		double b[3] = { 0, 0, 0 };

		F[3 * t] = F[3 * t + 1] = F[3 * t + 2] = 0;
		if (!irdm_measure_active(release, t, N))
			continue;
		for (int a = 0; a < 3; a++)
			b[a] = irdm_measure_held(release, t, N) ? irdm_measure_push_m[a] : 0;
		for (size_t s = 1; s <= t; s++) {
			const double *r = &R[9 * s], *f = &F[3 * (t - s)];
			for (int a = 0; a < 3; a++)
				b[a] -= r[3 * a] * f[0] + r[3 * a + 1] * f[1] + r[3 * a + 2] * f[2];
		}
		for (int a = 0; a < 3; a++)
			F[3 * t + (size_t)a] = inv[3 * a] * b[0] + inv[3 * a + 1] * b[1] + inv[3 * a + 2] * b[2];
	}
	return true;
}

/* R[s] += k phi phi^T x[s] */
static void add_outer(double *R, const double *phi, const double *x, double k, size_t N)
{
	double o[9];

	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
			o[3 * i + j] = k * phi[i] * phi[j];
	for (size_t s = 0; s < N; s++)
		if (x[s] != 0)
			for (int q = 0; q < 9; q++)
				R[9 * s + (size_t)q] += o[q] * x[s];
}

int irdm_split_probe_init(struct irdm_split_probe *p, const struct irdm_modes *m,
			  const struct irdm_mode *zoh, const int64_t *col_dofs, size_t n_cols,
			  size_t N)
{
	size_t n = m->n_modes;

	memset(p, 0, sizeof(*p));
	p->n_cols = n_cols;
	p->n_modes = n;
	p->N = N;
	p->zoh = zoh;
	p->omega2 = m->omega2;
	p->phi = malloc(n * n_cols * 3 * sizeof(double));
	p->R = calloc(n_cols * N * 9, sizeof(double));
	p->F = malloc(n_cols * 2 * N * 3 * sizeof(double));
	p->Rh = malloc(n_cols * N * 9 * sizeof(double));
	p->Rt = malloc(n_cols * N * 9 * sizeof(double));
	p->Fh = malloc(N * 3 * sizeof(double));
	p->h = malloc(N * sizeof(double));
	p->e = malloc(N * sizeof(double));
	if (!p->phi || !p->R || !p->F || !p->Rh || !p->Rt || !p->Fh || !p->h || !p->e) {
		irdm_split_probe_free(p);
		return IRDM_ENOMEM;
	}
	for (size_t d = 0; d < n; d++)
		for (size_t r = 0; r < 3 * n_cols; r++)
			p->phi[3 * n_cols * d + r] = col_dofs[r] < 0 ? 0.0 : m->phi[d * m->n + (size_t)col_dofs[r]];
	for (size_t d = 0; d < n; d++) {
		irdm_zoh_response(&zoh[d], N, p->h);
		for (size_t c = 0; c < n_cols; c++)
			add_outer(&p->R[c * N * 9], &p->phi[3 * (n_cols * d + c)], p->h, 1.0, N);
	}
	for (size_t c = 0; c < n_cols; c++)
		for (int run = 0; run < 2; run++)
			if (!irdm_split_forces(&p->R[c * N * 9], N, run, &p->F[(2 * c + (size_t)run) * N * 3])) {
				irdm_split_probe_free(p);
				return IRDM_EINVAL;
			}
	return IRDM_OK;
}

void irdm_split_miss(const struct irdm_mode *zoh, double omega2, unsigned H, size_t N, double *h,
		     double *e)
{
	double kept = 0, bump_sum = 0, rem;

	irdm_zoh_response(zoh, N, h);
	for (size_t s = 0; s < N; s++)
		e[s] = s < H ? 0.0 : h[s];
	if (!H) { /* no head: the static correction, all of it at R[0] */
		e[0] -= 1.0 / omega2;
		return;
	}
	for (size_t s = 0; s < H && s < N; s++)
		kept += h[s];
	for (size_t i = 0; i < H; i++) {
		bump_sum += irdm_window_bump(i, H);
		if (H + i < N) /* the head's samples past N: the run never sees them */
			kept += h[H + i] * irdm_window_taper(i, H);
	}
	rem = 1.0 / omega2 - kept;
	for (size_t i = 0; i < H && H + i < N; i++)
		e[H + i] = h[H + i] * (1.0 - irdm_window_taper(i, H)) -
			   rem * irdm_window_bump(i, H) / bump_sum;
}

void irdm_split_begin(struct irdm_split_probe *p)
{
	memcpy(p->Rh, p->R, p->n_cols * p->N * 9 * sizeof(double));
}

double irdm_split_try(struct irdm_split_probe *p, const size_t *drop, size_t n_drop, unsigned H)
{
	size_t N = p->N;
	double worst = 0;

	memcpy(p->Rt, p->Rh, p->n_cols * N * 9 * sizeof(double));
	for (size_t i = 0; i < n_drop; i++) {
		size_t d = drop[i];

		irdm_split_miss(&p->zoh[d], p->omega2[d], H, p->N, p->h, p->e);
		for (size_t c = 0; c < p->n_cols; c++)
			add_outer(&p->Rt[c * N * 9], &p->phi[3 * (p->n_cols * d + c)], p->e, -1.0, N);
	}
	for (size_t c = 0; c < p->n_cols; c++)
		for (int run = 0; run < 2; run++) {
			const double *Fr = &p->F[(2 * c + (size_t)run) * N * 3];
			double num = 0, den = 0;

			if (!irdm_split_forces(&p->Rt[c * N * 9], N, run, p->Fh))
				return INFINITY;
			for (size_t k = 0; k < 3 * N; k++) {
				num += (p->Fh[k] - Fr[k]) * (p->Fh[k] - Fr[k]);
				den += Fr[k] * Fr[k];
			}
			worst = fmax(worst, den > 0 ? sqrt(num / den) : 0);
		}
	return worst;
}

void irdm_split_commit(struct irdm_split_probe *p)
{
	double *t = p->Rh;

	p->Rh = p->Rt;
	p->Rt = t;
}
