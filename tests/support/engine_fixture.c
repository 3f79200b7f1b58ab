/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdbool.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "engine_fixture.h"
#include "irdm/posix/image_map.h"
#include "irdm/precision.h"
#include "image/image_response.h"
#include "precompute/precompute.h"

void efx_image(struct irdm_image *img, const char *path, ...)
{
	struct irdm_scene sc;
	struct irdm_precompute_opts o = { .out_path = path };
	struct irdm_precompute_report rep;
	char err[1024];
	va_list ap;

	irdm_scene_defaults(&sc);
	/* the accuracy measurement is what test_measure tests: elsewhere it
	 * would only cost a dense eigensolve per image */
	sc.max_error = 0;
	/* an FIR with the tail its test names (fir_tail = window by name):
	 * these tests run the engine on a given FIR, the precompute's search
	 * for a certified window is test_fir_tail's */
	sc.fir_tail_auto = false;
	va_start(ap, path);
	for (const char *k = va_arg(ap, const char *); k; k = va_arg(ap, const char *)) {
		const char *v = va_arg(ap, const char *);
		if (irdm_scene_set(&sc, k, v, "test", err, sizeof(err)))
			fail_msg("%s", err);
	}
	va_end(ap);
	if (irdm_precompute(&sc, &o, &rep, err, sizeof(err)))
		fail_msg("precompute: %s", err);
	if (irdm_image_map(path, 0, img, err, sizeof(err)))
		fail_msg("map: %s", err);
}

struct irdm_session *efx_session(const struct irdm_image *img, const struct irdm_engine_config *cfg)
{
	struct irdm_session_config sc = { .engine = *cfg };
	const char *portable = getenv("IRDM_TEST_PORTABLE_SUM");
	struct irdm_session *s;
	char err[512];

	/* the spread of a figure across the history sums (make check runs
	 * the stability suite with each): the portable one where AVX2 is */
	if (portable && strcmp(portable, "1") == 0)
		sc.engine.fir_portable_sum = true;

	if (irdm_session_open_image(&s, img, &sc, err, sizeof(err)))
		fail_msg("session: %s", err);
	return s;
}

const double *efx_column_modal(const struct irdm_image *img, size_t c, double *phi, double D[9])
{
	size_t K = img->meta->n_modes, row = img->columns[c];
	long k = irdm_image_corr_block(img, (uint32_t)c, (uint32_t)c);

	for (size_t i = 0; i < 3 * K; i++)
		phi[i] = irdm_elem_get(img->mode_shapes, img->meta->precision, row * 3 * K + i);
	if (!img->corr_start)
		return NULL;
	assert_true(k >= 0);                              /* the diagonal is always kept */
	efx_corr_block(img, (uint32_t)c, (uint32_t)c, D); /* + the far field */
	return D;
}

uint32_t efx_column_row_near(const struct irdm_image *img, const double p[3])
{
	double best = INFINITY;
	uint32_t br = 0;

	for (uint32_t c = 0; c < img->meta->n_cols; c++) {
		uint32_t r = img->columns[c];
		double d = 0;
		for (int a = 0; a < 3; a++)
			d += pow(img->nodes[r].pos_m[a] - p[a], 2);
		if (d < best) {
			best = d;
			br = r;
		}
	}
	return br;
}

double *efx_contact_responses(const struct irdm_image *img, const struct irdm_contact_site *st,
			      int m, size_t N, double tail_r)
{
	int n = 3 * m;
	double *W = calloc(N * (size_t)n * n, sizeof(double));
	double *R = malloc(N * 9 * sizeof(double));

	assert_non_null(W);
	assert_non_null(R);
	for (int i = 0; i < m; i++)
		for (int j = 0; j < m; j++)
			for (uint32_t v = 0; v < st[i].n_nodes; v++)
				for (uint32_t w = 0; w < st[j].n_nodes; w++) {
					double a = st[i].weight[v] * st[j].weight[w];
					if (a == 0 || st[i].col[v] == UINT32_MAX || st[j].col[w] == UINT32_MAX)
						continue;
					/* displacement at v (row) per force at w (column) */
					assert_int_equal(irdm_image_response(img, st[j].col[w], st[i].row[v], N, R), 0);
					double ws = a;
					for (size_t s = 0; s < N; s++, ws *= tail_r)
						for (int r = 0; r < 3; r++)
							for (int c = 0; c < 3; c++)
								W[s * n * n + (size_t)(3 * i + r) * n + 3 * j + c] +=
									ws * R[9 * s + 3 * (size_t)r + (size_t)c];
				}
	free(R);
	return W;
}

