/* SPDX-License-Identifier: MIT */
/*
 * Stability of the single-contact force recursion
 *   R[0] F[t] = U[t] - sum_{s>=1} R[s] F[t-s]
 * at one node: its spectral radius is the largest |z| with
 * det(sum_s R[s] z^-s) = 0.  Below 1 the recursion is stable.
 */
#ifndef IRDM_TOOLS_STABILITY_H
#define IRDM_TOOLS_STABILITY_H

#include <stddef.h>

#include "irdm/error.h"
#include "irdm/image_format.h"

/* Bounds of the search; a radius outside is reported as the bound. */
#define IRDM_STAB_RHO_MIN 0.5
#define IRDM_STAB_RHO_MAX 2.0

/*
 * FIR, by the argument principle: the number of zeros of det Q(w),
 * Q(w) = sum_s R[s] w^s, inside |w| < r is the winding number of det Q on
 * that circle (FFT-evaluated, refined until no phase step exceeds pi/2);
 * bisection on r gives rho = 1 / min |w|.  R: T blocks of 9 (row-major
 * 3x3).  Returns a certified upper bound of rho (accurate to ~1e-6 unless a
 * zero sits too close to the circle to resolve, then a looser bound).
 */
double irdm_stability_fir(const double *R, size_t T);

/* The same by the eigenvalues of the 3(T-1) block companion matrix (dense
 * LAPACK, O(T^3)); the reference for tests and small T.  -1 on failure. */
double irdm_stability_fir_companion(const double *R, size_t T);

/*
 * Modal: eigenvalues of the closed-loop matrix (I - B R0^-1 C) A of the
 * modal state recursion at one node (dimension 2K).  phi_c: 3 x K
 * row-major (phi_c[i*K + k]); D: 3x3 static correction or NULL.  -1 on
 * failure.
 */
double irdm_stability_modal(const struct irdm_mode *zoh, size_t K, const double *phi_c,
			    const double *D);

/*
 * The same with an exact FIR head (the hybrid representation, node_tf.h):
 * u[t] = sum_k phi_k x_k,q[t+1] + sum_{s<n_head} D_s f[t-s], head: n_head
 * blocks D_s of 9 ([s][i][j] row-major), head[0] = D_0 in place of D
 * (n_head 0 or head NULL: none; n_head 1: the call above with D = head).
 * The eigenvalues of the explicit closed-loop state matrix of dimension
 * 2K + 3(n_head - 1) (the modes and the ring of the last n_head - 1
 * forces): dense LAPACK, the brute-force reference.  -1 on failure.
 */
double irdm_stability_modal_head(const struct irdm_mode *zoh, size_t K, const double *phi_c,
				 const double *head, size_t n_head);

/*
 * Modal, by the argument principle on det H(z), H the node's 3x3
 * force-to-displacement transfer function (stability_modal.c): O(modes)
 * per point of a circle, no eigenproblem.  rho is an upper bound of the
 * spectral radius by a winding number, within REL_TOL = 1e-8 relative of
 * rho_lo.  rho_lo is a lower bound by a winding number (lo_certified), or
 * the modulus of a closed-loop pole Newton converged to (lo_newton), or,
 * with neither, only where the count was unresolved (a root too close to
 * the circle for ARC_MIN_RAD).  Radii
 * outside [IRDM_STAB_RHO_MIN, IRDM_STAB_RHO_MAX] are reported as the bound
 * (rho_lo 0 below it).  -1 if R0 is singular or out of memory.
 */
struct irdm_stab_cert {
	double rho, rho_lo;
	int lo_certified;         /* rho_lo by a winding number */
	int lo_newton;            /* rho_lo = |a closed-loop pole| found by Newton */
	unsigned circles, newton; /* circles walked, Newton roots found */
	size_t points;            /* transfer-function evaluations on circles */
};

int irdm_stability_modal_cert(const struct irdm_mode *zoh, size_t K, const double *phi_c,
			      const double *D, struct irdm_stab_cert *out);

/* The same, rho only (-1 on failure). */
double irdm_stability_modal_ap(const struct irdm_mode *zoh, size_t K, const double *phi_c,
			       const double *D);

/*
 * The certificate with an exact FIR head (head, n_head as for
 * irdm_stability_modal_head): H(z) gains sum_{s>=1} D_s z^-s, a pole of
 * order up to 3(n_head - 1) at z = 0, and the count of closed-loop poles
 * the ring's 3(n_head - 1) open-loop poles there; the search and its
 * accuracy are those of irdm_stability_modal_cert (which is this with
 * head = D, n_head = 1).  Each point costs O(n_head) more (bench_head_cert:
 * ~15 ns per head sample).  Past n_head ~1000, |z|^-n_head overflows on
 * the smallest circles, which then count as unresolved (the safe side).
 */
int irdm_stability_modal_cert_head(const struct irdm_mode *zoh, size_t K, const double *phi_c,
				   const double *head, size_t n_head, struct irdm_stab_cert *out);

/* The same, rho only (-1 on failure). */
double irdm_stability_modal_ap_head(const struct irdm_mode *zoh, size_t K, const double *phi_c,
				    const double *head, size_t n_head);

#endif
