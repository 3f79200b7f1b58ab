/* SPDX-License-Identifier: MIT */
/*
 * Distributed shift-invert Krylov-Schur for the lowest modes (SLEPc over
 * MPI): K and M in PETSc matrices, each rank holding its block of rows;
 * (K - sigma M)^-1 applied through one MUMPS factorisation spread over the
 * ranks; the eigenvectors M-normalised and gathered on rank 0 only (the
 * other ranks get the eigenvalues).  The same problem as eig_lanczos.c's,
 * solved by a second method: the two agree to rounding (test_slepc).
 */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dist/plugin/plugin.h"
#include "util/clock.h"

#include <slepceps.h>

/* Tolerance of the eigensolve's relative residual: the serial solvers'
 * eigenvalues are rounding-exact, this keeps SLEPc's within 1e-9. */
#define SLEPC_TOL 1e-12
#define SLEPC_MAX_IT 1000

struct monitor_ctx {
	irdm_progress_fn progress;
	void *pctx;
	PetscInt nev;
};

/* Where the time went, as a line of the progress (rank 0): what a user
 * extrapolates from (docs/mpi.md, "What scales"). */
static void say_times(const struct monitor_ctx *m, const double t[6])
{
	char line[256];

	if (!m->progress || irdm_mpi_rank() != 0)
		return;
	snprintf(line, sizeof(line),
		 "slepc on %d rank%s: assembly %.2f s, MUMPS factorisation %.2f s, "
		 "Krylov-Schur %.2f s, eigenvectors to rank 0 %.2f s, static loads %.2f s",
		 irdm_mpi_size(), irdm_mpi_size() > 1 ? "s" : "", t[1] - t[0], t[2] - t[1],
		 t[3] - t[2], t[4] - t[3], t[5] - t[4]);
	m->progress(m->pctx, line, -1.0);
}

static PetscErrorCode monitor(EPS eps, PetscInt its, PetscInt nconv, PetscScalar *er,
			      PetscScalar *ei, PetscReal *errest, PetscInt nest, void *ctx)
{
	struct monitor_ctx *m = ctx;

	(void)eps;
	(void)its;
	(void)er;
	(void)ei;
	(void)errest;
	(void)nest;
	if (m->progress && irdm_mpi_rank() == 0)
		m->progress(m->pctx, "SLEPc Krylov-Schur", fmin(0.99, (double)nconv / (double)m->nev));
	return 0;
}

/*
 * This rank's rows [lo, hi) of the symmetric CSC a (both triangles stored:
 * column j is row j) into a PETSc AIJ matrix, preallocated exactly.
 */
static int csc_rows_to_petsc(const struct irdm_csc *a, PetscInt lo, PetscInt hi, Mat *out,
			     char *err, size_t errlen)
{
	PetscInt nloc = hi - lo, *d_nnz, *o_nnz, *cols;
	size_t max_row = 0;
	PetscErrorCode perr = 0;

	for (PetscInt i = lo; i < hi; i++)
		if ((size_t)(a->colptr[i + 1] - a->colptr[i]) > max_row)
			max_row = (size_t)(a->colptr[i + 1] - a->colptr[i]);
	d_nnz = irdm_mpi_fault("oom") ? NULL : malloc(((size_t)nloc + 1) * sizeof(PetscInt));
	o_nnz = malloc(((size_t)nloc + 1) * sizeof(PetscInt));
	cols = malloc((max_row + 1) * sizeof(PetscInt));
	if (!d_nnz || !o_nnz || !cols) {
		snprintf(err, errlen, "slepc: out of memory for %ld matrix rows", (long)nloc);
		free(d_nnz);
		free(o_nnz);
		free(cols);
		return IRDM_ENOMEM;
	}
	for (PetscInt i = lo; i < hi; i++) {
		d_nnz[i - lo] = o_nnz[i - lo] = 0;
		for (int64_t p = a->colptr[i]; p < a->colptr[i + 1]; p++)
			if (a->rowind[p] >= lo && a->rowind[p] < hi)
				d_nnz[i - lo]++;
			else
				o_nnz[i - lo]++;
	}
	perr = MatCreateAIJ(PETSC_COMM_WORLD, nloc, nloc, (PetscInt)a->n, (PetscInt)a->n, 0, d_nnz,
			    0, o_nnz, out);
	for (PetscInt i = lo; i < hi && !perr; i++) {
		PetscInt len = (PetscInt)(a->colptr[i + 1] - a->colptr[i]);
		for (PetscInt k = 0; k < len; k++)
			cols[k] = (PetscInt)a->rowind[a->colptr[i] + k];
		perr = MatSetValues(*out, 1, &i, len, cols, &a->val[a->colptr[i]], INSERT_VALUES);
	}
	if (!perr)
		perr = MatAssemblyBegin(*out, MAT_FINAL_ASSEMBLY);
	if (!perr)
		perr = MatAssemblyEnd(*out, MAT_FINAL_ASSEMBLY);
	free(d_nnz);
	free(o_nnz);
	free(cols);
	if (perr) {
		snprintf(err, errlen, "slepc: PETSc error %d assembling a matrix", (int)perr);
		return IRDM_ENUMERIC;
	}
	return IRDM_OK;
}

