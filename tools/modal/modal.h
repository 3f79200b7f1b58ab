/* SPDX-License-Identifier: MIT */
/*
 * Modal analysis: K phi = w^2 M phi over the free DoFs, rigid modes
 * separated, eigenvectors M-orthonormal.  Two independent solvers: dense
 * LAPACK (all modes) and shift-invert Lanczos (ARPACK on a CHOLMOD factor)
 * for the lowest modes of large models.
 */
#ifndef IRDM_TOOLS_MODAL_H
#define IRDM_TOOLS_MODAL_H

#include <stdbool.h>
#include <stddef.h>

#include "fem/fem.h"
#include "irdm/error.h"
#include "irdm/image_format.h"

enum irdm_eig_method {
	IRDM_EIG_AUTO = 0, /* dense when small or all modes wanted, else Lanczos */
	IRDM_EIG_DENSE = 1,
	IRDM_EIG_LANCZOS = 2,
	IRDM_EIG_SLEPC = 3, /* SLEPc over MPI ranks (tools/dist/), if built in */
};

/* What makes a dense solve's vectors whole later (eig_dense.c). */
struct irdm_eig_rest;
struct irdm_sym;
/* Which of phi's columns are whole, and where to make the others so. */
struct irdm_modes_rest;

struct irdm_modes {
	size_t n;               /* vector length (free DoFs) */
	size_t n_modes;         /* elastic modes stored, ascending */
	size_t n_rigid;         /* rigid modes found and excluded */
	size_t n_elastic_total; /* elastic modes of the model: n - n_rigid */
	double *omega2;         /* n_modes eigenvalues w^2 (rad^2/s^2) */
	double *phi;            /* n x n_modes, column-major, Phi^T M Phi = I
				 * (NULL on an MPI rank other than 0) */
	double *rigid_phi;      /* n x n_rigid (floating only; NULL as phi) */
	/* K^-1 e_j for the loads asked (struct irdm_modes_want), n x n_loads,
	 * by the slepc path of a grounded object on rank 0 (NaN outside the
	 * kept DoFs); NULL: the static correction solves for itself */
	double *compliance;
	size_t n_compliance;
	/* non-NULL: some columns of phi hold only want->every's DoFs (NaN
	 * elsewhere) until irdm_modes_complete() makes them whole */
	struct irdm_modes_rest *rest;
	unsigned eig_blocks; /* blocks the solve was split into by symmetry (1: whole) */
};

/* What the caller will read of the modes (irdm_modes_solve_kept). */
struct irdm_modes_want {
	const bool *keep;         /* free DoFs read of elastic modes (NULL: all) */
	const int64_t *load_dofs; /* free DoFs of the static correction's unit loads */
	size_t n_loads;
	/* free DoFs read of every elastic mode (NULL: every DoF of every
	 * mode); a dense all-modes solve then gives each mode at those DoFs
	 * only, the others made whole on demand (irdm_modes_complete) */
	const bool *every;
	/* the model's symmetries (modal/symmetry.h; NULL: none): they split
	 * the dense all-modes solve */
	const struct irdm_sym *sym;
};

/* Progress of a stage in [0, 1]; a negative fraction: `stage` is a line to
 * show as it is (mesh statistics, warnings). */
typedef void (*irdm_progress_fn)(void *ctx, const char *stage, double fraction);

/*
 * The eigensolver over MPI ranks (IRDM_EIG_SLEPC), handed in by a caller
 * that can start MPI (tools/dist/): modal itself knows no MPI.  rank: this
 * process's rank (rank 0 alone keeps the eigenvectors); solve: as
 * irdm_eig_slepc() (dist/dist.h).
 */
struct irdm_eig_dist {
	int rank;
	int (*solve)(const struct irdm_fem *fem, size_t n_lowest, double sigma,
		     const struct irdm_modes_want *want, size_t n_whole,
		     irdm_progress_fn progress, void *ctx, double *w2, double *phi,
		     double *compliance, char *err, size_t errlen);
};

/*
 * Solve for the lowest n_wanted elastic modes (0: all).  floating: expect 6
 * rigid modes (eigenvalues below rigid_tol * w_max^2) and drop them.
 * A grounded model that shows a zero eigenvalue is an error (a mechanism:
 * not enough fixed nodes).
 */
