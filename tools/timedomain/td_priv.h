/* SPDX-License-Identifier: MIT */
/* Internals of the time-domain precompute shared between its files. */
#ifndef IRDM_TOOLS_TD_PRIV_H
#define IRDM_TOOLS_TD_PRIV_H

#include <cholmod.h>

#include "fem/fem.h"

/*
 * Factorise S = cm M + ck K (both over the free DoFs) with CHOLMOD in the
 * caller's common.  Only the upper triangle is handed over (stype = 1).
 * Returns 0, or -1 with a message.
 */
int irdm_td_factor(const struct irdm_fem *fem, double cm, double ck, cholmod_common *cc,
		   cholmod_factor **L, char *err, size_t errlen);

/* Y = A X for k columns (n x k, column-major, leading dimension n). */
void irdm_td_matvec_block(const struct irdm_csc *a, const double *x, double *y, size_t k);

#endif /* IRDM_TOOLS_TD_PRIV_H */
