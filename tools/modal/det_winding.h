/* SPDX-License-Identifier: MIT */
/*
 * The winding number of det H(z) on a circle |z| = r, H a node's transfer
 * function (node_tf.h), by an adaptive walk (det_winding.c).
 */
#ifndef IRDM_TOOLS_DET_WINDING_H
#define IRDM_TOOLS_DET_WINDING_H

#include <complex.h>
#include <stddef.h>

#include "modal/node_tf.h"

struct irdm_tf_point {
	double complex det;
	double complex ld; /* (det H)' / det H = tr(H^-1 H') */
	double pole_dist;  /* to the nearest pole of H */
};

/* det H, (log det H)' and the pole distance at z; -1 if det H is 0 or not
 * finite there. */
int irdm_tf_point_at(const struct irdm_node_tf *tf, double complex z, struct irdm_tf_point *p);

/*
 * On a circle outside every closed-loop pole, the phase velocity of det H,
 * v = d arg / d theta = Re(z (log det H)'), peaks by about r / delta at
 * the angle of a zero delta inside: the highest peaks are the zeros nearest
 * the circle, the largest first.  On a circle with poles outside, v dips
 * by about r / delta next to a zero delta outside.  The walk keeps the
 * IRDM_N_PEAKS highest local maxima and deepest local minima as Newton starts.
 */
#define IRDM_N_PEAKS 4

struct irdm_peaks {
	double complex z[IRDM_N_PEAKS];
	double v[IRDM_N_PEAKS]; /* -INFINITY: none */
};

enum { IRDM_SIDE_HI,
       IRDM_SIDE_LO }; /* peaks (all poles inside), dips */

struct irdm_walk {
	struct irdm_peaks side[2];
	double complex prev_z;
	double prev_v, prev2_v;
	size_t points;
};

/* Winding number of det H on |z| = r, or INT_MIN if unresolved; w: the
 * walk's points and its peaks and dips. */
int irdm_tf_winding(const struct irdm_node_tf *tf, double r, struct irdm_walk *w);

#endif
