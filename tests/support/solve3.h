/* SPDX-License-Identifier: MIT */
/* A 3x3 linear solve for tests and benchmarks, independent of the libraries
 * they check (not the firmware's). */
#ifndef IRDM_TESTS_SOLVE3_H
#define IRDM_TESTS_SOLVE3_H

/* x = a^-1 b by Cramer's rule, a row-major; for the small, well-conditioned
 * systems of a test (a Jacobian near home, a contact's R[0]). */
void ts_solve3(const double a[9], const double b[3], double x[3]);

#endif