/* Krylov-Schur, shift-and-invert at sigma, the factorisation by MUMPS. */
static PetscErrorCode setup_eps(EPS eps, Mat K, Mat M, PetscInt nev, double sigma,
				struct monitor_ctx *mon)
{
	ST st;
	KSP ksp;
	PC pc;

	PetscCall(EPSSetOperators(eps, K, M));
	PetscCall(EPSSetProblemType(eps, EPS_GHEP));
	PetscCall(EPSSetType(eps, EPSKRYLOVSCHUR));
	PetscCall(EPSSetDimensions(eps, nev, PETSC_DEFAULT, PETSC_DEFAULT));
	PetscCall(EPSSetTolerances(eps, SLEPC_TOL, SLEPC_MAX_IT));
	PetscCall(EPSSetTarget(eps, sigma));
	PetscCall(EPSSetWhichEigenpairs(eps, EPS_TARGET_MAGNITUDE));
	PetscCall(EPSGetST(eps, &st));
	PetscCall(STSetType(st, STSINVERT));
	PetscCall(STGetKSP(st, &ksp));
	PetscCall(KSPSetType(ksp, KSPPREONLY));
	PetscCall(KSPGetPC(ksp, &pc));
	/* K - sigma M is definite (sigma below the lowest eigenvalue) */
	PetscCall(PCSetType(pc, PCCHOLESKY));
	PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
	PetscCall(EPSMonitorSet(eps, monitor, mon, NULL));
	/* PETSC_OPTIONS (-eps_ncv, -mat_mumps_icntl_14, ...) still tune it */
	PetscCall(EPSSetFromOptions(eps));
	return 0;
}

/* Sort order: ascending eigenvalue (SLEPc orders by distance to sigma). */
struct eig_idx {
	double w2;
	PetscInt i;
};

static int cmp_eig(const void *a, const void *b)
{
	double x = ((const struct eig_idx *)a)->w2, y = ((const struct eig_idx *)b)->w2;

	return (x > y) - (x < y);
}

/*
 * The scatter of the kept DoFs to rank 0 (keep NULL: all of them): into xk,
 * of length n_keep on rank 0 and 0 elsewhere; idx (rank 0) their indices.
 */
static PetscErrorCode kept_scatter(Vec x, const bool *keep, PetscInt n, VecScatter *sc, Vec *xk,
				   PetscInt **idx, PetscInt *n_keep)
{
	IS from, to;

	*n_keep = 0;
	*idx = NULL;
	if (irdm_mpi_rank() == 0) {
		PetscCall(PetscMalloc1(n ? n : 1, idx));
		for (PetscInt i = 0; i < n; i++)
			if (!keep || keep[i])
				(*idx)[(*n_keep)++] = i;
	}
	PetscCall(ISCreateGeneral(PETSC_COMM_SELF, *n_keep, *idx, PETSC_USE_POINTER, &from));
	PetscCall(ISCreateStride(PETSC_COMM_SELF, *n_keep, 0, 1, &to));
	PetscCall(VecCreateSeq(PETSC_COMM_SELF, *n_keep, xk));
	PetscCall(VecScatterCreate(x, from, *xk, to, sc));
	PetscCall(ISDestroy(&from));
	PetscCall(ISDestroy(&to));
	return 0;
}

