/* SPDX-License-Identifier: MIT */
/*
 * The modal certificate (stability_modal.c) against the dense eigenvalues
 * of the closed-loop matrix (stability.c): the checks and tolerances the
 * modal and hybrid (FIR head) stability tests share.
 */
#ifndef IRDM_TESTS_STAB_CERT_H
#define IRDM_TESTS_STAB_CERT_H

#include <stddef.h>

#include "modal/stability.h"

/* The dense eigenvalues of a 2K matrix with ||A|| ~ 1: measured agreement
 * with the certified bracket is below 1e-12; 1e-10 is the margin. */
#define STAB_DENSE_TOL 1e-10
/* stated width of the bracket (REL_TOL in stability_modal.c) */
#define STAB_CERT_WIDTH 1e-8
/* a Newton root as rho_lo: to its last step (NEWTON_TOL 1e-10) at a double
 * root (the floating cube's degenerate modes; measured 7e-11), margin 10 */
#define STAB_NEWTON_LO_TOL 1e-9

/*
 * dense (the reference radius, clamped here to the search's bounds) and
 * cert agree: the same verdict (radius < 1), rho_lo certified or a Newton
 * root, the bracket [rho_lo, rho] holds dense to the tolerances above and
 * is at most STAB_CERT_WIDTH wide (or, for a radius below the search's
 * lower bound, rho is that bound and rho_lo 0).  Fails the test naming
 * what and case otherwise.  Returns the clamped dense radius.
 */
double stab_cert_check(const char *what, size_t c, double dense, const struct irdm_stab_cert *cert);

/*
 * The exact response at one node of modes [k0, k1) of a 3 x n_all shape
 * matrix (phi[i n_all + k]): the FIR head a hybrid image records for the
 * modes it drops, D_s = sum_k phi_k phi_k^T h_k[s], s < n_head, into head
 * (n_head blocks of 9, row-major).
 */
void stab_dropped_head(const struct irdm_mode *zoh, const double *phi, size_t n_all, size_t k0,
		       size_t k1, size_t n_head, double *head);

#endif
