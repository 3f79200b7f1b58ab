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
void openblas_set_num_threads(int n);

#endif
