/* SPDX-License-Identifier: MIT */
/* Sparse Cholesky factors of ck K + cm M (CHOLMOD). */
#ifndef IRDM_TOOLS_FEM_FACTOR_H
#define IRDM_TOOLS_FEM_FACTOR_H

#include <cholmod.h>

#include "fem/fem.h"
#include "irdm/error.h"

/*
 * Factorise ck K + cm M (over the free DoFs) in the caller's CHOLMOD common;
 * only the upper triangle is handed over (stype = 1).  `what` names the
 * caller in messages.  A one-line reason goes to err.
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_ENUMERIC if the matrix is not positive
 * definite (a mechanism or a bad shift) or CHOLMOD fails otherwise.
 */
int irdm_fem_factor(const struct irdm_fem *fem, double ck, double cm, const char *what,
		    cholmod_common *cc, cholmod_factor **L, char *err, size_t errlen);

/* The same with diag[j] added to diagonal entry j (diag: n free DoFs, or
 * NULL): springs to ground at chosen DoFs. */
int irdm_fem_factor_diag(const struct irdm_fem *fem, double ck, double cm, const double *diag,
			 const char *what, cholmod_common *cc, cholmod_factor **L, char *err,
			 size_t errlen);

#endif