/* x (M-normalised here rather than by the solver's choice) to rank 0's
 * column dst of n: the whole vector, or the kept DoFs and NaN elsewhere. */
static PetscErrorCode send_vector(Vec x, Mat M, Vec mx, VecScatter sc, Vec xk,
				  const PetscInt *idx, PetscInt n_keep, PetscInt n, double *dst)
{
	const PetscScalar *a;
	PetscScalar xmx;

	PetscCall(MatMult(M, x, mx));
	PetscCall(VecDot(x, mx, &xmx));
	PetscCall(VecScale(x, 1.0 / sqrt(PetscRealPart(xmx))));
	PetscCall(VecScatterBegin(sc, x, xk, INSERT_VALUES, SCATTER_FORWARD));
	PetscCall(VecScatterEnd(sc, x, xk, INSERT_VALUES, SCATTER_FORWARD));
	if (!dst)
		return 0;
	if (n_keep < n)
		for (PetscInt i = 0; i < n; i++)
			dst[i] = NAN;
	PetscCall(VecGetArrayRead(xk, &a));
	for (PetscInt i = 0; i < n_keep; i++)
		dst[idx[i]] = a[i];
	PetscCall(VecRestoreArrayRead(xk, &a));
	return 0;
}

/* Eigenpairs in ascending order: every rank the eigenvalues, rank 0 the
 * vectors (phi may be NULL elsewhere): the first n_whole whole, the rest at
 * the kept DoFs only, which alone cross the network. */
static PetscErrorCode extract(EPS eps, Mat M, PetscInt nev, const bool *keep, PetscInt n_whole,
			      struct eig_idx *ix, double *w2, double *phi)
{
	Vec x, mx, x_all, x_kept;
	VecScatter to_all, to_kept;
	PetscInt n, n_all, n_kept, *idx_all, *idx_kept;

	for (PetscInt k = 0; k < nev; k++) {
		PetscScalar kr;
		PetscCall(EPSGetEigenvalue(eps, k, &kr, NULL));
		ix[k] = (struct eig_idx){ PetscRealPart(kr), k };
	}
	qsort(ix, (size_t)nev, sizeof(*ix), cmp_eig);
	PetscCall(MatCreateVecs(M, &x, &mx));
	PetscCall(VecGetSize(x, &n));
	PetscCall(kept_scatter(x, NULL, n, &to_all, &x_all, &idx_all, &n_all));
	PetscCall(kept_scatter(x, keep, n, &to_kept, &x_kept, &idx_kept, &n_kept));
	for (PetscInt k = 0; k < nev; k++) {
		PetscScalar kr;
		bool whole = k < n_whole;
		PetscCall(EPSGetEigenpair(eps, ix[k].i, &kr, NULL, x, NULL));
		w2[k] = PetscRealPart(kr);
		PetscCall(send_vector(x, M, mx, whole ? to_all : to_kept, whole ? x_all : x_kept,
				      whole ? idx_all : idx_kept, whole ? n_all : n_kept, n,
				      phi ? &phi[(size_t)k * (size_t)n] : NULL));
	}
	PetscCall(VecScatterDestroy(&to_all));
	PetscCall(VecScatterDestroy(&to_kept));
	PetscCall(VecDestroy(&x_all));
	PetscCall(VecDestroy(&x_kept));
	PetscCall(PetscFree(idx_all));
	PetscCall(PetscFree(idx_kept));
	PetscCall(VecDestroy(&x));
	PetscCall(VecDestroy(&mx));
	return 0;
}

