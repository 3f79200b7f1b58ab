/* SPDX-License-Identifier: MIT */
/* Images and engines for the engine tests, and the brute-force reference. */
#ifndef IRDM_TESTS_ENGINE_FIXTURE_H
#define IRDM_TESTS_ENGINE_FIXTURE_H

#include "irdm/engine.h"
#include "irdm/image.h"
#include "irdm/session.h"

/* Build an image with the library from "key=value" pairs (NULL-terminated),
 * map it.  Aborts the test on failure.  Unlike a scene's defaults, no
 * max_error and no fir_tail unless the pairs name them. */
void efx_image(struct irdm_image *img, const char *path, ...);

/* A session (engine only) on img, which it borrows; aborts the test on
 * failure.  irdm_session_close() frees it.  IRDM_TEST_PORTABLE_SUM=1
 * forces the portable history sums (cfg.fir_portable_sum): make
 * test-variants runs the stability suite so, to catch a figure that only
 * one sum's rounding meets. */
struct irdm_session *efx_session(const struct irdm_image *img, const struct irdm_engine_config *cfg);

/*
 * Brute-force reference: forces at contact sites (fixed per run, m sites)
 * for prescribed displacements of the contact points, by direct double
 * convolution  sum_{s=0}^{t} W[s] F[t-s] = U[t]  with W[s] assembled from
 * R[s] blocks read back from the image (tools/image/image_response.c).
 * target: N x 3m (NAN = released), F_out: N x 3m.
 */
void efx_reference(const struct irdm_image *img, const struct irdm_contact_site *sites, int m,
		   size_t N, const double *target, double *F_out);

/* The same with every R[s] weighted by tail_r^s (an FIR image's tail as a
 * stabilised engine uses it; tail_r = 1: as recorded). */
void efx_reference_tail(const struct irdm_image *img, const struct irdm_contact_site *sites, int m,
			size_t N, const double *target, double tail_r, double *F);

/*
 * The reference with the engine's other modes, each restated from its
 * physics: a virtual coupling k, b (F = k (p - u) + b (dp - du) / dt; k = 0:
 * rigid), the paper's per-vertex solve (no R[0] cross terms between
 * contacts: node sites only), push contacts (normal[3 i..]: outward; a
 * contact whose force would pull the tool, F . n > 0, lets go for good),
 * and the FIR tail weight.
 */
struct efx_ref_opts {
	double tail_r;
	int per_vertex;
	double k_n_per_m, b_ns_per_m, dt_s;
	int push;
	const double *normal;
};
void efx_reference_opts(const struct irdm_image *img, const struct irdm_contact_site *sites, int m,
			size_t N, const double *target, const struct efx_ref_opts *o, double *F);

/* W[s] (3m x 3m, row-major per s; rows: displacement of site i axis r,
 * columns: force of site j axis c) of the sites from the image's R[s]
 * blocks, times tail_r^s.  Malloc'd: the caller frees. */
double *efx_contact_responses(const struct irdm_image *img, const struct irdm_contact_site *sites,
			      int m, size_t N, double tail_r);

/* efx_reference_opts() on responses W the caller built (and may have
 * changed): what the engine should do with them. */
void efx_reference_w(const double *W, int m, size_t N, const double *target,
		     const struct efx_ref_opts *o, double *F);

/* Solve the n x n system a x = b in place (Gaussian elimination, partial
 * pivoting); -1 if a pivot vanishes. */
int efx_dense_solve(double *a, double *b, int n);

/* Relative RMS of a - b over n values: |a - b|_2 / |b|_2. */
double efx_rel_rms(const double *a, const double *b, size_t n);

/* A modal image's column c at its own node: its 3 x K shapes (phi[i K + k])
 * and its static-correction block (far field included) into D, returning
 * D, or NULL when the image has none. */
const double *efx_column_modal(const struct irdm_image *img, size_t c, double *phi, double D[9]);
/* The image's static-correction block (force col_force -> displacement
 * col_disp) written out here, independently of irdm_image_corr_value():
 * the kept block (0 if dropped) + sum_k lambda_k u[disp][i][k] u[force][j][k]
 * of STATIC_CORR_LOWRANK; zeros without a correction. */
void efx_corr_block(const struct irdm_image *img, uint32_t col_force, uint32_t col_disp,
		    double blk[9]);

/* The paper's step and release at a node, N ticks: pressed dz along z
 * from tick 0, to the end ("step") and released at tick release
 * ("release"); each target (N x 3, NAN: released) handed to check(what,
 * target). */
void efx_step_release(size_t N, size_t release, double dz,
		      void (*check)(const char *what, const double *target));

/* Image node (row) index nearest to p among the columns. */
uint32_t efx_column_row_near(const struct irdm_image *img, const double p[3]);

#endif
