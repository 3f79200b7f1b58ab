/* SPDX-License-Identifier: MIT */
/*
 * What the dense solvers share (eig_dense.c, eig_dense_at.c).
 */
#ifndef IRDM_MODAL_EIG_DENSE_PRIV_H
#define IRDM_MODAL_EIG_DENSE_PRIV_H

#include <stdbool.h>

#include "fem/fem.h"

/* Whether M has no off-diagonal nonzero (a lumped mass). */
bool irdm_eig_mass_is_diagonal(const struct irdm_csc *m);
/* dsqrt[j] = sqrt(M_jj), M lumped. */
void irdm_eig_mass_sqrt(const struct irdm_csc *m, double *dsqrt);
/* A LAPACK workspace query's answer as a count; -1 past int. */
int irdm_eig_work_size(double q);
/*
 * One workspace for dsytrd, dstedc into z and, with_ormtr, dormtr on A
 * (n x n), as their queries ask.  0, or -1 out of memory (*work and
 * *iwork then whatever was allocated).
 */
int irdm_eig_workspace(double *a, int n, double *d, double *e, double *tau, double *z,
		       bool with_ormtr, double **work, int *lwork, int **iwork, int *liwork);

#endif
