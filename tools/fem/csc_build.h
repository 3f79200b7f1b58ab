/* SPDX-License-Identifier: MIT */
/* Building CSC matrices from (row, col, value) triplets. */
#ifndef IRDM_TOOLS_CSC_BUILD_H
#define IRDM_TOOLS_CSC_BUILD_H

#include "fem/fem.h"
#include "irdm/error.h"

struct irdm_triplet {
	int64_t row;
	int64_t col;
	double val;
};

/* Consumes (sorts) t.  Return: IRDM_OK; IRDM_ENOMEM. */
int irdm_csc_from_triplets(size_t n, struct irdm_triplet *t, size_t nt,
			   struct irdm_csc *a);

#endif
