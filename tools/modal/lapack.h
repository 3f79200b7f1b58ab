/* SPDX-License-Identifier: MIT */
/* Fortran LAPACK/BLAS prototypes we call (OpenBLAS provides them).  Declared
 * here rather than through LAPACKE so that no row-major copies are made. */
#ifndef IRDM_TOOLS_LAPACK_H
#define IRDM_TOOLS_LAPACK_H

void dsyevr_(const char *jobz, const char *range, const char *uplo, const int *n,
	     double *a, const int *lda, const double *vl, const double *vu,
	     const int *il, const int *iu, const double *abstol, int *m, double *w,
	     double *z, const int *ldz, int *isuppz, double *work, const int *lwork,
	     int *iwork, const int *liwork, int *info);
void dsytrd_(const char *uplo, const int *n, double *a, const int *lda, double *d, double *e,
	     double *tau, double *work, const int *lwork, int *info);
void dstedc_(const char *compz, const int *n, double *d, double *e, double *z, const int *ldz,
	     double *work, const int *lwork, int *iwork, const int *liwork, int *info);
void dormtr_(const char *side, const char *uplo, const char *trans, const int *m, const int *n,
	     const double *a, const int *lda, const double *tau, double *c, const int *ldc,
	     double *work, const int *lwork, int *info);
void dpotrf_(const char *uplo, const int *n, double *a, const int *lda, int *info);
void dsygst_(const int *itype, const char *uplo, const int *n, double *a, const int *lda,
	     const double *b, const int *ldb, int *info);
void dtrsm_(const char *side, const char *uplo, const char *transa, const char *diag,
	    const int *m, const int *n, const double *alpha, const double *a, const int *lda,
	    double *b, const int *ldb);
void dgeev_(const char *jobvl, const char *jobvr, const int *n, double *a, const int *lda,
	    double *wr, double *wi, double *vl, const int *ldvl, double *vr, const int *ldvr,
	    double *work, const int *lwork, int *info);
void dgemm_(const char *ta, const char *tb, const int *m, const int *n, const int *k,
	    const double *alpha, const double *a, const int *lda, const double *b,
	    const int *ldb, const double *beta, double *c, const int *ldc);
void dgesv_(const int *n, const int *nrhs, double *a, const int *lda, int *ipiv, double *b,
	    const int *ldb, int *info);
void dgeqrf_(const int *m, const int *n, double *a, const int *lda, double *tau, double *work,
	     const int *lwork, int *info);
void dorgqr_(const int *m, const int *n, const int *k, double *a, const int *lda,
	     const double *tau, double *work, const int *lwork, int *info);
void dgesdd_(const char *jobz, const int *m, const int *n, double *a, const int *lda, double *s,
	     double *u, const int *ldu, double *vt, const int *ldvt, double *work,
	     const int *lwork, int *iwork, int *info);
void openblas_set_num_threads(int n);
int openblas_get_num_threads(void);

/*
 * OpenBLAS single-threaded while our own workers run: they already occupy
 * the CPUs, nested BLAS threads would oversubscribe them, and a BLAS thread
 * count that differs between runs could change reduction order and so break
 * bitwise reproducibility.  The count is process-wide state, so it is
 * saved and given back as it was, not reset to some default:
 *
 *	int saved = irdm_blas_serial_begin();
 *	... parallel phase ...
 *	irdm_blas_serial_end(saved);
 */
static inline int irdm_blas_serial_begin(void)
{
	int saved = openblas_get_num_threads();

	openblas_set_num_threads(1);
	return saved;
}

static inline void irdm_blas_serial_end(int saved)
{
	openblas_set_num_threads(saved);
}

#endif