/*
 * The static correction's loads: K x = e_j for every load DoF, by the
 * eigensolve's MUMPS factor of K (sigma = 0: the shift-and-invert operator
 * is K itself), LOADS_PER_SOLVE right-hand sides at a time (what bounds the
 * dense blocks: n x LOADS_PER_SOLVE doubles, split by rows), each column's
 * kept DoFs to rank 0's compliance (NaN elsewhere).
 */
#define LOADS_PER_SOLVE 64

static PetscErrorCode solve_loads(EPS eps, Mat K, const struct irdm_modes_want *want,
				  double *compliance)
{
	PetscInt n, lo, hi, n_kept, *idx_kept;
	Vec col, x_kept;
	VecScatter to_kept;
	Mat B, X;
	ST st;
	KSP ksp;

	PetscCall(EPSGetST(eps, &st));
	PetscCall(STGetKSP(st, &ksp));
	PetscCall(MatGetSize(K, &n, NULL));
	PetscCall(MatGetOwnershipRange(K, &lo, &hi));
	PetscCall(MatCreateVecs(K, &col, NULL));
	PetscCall(kept_scatter(col, want->keep, n, &to_kept, &x_kept, &idx_kept, &n_kept));
	for (size_t j0 = 0; j0 < want->n_loads; j0 += LOADS_PER_SOLVE) {
		PetscInt nb = (PetscInt)(want->n_loads - j0 < LOADS_PER_SOLVE ? want->n_loads - j0 : LOADS_PER_SOLVE);
		PetscCall(MatCreateDense(PETSC_COMM_WORLD, hi - lo, PETSC_DECIDE, n, nb, NULL, &B));
		PetscCall(MatCreateDense(PETSC_COMM_WORLD, hi - lo, PETSC_DECIDE, n, nb, NULL, &X));
		for (PetscInt j = 0; j < nb; j++) {
			PetscInt d = (PetscInt)want->load_dofs[j0 + (size_t)j];
			if (d >= lo && d < hi)
				PetscCall(MatSetValue(B, d, j, 1.0, INSERT_VALUES));
		}
		PetscCall(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY));
		PetscCall(MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY));
		PetscCall(KSPMatSolve(ksp, B, X));
		for (PetscInt j = 0; j < nb; j++) {
			Vec xj;
			const PetscScalar *a;
			double *dst = compliance ? &compliance[(j0 + (size_t)j) * (size_t)n] : NULL;
			PetscCall(MatDenseGetColumnVecRead(X, j, &xj));
			PetscCall(VecScatterBegin(to_kept, xj, x_kept, INSERT_VALUES, SCATTER_FORWARD));
			PetscCall(VecScatterEnd(to_kept, xj, x_kept, INSERT_VALUES, SCATTER_FORWARD));
			PetscCall(MatDenseRestoreColumnVecRead(X, j, &xj));
			if (!dst)
				continue;
			for (PetscInt i = 0; i < n; i++)
				dst[i] = NAN;
			PetscCall(VecGetArrayRead(x_kept, &a));
			for (PetscInt i = 0; i < n_kept; i++)
				dst[idx_kept[i]] = a[i];
			PetscCall(VecRestoreArrayRead(x_kept, &a));
		}
		PetscCall(MatDestroy(&B));
		PetscCall(MatDestroy(&X));
	}
	PetscCall(VecScatterDestroy(&to_kept));
	PetscCall(VecDestroy(&x_kept));
	PetscCall(PetscFree(idx_kept));
	PetscCall(VecDestroy(&col));
	return 0;
}

/* This rank's share of the n rows (PETSc's split: contiguous blocks). */
static int my_rows(PetscInt n, PetscInt *lo, PetscInt *hi)
{
	PetscInt nloc = PETSC_DECIDE, end = 0;

	if (PetscSplitOwnership(PETSC_COMM_WORLD, &nloc, &n))
		return -1;
	if (MPI_Scan(&nloc, &end, 1, MPIU_INT, MPI_SUM, PETSC_COMM_WORLD))
		return -1;
	*lo = end - nloc;
	*hi = end;
	return 0;
}

