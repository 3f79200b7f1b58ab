/* SPDX-License-Identifier: MIT */
/*
 * What the slepc plugin (irdm-slepc.so, tools/dist/plugin/) offers the
 * loader (tools/dist/dist.c).  PETSc and SLEPc pull in a hundred shared
 * libraries whose relocation cost every irdm command 50 ms (0.4 s on a
 * loaded machine) before main(); in a plugin only a run that asks for
 * eigensolver = slepc pays it.
 */
#ifndef IRDM_TOOLS_DIST_OPS_H
#define IRDM_TOOLS_DIST_OPS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "modal/modal.h"

#define IRDM_SLEPC_PLUGIN "irdm-slepc.so"
#define IRDM_SLEPC_PLUGIN_ENTRY "irdm_slepc_plugin"
#define IRDM_DIST_OPS_VERSION 3

struct irdm_dist_ops {
	int version; /* IRDM_DIST_OPS_VERSION */
	int (*begin)(char *err, size_t errlen);
	void (*end)(void);
	int (*rank)(void);
	int (*size)(void);
	unsigned (*threads)(void);
	/* line: the whole message, printed before MPI_Abort */
	void (*abort)(const char *line);
	void (*wait_all)(void);
	int (*gather)(const double *mine, const size_t *counts, double *all, char *err,
		      size_t errlen);
	int (*eig)(const struct irdm_fem *fem, size_t n_lowest, double sigma,
		   const struct irdm_modes_want *want, size_t n_whole, irdm_progress_fn progress,
		   void *ctx, double *w2, double *phi, double *compliance, char *err,
		   size_t errlen);
};

typedef const struct irdm_dist_ops *(*irdm_slepc_plugin_fn)(void);

/* IRDM_TEST_FAULT = "RANK:WHERE" names this rank and where (dist.h). */
static inline bool irdm_dist_fault_at(int rank, const char *where)
{
	const char *f = getenv("IRDM_TEST_FAULT");
	char *end;
	long r;

	if (!f)
		return false;
	r = strtol(f, &end, 10);
	return end != f && *end == ':' && r == rank && !strcmp(end + 1, where);
}

#endif
