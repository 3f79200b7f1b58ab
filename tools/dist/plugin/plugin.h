/* SPDX-License-Identifier: MIT */
/* Inside the slepc plugin (irdm-slepc.so): what its two files share. */
#ifndef IRDM_TOOLS_DIST_PLUGIN_H
#define IRDM_TOOLS_DIST_PLUGIN_H

#include <stdbool.h>
#include <stddef.h>

#include "dist/dist_ops.h"

int irdm_mpi_begin(char *err, size_t errlen);
int irdm_mpi_rank(void);
int irdm_mpi_size(void);
bool irdm_mpi_fault(const char *where);

/* irdm_eig_slepc() of dist.h, here. */
int irdm_slepc_eig(const struct irdm_fem *fem, size_t n_lowest, double sigma,
		   const struct irdm_modes_want *want, size_t n_whole,
		   irdm_progress_fn progress, void *pctx, double *w2, double *phi,
		   double *compliance, char *err, size_t errlen);

#endif