/* t[0] is set (assembly's start); t[1..5]: assembled, factorised, solved,
 * gathered, static loads solved. */
static int solve(Mat K, Mat M, PetscInt nev, double sigma, const struct irdm_modes_want *want,
		 PetscInt n_whole, struct monitor_ctx *mon, double t[6], double *w2, double *phi,
		 double *compliance, char *err, size_t errlen)
{
	struct eig_idx *ix = malloc((size_t)nev * sizeof(*ix));
	PetscInt nconv = 0;
	EPS eps = NULL;
	PetscErrorCode perr;
	int ret = IRDM_ENUMERIC;

	if (!ix) {
		snprintf(err, errlen, "slepc: out of memory");
		return IRDM_ENOMEM;
	}
	t[1] = irdm_now_s();
	perr = EPSCreate(PETSC_COMM_WORLD, &eps);
	if (!perr)
		perr = setup_eps(eps, K, M, nev, sigma, mon);
	if (irdm_mpi_fault("kill"))
		raise(SIGKILL);
	if (mon->progress && irdm_mpi_rank() == 0)
		mon->progress(mon->pctx, "MUMPS factorisation", 0.0);
	if (!perr) /* the shift-and-invert factorisation */
		perr = EPSSetUp(eps);
	t[2] = irdm_now_s();
	if (!perr)
		perr = EPSSolve(eps);
	t[3] = irdm_now_s();
	if (perr) {
		const char *text = NULL;
		PetscErrorMessage(perr, &text, NULL);
		snprintf(err, errlen, "slepc: the eigensolve failed: %s (PETSc error %d)",
			 text ? text : "?", (int)perr);
		goto out_free;
	}
	EPSGetConverged(eps, &nconv);
	if (nconv < nev) {
		snprintf(err, errlen, "slepc: %ld of %ld eigenpairs converged", (long)nconv, (long)nev);
		goto out_free;
	}
	if (extract(eps, M, nev, want->keep, n_whole, ix, w2, phi)) {
		snprintf(err, errlen, "slepc: gathering the eigenvectors failed");
		goto out_free;
	}
	t[4] = irdm_now_s();
	if (sigma == 0 && want->n_loads && solve_loads(eps, K, want, compliance)) {
		snprintf(err, errlen, "slepc: the static correction's solves failed");
		goto out_free;
	}
	t[5] = irdm_now_s();
	ret = IRDM_OK;
out_free:
	EPSDestroy(&eps);
	free(ix);
	return ret;
}

int irdm_slepc_eig(const struct irdm_fem *fem, size_t n_lowest, double sigma,
		   const struct irdm_modes_want *want, size_t n_whole,
		   irdm_progress_fn progress, void *pctx, double *w2, double *phi,
		   double *compliance, char *err, size_t errlen)
{
	struct monitor_ctx mon = { progress, pctx, (PetscInt)n_lowest };
	Mat K = NULL, M = NULL;
	PetscInt lo, hi;
	double t[6] = { irdm_now_s(), 0, 0, 0, 0, 0 };
	int ret;

	/* a no-op when the command started it (a singleton for a library caller) */
	ret = irdm_mpi_begin(err, errlen);
	if (ret)
		return ret;
	if (my_rows((PetscInt)fem->K.n, &lo, &hi)) {
		snprintf(err, errlen, "slepc: cannot split %zu rows over the ranks", fem->K.n);
		return IRDM_ENUMERIC;
	}
	if (progress && irdm_mpi_rank() == 0)
		progress(pctx, "distributed assembly", 0.0);
	ret = csc_rows_to_petsc(&fem->K, lo, hi, &K, err, errlen);
	if (!ret)
		ret = csc_rows_to_petsc(&fem->M, lo, hi, &M, err, errlen);
	if (!ret)
		ret = solve(K, M, (PetscInt)n_lowest, sigma, want, (PetscInt)n_whole, &mon, t, w2,
			    phi, compliance, err, errlen);
	if (!ret)
		say_times(&mon, t);
	MatDestroy(&K);
	MatDestroy(&M);
	return ret;
}
