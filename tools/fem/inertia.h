/* SPDX-License-Identifier: MIT */
/*
 * How many modes lie below a frequency, without solving them: by
 * Sylvester's law of inertia the eigenvalues of K x = lam M x below sigma
 * are as many as the negative pivots of K - sigma M = L D L^T.  One sparse
 * factorisation (CHOLMOD's simplicial LDL^T, which takes negative pivots
 * without pivoting); a pivot that is exactly zero (sigma an eigenvalue to
 * rounding) is refused.
 */
#ifndef IRDM_TOOLS_FEM_INERTIA_H
#define IRDM_TOOLS_FEM_INERTIA_H

#include <stddef.h>

#include "fem/fem.h"

/*
 * *count: the eigenvalues of K x = lam M x (over the free DoFs) below
 * sigma (rad^2/s^2).
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_ENUMERIC (a zero pivot, or CHOLMOD
 * failed); err says which.
 */
int irdm_fem_count_below(const struct irdm_fem *fem, double sigma, size_t *count, char *err,
			 size_t errlen);

#endif
