/* SPDX-License-Identifier: MIT */
/* Internals of the time-domain precompute shared between its files. */
#ifndef IRDM_TOOLS_TD_PRIV_H
#define IRDM_TOOLS_TD_PRIV_H

#include <cholmod.h>

#include "fem/fem.h"

/* Y = A X for k columns (n x k, column-major, leading dimension n). */
void irdm_td_matvec_block(const struct irdm_csc *a, const double *x, double *y, size_t k);

#endif /* IRDM_TOOLS_TD_PRIV_H */