int efx_dense_solve(double *a, double *b, int n)
{
	for (int k = 0; k < n; k++) {
		int p = k;
		for (int i = k + 1; i < n; i++)
			if (fabs(a[i * n + k]) > fabs(a[p * n + k]))
				p = i;
		if (fabs(a[p * n + k]) < 1e-300)
			return -1;
		for (int j = 0; j < n; j++) {
			double t = a[k * n + j];
			a[k * n + j] = a[p * n + j];
			a[p * n + j] = t;
		}
		double t = b[k];
		b[k] = b[p];
		b[p] = t;
		for (int i = k + 1; i < n; i++) {
			double f = a[i * n + k] / a[k * n + k];
			for (int j = k; j < n; j++)
				a[i * n + j] -= f * a[k * n + j];
			b[i] -= f * b[k];
		}
	}
	for (int i = n - 1; i >= 0; i--) {
		for (int j = i + 1; j < n; j++)
			b[i] -= a[i * n + j] * b[j];
		b[i] /= a[i * n + i];
	}
	return 0;
}

void efx_reference(const struct irdm_image *img, const struct irdm_contact_site *sites, int m,
		   size_t N, const double *target, double *F)
{
	struct efx_ref_opts o = { .tail_r = 1.0 };

	efx_reference_opts(img, sites, m, N, target, &o, F);
}

void efx_reference_tail(const struct irdm_image *img, const struct irdm_contact_site *sites, int m,
			size_t N, const double *target, double tail_r, double *F)
{
	struct efx_ref_opts o = { .tail_r = tail_r };

	efx_reference_opts(img, sites, m, N, target, &o, F);
}

/* u_k[t] = sum_{s=0}^{t} W[s](k, :) F[t-s]: the contact points' displacement. */
static double disp_at(const double *W, const double *F, int n, size_t t, int k)
{
	double u = 0;

	for (size_t s = 0; s <= t; s++)
		for (int j = 0; j < n; j++)
			u += W[s * n * n + (size_t)k * n + j] * F[(t - s) * n + j];
	return u;
}

/*
 * One tick's system over the active unknowns act[0..na), written from the
 * physics rather than from the engine's algebra: u = W0 F + U~ and, with a
 * coupling, F = k (p - u) + (b/dt) ((p - p') - (u - u')); rigid: u = p.
 * Per vertex: no W0 cross terms between different contacts.
 */
static void tick_system(const double *W, const double *F, const double *target, int n, size_t t,
			const int *act, int na, const struct efx_ref_opts *o, const double *prev,
			double *a, double *rhs)
{
	double bdt = o->b_ns_per_m / (o->dt_s > 0 ? o->dt_s : 1);

	for (int q = 0; q < na; q++) {
		int k = act[q];
		double u = 0, p = target[t * n + k];

		for (size_t s = 1; s <= t; s++)
			for (int j = 0; j < n; j++)
				u += W[s * n * n + (size_t)k * n + j] * F[(t - s) * n + j];
		for (int c = 0; c < na; c++) {
			double w0 = W[(size_t)k * n + act[c]];

			if (o->per_vertex && k / 3 != act[c] / 3)
				w0 = 0;
			a[q * na + c] = o->k_n_per_m > 0 ? (o->k_n_per_m + bdt) * w0 : w0;
		}
		if (o->k_n_per_m > 0) {
			a[q * na + q] += 1.0;
			rhs[q] = o->k_n_per_m * (p - u) + bdt * (p - prev[2 * k] - u + prev[2 * k + 1]);
		} else {
			rhs[q] = p - u;
		}
	}
}

void efx_reference_opts(const struct irdm_image *img, const struct irdm_contact_site *sites, int m,
			size_t N, const double *target, const struct efx_ref_opts *o, double *F)
{
	double *W = efx_contact_responses(img, sites, m, N, o->tail_r);

	efx_reference_w(W, m, N, target, o, F);
	free(W);
}

