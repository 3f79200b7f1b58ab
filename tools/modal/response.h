/* SPDX-License-Identifier: MIT */
/*
 * Impulse responses from modes.  A selection of DoFs is a list of free-DoF
 * indices (or -1 for a fixed DoF, whose response is zero).
 */
#ifndef IRDM_TOOLS_RESPONSE_H
#define IRDM_TOOLS_RESPONSE_H

#include "irdm/error.h"
#include "modal/modal.h"

/* Discretise every mode with its Rayleigh damping ratio. */
int irdm_modes_discretise(const struct irdm_modes *m, const struct irdm_rayleigh *damp,
			  double dt_s, struct irdm_mode *out);

/*
 * FIR blocks R[c][r][s] (3x3, [i][j] = row axis i, column axis j) for column
 * nodes cols (3 DoFs each, free indices or -1) and row nodes rows, s < T:
 *   R = sum_k phi_r,k phi_c,k^T h_k[s]  (+ D[c][r] at s = 0 when D != NULL).
 * out has n_cols*n_rows*T*9 doubles, layout of the FIR section.
 * Return: IRDM_OK; IRDM_ENOMEM (out is then not filled).
 */
int irdm_fir_from_modes(const struct irdm_modes *m, const struct irdm_mode *zoh,
			const int64_t *col_dofs, size_t n_cols, const int64_t *row_dofs,
			size_t n_rows, size_t T, const double *D, double *out,
			irdm_progress_fn progress, void *ctx);

/*
 * Static correction: the compliance of the modes NOT kept,
 *   D[c][r] = G[r][c] - sum_{kept k} phi_r,k phi_c,k^T / w_k^2,
 * G = K^-1 (grounded) or the elastic compliance (floating: the compliance
 * that ignores rigid motion, found by shifted solves with iterative
 * refinement).  out: n_cols*n_rows*9, layout [c][r][i][j].
 */
int irdm_static_correction(const struct irdm_fem *fem, const struct irdm_modes *m,
			   bool floating, const int64_t *col_dofs, size_t n_cols,
			   const int64_t *row_dofs, size_t n_rows, double *out,
			   char *err, size_t errlen);

/* A factorisation of K (floating: K + eps M) kept open so the compliance
 * columns of many batches share it. */
struct irdm_compliance;

/* How a floating object's singular K is solved (static.c): K + eps M with
 * eight refinement steps, or K with springs at six pinned DoFs, one solve.
 * Both give the elastic compliance; grounded objects solve K once. */
enum irdm_compliance_method {
	IRDM_COMPLIANCE_SHIFTED,
	IRDM_COMPLIANCE_PINNED,
};

/* Return: IRDM_OK; IRDM_ENOMEM; IRDM_ENUMERIC (as irdm_fem_factor). */
int irdm_compliance_open(const struct irdm_fem *fem, const struct irdm_modes *m,
			 bool floating, enum irdm_compliance_method method,
			 struct irdm_compliance **c, char *err, size_t errlen);

/* Compliance columns X (n x n_in) of the free DoFs in[] with c's factor.
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_ENUMERIC if a solve fails. */
int irdm_compliance_columns(struct irdm_compliance *c, const int64_t *in, size_t n_in,
			    double *X, char *err, size_t errlen);

/* Compliance X = G F (n x n_rhs) of n_rhs full-length loads F (n x n_rhs,
 * column after column), whose rigid part is removed here, in place.
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_ENUMERIC if a solve fails. */
int irdm_compliance_loads(struct irdm_compliance *c, double *F, size_t n_rhs, double *X,
			  char *err, size_t errlen);

/* Free c (NULL: no-op). */
void irdm_compliance_close(struct irdm_compliance *c);

/* Full static compliance columns X (n x n_in) for free DoFs in[] (same
 * meaning of G as above); exposed for tests and the static correction. */
int irdm_compliance_solve(const struct irdm_fem *fem, const struct irdm_modes *m,
			  bool floating, const int64_t *in, size_t n_in, double *X,
			  char *err, size_t errlen);

#endif
