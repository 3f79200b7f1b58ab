/* SPDX-License-Identifier: MIT */
/*
 * The hybrid representation's head without every mode: the same blocks
 * as irdm_exact_head() writes, from polynomials in the stiffness (a
 * Chebyshev series per touchable DoF) and the kept modes alone, for a
 * model whose every mode a dense eigensolve
 * cannot afford (its cost grows as n^3, its memory as n^2).
 */
#ifndef IRDM_TOOLS_KRYLOV_HEAD_H
#define IRDM_TOOLS_KRYLOV_HEAD_H

#include <stddef.h>
#include <stdint.h>

#include "fem/fem.h"
#include "modal/modal.h"
#include "modal/static_sparse.h"

/* The expansion is cut where what it leaves (the sum of its dropped
 * coefficients' sizes) is below tol of the largest dropped mode's
 * response; these are an image head's. */
#define IRDM_KRYLOV_HEAD_TOL 1e-8
#define IRDM_KRYLOV_HEAD_MAX_TERMS 20000

struct irdm_krylov_head_opts {
	double tol;       /* IRDM_KRYLOV_HEAD_TOL */
	size_t max_steps; /* terms (a run's products with K: one fewer): refused past it */
	unsigned threads; /* the column batches are shared by threads (0: one per online CPU) */
	size_t samples;   /* samples computed, the rest 0 before the taper (0: all 2H) */
};

struct irdm_krylov_head_stats {
	size_t runs;    /* one per column axis */
	size_t terms;   /* the expansion's, the same for every run */
	size_t samples; /* computed */
	double tail;    /* the bound on what the cut leaves, relative */
	double lam_up;  /* the bound on the spectrum of M^-1/2 K M^-1/2 */
};

/*
 * head[(k 2H + s) 9 + 3 i + j] as irdm_exact_head() defines it, for every
 * kept block k of corr and s < 2H, the dropped modes' response computed as
 *   D_s e_j = M^-1/2 h_s(A) P M^-1/2 e_j,  A = M^-1/2 K M^-1/2,
 * P the projector off the kept modes, h_s the zero-order-hold response of
 * a mode (damping: Rayleigh, dt_s) at sample s as a function of its
 * eigenvalue, by its Chebyshev series in A on [0, Gershgorin's bound]
 * (one three-term recurrence per start vector, the start projected),
 * cut at o->tol.  fem: K and a lumped
 * M over the free DoFs; kept: the lowest modes, whole vectors,
 * M-orthonormal (grounded: no rigid modes); col_dofs as for
 * irdm_static_correction_sparse(); target as for irdm_exact_head().
 * st (may be NULL) gets the runs' counts.
 * Return: IRDM_OK; IRDM_EINVAL (M not lumped, no kept mode, H < 1,
 * o->max_steps < 2, a column without its diagonal block); IRDM_ENOMEM; IRDM_ENUMERIC (the
 * expansion needs more than o->max_steps terms, or a run grew: an
 * eigenvalue above the bound);
 * err says which.
 */
/*
 * Gershgorin's bound on the spectrum of M^-1/2 K M^-1/2 (fem: a lumped
 * M), as the head's expansion takes it: no mode is above its square
 * root in rad/s.
 */
double irdm_krylov_spectrum_bound(const struct irdm_fem *fem);

int irdm_krylov_head(const struct irdm_fem *fem, const struct irdm_modes *kept,
		     const struct irdm_rayleigh *damping, double dt_s, const int64_t *col_dofs,
		     const struct irdm_corr_sparse *corr, const double *target, size_t H,
		     const struct irdm_krylov_head_opts *o, irdm_progress_fn progress, void *ctx, double *head,
		     struct irdm_krylov_head_stats *st, char *err, size_t errlen);

#endif
