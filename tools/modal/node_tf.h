/* SPDX-License-Identifier: MIT */
/*
 * The 3x3 force-to-displacement transfer function of one node of a modal
 * image,
 *   H(z) = R0 + sum_k phi_k phi_k^T g_k(z),
 *   g_k(z) = z e_q^T (zI - A_k)^-1 b_k - b_k,0
 *          = (beta1 z + beta0) / ((z - l1)(z - l2)),
 * where u[t] = sum_k phi_k x_k,q[t+1] + D f[t] (engine_modal.c) and
 * R0 = H(infinity) = sum_k phi_k phi_k^T b_k,0 + D.  The closed-loop
 * matrix of the force recursion satisfies
 *   det(zI - A_cl) = det(zI - A) det H(z) / det R0,
 * so its poles are the zeros of det H plus the open-loop poles l1, l2 of
 * every mode, minus the poles of det H.  Also a bound on how far H can move
 * along an arc, from the arc's distance to those poles.
 *
 * With an exact FIR head of H samples for the dropped modes (the hybrid
 * representation), u[t] = sum_k phi_k x_k,q[t+1] + sum_{s<H} D_s f[t-s]:
 *   H(z) = R0 + sum_k phi_k phi_k^T g_k(z) + sum_{s=1}^{H-1} D_s z^-s,
 * R0 = sum_k phi_k phi_k^T b_k,0 + D_0.  The ring of the last H-1 forces
 * adds 3(H-1) open-loop poles at z = 0 to A and the same poles to H, so
 * the identity above holds unchanged; for H = 1 this is the plain image
 * with D = D_0.
 */
#ifndef IRDM_TOOLS_NODE_TF_H
#define IRDM_TOOLS_NODE_TF_H

#include <complex.h>
#include <stddef.h>

#include "irdm/image_format.h"

struct irdm_node_tf {
	size_t K;
	size_t n_pad;  /* length of the mode arrays: even, > K */
	double r0[9];  /* R[0], row-major */
	double *t, *d; /* den_k(z) = z^2 - t z + d */
	double *beta1, *beta0;
	double *p;            /* phi phi^T: xx, xy, xz, yy, yz, zz arrays */
	double complex *pole; /* 2 per mode */
	double *pole_xy;      /* the poles of H: re, im of the first, of the second */
	const double *head;   /* borrowed: n_head blocks D_s of 9, row-major */
	size_t n_head;        /* > 1: head terms in H, and a pole of H at 0 */
};

/* phi_c: 3 x K row-major; D: 3x3 or NULL.  0, or -1 out of memory. */
int irdm_node_tf_init(struct irdm_node_tf *tf, const struct irdm_mode *zoh, size_t K,
		      const double *phi_c, const double *D);
/* The same with a head: n_head blocks of 9 ([s][i][j]), head[0] = D_0
 * added to R0 as D is above; tf borrows head, which must outlive it.
 * n_head 0 or head NULL: no correction. */
int irdm_node_tf_init_head(struct irdm_node_tf *tf, const struct irdm_mode *zoh, size_t K,
			   const double *phi_c, const double *head, size_t n_head);
void irdm_node_tf_free(struct irdm_node_tf *tf);

/* H(z) and H'(z), row-major; the distance from z to the nearest pole of H. */
void irdm_node_tf_eval(const struct irdm_node_tf *tf, double complex z, double complex H[9],
		       double complex dH[9], double *pole_dist);

/* Open-loop poles with |l| < r: both of every mode, and a head's ring of
 * 3(n_head - 1) at 0 (r > 0). */
size_t irdm_node_tf_poles_inside(const struct irdm_node_tf *tf, double r);

/* All open-loop poles, the closed loop's order: 2K + 3(n_head - 1). */
size_t irdm_node_tf_order(const struct irdm_node_tf *tf);

#endif