void efx_reference_w(const double *W, int m, size_t N, const double *target,
		     const struct efx_ref_opts *o, double *F)
{
	int n = 3 * m;
	double prev[24]; /* per unknown: the target and displacement of t-1 */
	bool on[4] = { false }, released[4] = { false };

	assert_true(m <= 4);
	for (size_t t = 0; t < N; t++) {
		double rhs[12], a[144];
		int act[12], na = 0;

		for (int k = 0; k < n; k++)
			F[t * n + k] = 0;
		for (int i = 0; i < m; i++) {
			bool want = !isnan(target[t * n + 3 * i]) && !released[i];
			if (want && !on[i]) /* fresh: no coupling damping yet */
				for (int r = 0; r < 3; r++) {
					int k = 3 * i + r;
					double u = 0;
					for (size_t s = 1; s <= t; s++)
						for (int j = 0; j < n; j++)
							u += W[s * n * n + (size_t)k * n + j] * F[(t - s) * n + j];
					prev[2 * k] = prev[2 * k + 1] = u;
				}
			on[i] = want;
		}
		for (int pass = 0; pass <= m; pass++) {
			int dropped = 0;

			na = 0;
			for (int i = 0; i < m; i++)
				if (on[i])
					for (int r = 0; r < 3; r++)
						act[na++] = 3 * i + r;
			if (!na)
				break;
			tick_system(W, F, target, n, t, act, na, o, prev, a, rhs);
			assert_int_equal(efx_dense_solve(a, rhs, na), 0);
			for (int q = 0; q < na; q++)
				F[t * n + act[q]] = rhs[q];
			/* a push contact that would pull the tool lets go */
			for (int i = 0; i < m && o->push; i++) {
				const double *f = &F[t * n + 3 * i], *nr = &o->normal[3 * i];
				if (on[i] && f[0] * nr[0] + f[1] * nr[1] + f[2] * nr[2] > 0) {
					on[i] = false;
					released[i] = true;
					dropped = 1;
				}
			}
			if (!dropped)
				break;
			for (int k = 0; k < n; k++)
				F[t * n + k] = 0;
		}
		for (int i = 0; i < m; i++)
			for (int r = 0; on[i] && r < 3; r++) {
				int k = 3 * i + r;
				prev[2 * k] = target[t * n + k];
				prev[2 * k + 1] = disp_at(W, F, n, t, k);
			}
	}
}

void efx_step_release(size_t N, size_t release, double dz,
		      void (*check)(const char *what, const double *target))
{
	double *u = calloc(N * 3, sizeof(double));

	assert_non_null(u);
	for (size_t t = 0; t < N; t++)
		u[3 * t + 2] = dz;
	check("step", u);
	for (size_t t = release; t < N; t++)
		u[3 * t] = u[3 * t + 1] = u[3 * t + 2] = NAN;
	check("release", u);
	free(u);
}

double efx_rel_rms(const double *a, const double *b, size_t n)
{
	double d = 0, r = 0;

	for (size_t i = 0; i < n; i++) {
		d += (a[i] - b[i]) * (a[i] - b[i]);
		r += b[i] * b[i];
	}
	return sqrt(d / r);
}

void efx_corr_block(const struct irdm_image *img, uint32_t col_force, uint32_t col_disp,
		    double blk[9])
{
	uint32_t prec = img->meta ? img->meta->precision : 0;
	size_t r = img->corr_rank;

	memset(blk, 0, 9 * sizeof(double));
	for (uint32_t k = img->corr_start ? img->corr_start[col_force] : 0;
	     img->corr_start && k < img->corr_start[col_force + 1]; k++)
		if (img->corr_rows[k] == col_disp)
			for (size_t e = 0; e < 9; e++)
				blk[e] = irdm_image_value(img, img->corr_blocks, col_force, (size_t)k * 9 + e);
	for (size_t i = 0; i < 3; i++)
		for (size_t j = 0; j < 3; j++)
			for (size_t k = 0; k < r; k++)
				blk[3 * i + j] += irdm_elem_get(img->corr_lambda, prec, k) *
						  irdm_elem_get(img->corr_u, prec, (3 * (size_t)col_disp + i) * r + k) *
						  irdm_elem_get(img->corr_u, prec, (3 * (size_t)col_force + j) * r + k);
}
