/* SPDX-License-Identifier: MIT */
/*
 * The precompute over MPI ranks (eigensolver = slepc): PETSc and SLEPc
 * started and stopped, which rank this is, a failure on one rank stopping
 * them all, and the time-domain inputs' share of each rank gathered on
 * rank 0.  Started only when the scene asks for the slepc eigensolver, so
 * every other command runs as before (no MPI_Init, no PETSc).
 *
 * PETSc, SLEPc and MPI live in a plugin, irdm-slepc.so (dist_ops.h), that
 * these functions load when first needed.  Without it (a build without
 * PETSc/SLEPc) irdm_dist_begin() fails with "not built in", and everything
 * else answers as a single rank.
 */
#ifndef IRDM_TOOLS_DIST_H
#define IRDM_TOOLS_DIST_H

#include <stdbool.h>
#include <stddef.h>

#include "irdm/error.h"
#include "modal/modal.h"

/* Whether this build can run the slepc eigensolver. */
bool irdm_dist_built_in(void);

/*
 * Initialise MPI, PETSc and SLEPc (a singleton without mpirun) and cap the
 * BLAS threads so that threads x ranks on a machine do not exceed its
 * cores.  Return: IRDM_OK; IRDM_EINVAL if not built in; IRDM_ENUMERIC if
 * PETSc/SLEPc cannot start.  A one-line reason goes to err.
 */
int irdm_dist_begin(char *err, size_t errlen);

/* Finalise what irdm_dist_begin() started (no-op otherwise). */
void irdm_dist_end(void);

/* This rank and the number of ranks (0 and 1 when not started). */
int irdm_dist_rank(void);
int irdm_dist_size(void);

/* Threads one rank may use: the machine's cores over the ranks on it. */
unsigned irdm_dist_threads(void);

/*
 * Stop every rank: "irdm CMD: rank R of N: ENAME: reason" on stderr, then
 * MPI_Abort (mpirun kills the others and exits non-zero).  Only with more
 * than one rank; a single rank returns its error as usual.
 */
void irdm_dist_abort(const char *cmd, int code, const char *reason);

/*
 * The end of a run: every rank waits here until rank 0 has written the
 * image.  The waiting ranks sleep between polls instead of spinning in
 * MPI_Finalize's barrier, which would take a core from rank 0's serial
 * stages (responses, certificate, image).
 */
void irdm_dist_wait_all(void);

/*
 * Rank 0 gets every rank's block of doubles: counts[r] from rank r, placed
 * one after the other in all (rank 0's buffer of sum(counts); NULL on the
 * other ranks).  mine is this rank's counts[rank] doubles.  Return:
 * IRDM_OK; IRDM_ENUMERIC if MPI fails.
 */
int irdm_dist_gather(const double *mine, const size_t *counts, double *all,
		     char *err, size_t errlen);

/* The eigensolve by SLEPc (Krylov-Schur, shift-invert through MUMPS) over the
 * MPI ranks (started here if the caller did not): every rank gets w2,
 * rank 0 alone phi (NULL elsewhere): the first n_whole vectors whole, the
 * others at the DoFs want->keep marks, NaN elsewhere; with sigma = 0 and
 * want->n_loads, also (K^-1 e_j at the kept DoFs, NaN elsewhere) into
 * compliance (rank 0's n x n_loads; NULL elsewhere).  Collective: every
 * rank calls it. */
int irdm_eig_slepc(const struct irdm_fem *fem, size_t n_lowest, double sigma,
		   const struct irdm_modes_want *want, size_t n_whole,
		   irdm_progress_fn progress, void *ctx, double *w2, double *phi,
		   double *compliance, char *err, size_t errlen);

/*
 * Fault injection for the failure tests, never set otherwise: true if the
 * environment variable IRDM_TEST_FAULT is "RANK:WHERE" with this rank and
 * this where ("mesh": the mesh cannot be read, "oom": an allocation of the
 * eigensolve fails, "kill": the rank dies by SIGKILL in the eigensolve).
 */
bool irdm_dist_fault(const char *where);

#endif