int irdm_modes_solve(const struct irdm_fem *fem, size_t n_wanted, bool floating,
		     enum irdm_eig_method method, irdm_progress_fn progress, void *ctx,
		     struct irdm_modes *out, char *err, size_t errlen);
/*
 * The same; dist: the distributed eigensolver (NULL: IRDM_EIG_SLEPC is an
 * error); want->keep (n entries, NULL: all) marks the free DoFs whose
 * elastic eigenvector entries the caller will read.  Over MPI
 * (IRDM_EIG_SLEPC) only those cross the network to rank 0, whose other
 * entries are NaN so that a stray read shows; rigid modes always come
 * whole.  A grounded object's slepc path also solves K x = e_j for
 * want->load_dofs with the eigensolve's MUMPS factor (out->compliance).
 */
int irdm_modes_solve_kept(const struct irdm_fem *fem, size_t n_wanted, bool floating,
			  enum irdm_eig_method method, const struct irdm_eig_dist *dist,
			  const struct irdm_modes_want *want, irdm_progress_fn progress,
			  void *ctx, struct irdm_modes *out, char *err, size_t errlen);
void irdm_modes_free(struct irdm_modes *m);

/*
 * Elastic columns [first, first + count) of m->phi readable at the free
 * DoFs dofs[0..n_dofs) (-1 entries skipped): made whole unless every
 * column already holds all of those (see want->every).
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_ENUMERIC (LAPACK).
 */
int irdm_modes_complete(struct irdm_modes *m, size_t first, size_t count, const int64_t *dofs,
			size_t n_dofs, char *err, size_t errlen);
/* Whether column k of m->phi is whole. */
bool irdm_modes_whole(const struct irdm_modes *m, size_t k);
/* The columns reordered as irdm_modes_permute() reorders phi:
 * new k = old order[k]. */
int irdm_modes_rest_permute(struct irdm_modes *m, const size_t *order);

/* Internal solvers (exposed for tests: a second method to compare with). */
int irdm_eig_dense(const struct irdm_fem *fem, size_t n_lowest, double *w2, double *phi,
		   char *err, size_t errlen);
/* Every eigenpair of a lumped-mass model, each vector at the n_at free
 * DoFs at[] only (NaN elsewhere); *rest makes chosen ones whole.  A
 * consistent mass: all whole, *rest NULL.  sym (NULL: none): the model's
 * symmetries, which split the solve (eig_dense_at.c). */
int irdm_eig_dense_at(const struct irdm_fem *fem, const struct irdm_sym *sym, const int64_t *at,
		      size_t n_at, irdm_progress_fn progress, void *ctx, double *w2, double *phi,
		      struct irdm_eig_rest **rest, char *err, size_t errlen);
/* Vectors z_cols[0..k) made whole into out (n x k).  Return as
 * irdm_modes_complete(). */
int irdm_eig_rest_fill(const struct irdm_eig_rest *r, const size_t *z_cols, size_t k, double *out);
void irdm_eig_rest_free(struct irdm_eig_rest *r);
/* The blocks r's solve was split into (NULL: 1). */
unsigned irdm_eig_rest_blocks(const struct irdm_eig_rest *r);
/* Bytes irdm_eig_dense_at() holds for n DoFs split into blocks whose
 * sizes squared sum to sum_sq (n^2: whole). */
double irdm_eig_dense_at_bytes(size_t n, double sum_sq);
int irdm_eig_lanczos(const struct irdm_fem *fem, size_t n_lowest, double sigma,
		     irdm_progress_fn progress, void *ctx, double *w2, double *phi,
		     char *err, size_t errlen);
/*
 * Exact zero-order-hold discretisation of q'' + 2 z w q' + w^2 q = g:
 * x[t+1] = A x[t] + b g[t], x = (q, q').  Any z >= 0 (under-, critically,
 * over-damped), any w >= 0 (w = 0: a free mass).
 */
void irdm_zoh_mode(double omega_rad_s, double zeta, double dt_s, struct irdm_mode *out);

/* Scalar response h[s] = e1^T A^s b of one discretised mode, s < n. */
void irdm_zoh_response(const struct irdm_mode *m, size_t n, double *h);

#endif /* IRDM_TOOLS_MODAL_H */
