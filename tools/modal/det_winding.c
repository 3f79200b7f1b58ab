/* SPDX-License-Identifier: MIT */
/*
 * The winding number of det H on |z| = r: a walk along the upper half
 * circle (H(conj z) = conj H(z); det H is real at +-r, so the half turns
 * by a multiple of pi) summing the principal phase steps of det H between
 * its points.  A step is exact when
 * det H turns by less than pi along the arc; the walk cannot see the turn
 * between its points, so it accepts an arc only when (arc_ok) the sampled
 * turn is below pi/4, the arc is at most 1 / |(log det H)'| at both ends
 * (zeros, alone or clustered, near the arc make that large) and at most
 * half the distance of both ends to the nearest pole of H (a pole with a
 * zero beside it cancels in (log det H)' from afar, and such a pair
 * straddling the circle turns det H by 2 pi within its own size).  This is
 * the FIR certificate's sampling criterion (stability.c: no sampled phase
 * step above pi/2) made adaptive and strengthened, not a proof: a feature
 * that none of the three tests sees could still be stepped over.  Below
 * ARC_MIN_RAD, or past WALK_MAX_POINTS, the count is unresolved and the
 * search treats the circle as having poles outside (the safe side).
 */
#include <limits.h>
#include <math.h>
#include <stdbool.h>

#include "modal/det_winding.h"
#include "modal/mat3c.h"

#define ARC_MIN_RAD 1e-13       /* shorter arcs: unresolved */
#define WALK_MAX_POINTS 2000000 /* per circle: unresolved beyond */

int irdm_tf_point_at(const struct irdm_node_tf *tf, double complex z, struct irdm_tf_point *p)
{
	double complex H[9], dH[9], adj[9], tr = 0;

	irdm_node_tf_eval(tf, z, H, dH, &p->pole_dist);
	irdm_adj3c(H, adj);
	p->det = irdm_det3c(H);
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
			tr += adj[3 * i + j] * dH[3 * j + i];
	double m = cabs(p->det);
	if (!(m > 0) || !isfinite(m))
		return -1;
	p->ld = tr / p->det;
	return isfinite(cabs(p->ld)) ? 0 : -1;
}

static void keep_peak(struct irdm_peaks *p, double complex z, double v)
{
	int low = 0;

	for (int i = 1; i < IRDM_N_PEAKS; i++)
		if (p->v[i] < p->v[low])
			low = i;
	if (v > p->v[low]) {
		p->v[low] = v;
		p->z[low] = z;
	}
}

/* the walk's last three velocities: the middle one a local max or min? */
static void track_peaks(struct irdm_walk *w, double complex z, const struct irdm_tf_point *b)
{
	double v = creal(z * b->ld);

	if (w->prev_v >= w->prev2_v && w->prev_v >= v)
		keep_peak(&w->side[IRDM_SIDE_HI], w->prev_z, w->prev_v);
	if (w->prev_v <= w->prev2_v && w->prev_v <= v)
		keep_peak(&w->side[IRDM_SIDE_LO], w->prev_z, -w->prev_v);
	w->prev2_v = w->prev_v;
	w->prev_v = v;
	w->prev_z = z;
}

/*
 * An arc is accepted when det H turns by less than MAX_TURN between its
 * ends, its length times |(log det H)'| at either end is at most
 * MAX_LOG_STEP, and it is at most MAX_POLE_STEP times the distance of
 * either end to the nearest pole of H.  Zeros near the arc, alone or in
 * clusters (near-double roots), make |(log det H)'| large: their terms
 * 1 / (z - z_j) add.  A pole next to a zero (a mode the node barely sees)
 * cancels that far from the pair, and a pair straddling the circle turns
 * det H by 2 pi over a stretch the size of the pair, invisible to both
 * tests above; the pole rule resolves every pole, so every such pair, at
 * its own scale.
 */
#define MAX_TURN (M_PI / 4)
#define MAX_LOG_STEP 1.0
#define MAX_POLE_STEP 0.5

static double step_limit(double r, const struct irdm_tf_point *a)
{
	return fmin(MAX_LOG_STEP / cabs(a->ld), MAX_POLE_STEP * a->pole_dist) / r;
}

static bool arc_ok(double r, double step, const struct irdm_tf_point *a,
		   const struct irdm_tf_point *b)
{
	return fabs(carg(b->det / a->det)) < MAX_TURN && step <= step_limit(r, a) && step <= step_limit(r, b);
}

/* Winding number of det H on |z| = r, or INT_MIN if unresolved. */
int irdm_tf_winding(const struct irdm_node_tf *tf, double r, struct irdm_walk *w)
{
	struct irdm_tf_point a, b;
	double theta = 0, step = M_PI / 64, turn = 0;

	*w = (struct irdm_walk){ .points = 1, .prev_v = NAN, .prev2_v = NAN };
	for (int i = 0; i < IRDM_N_PEAKS; i++)
		w->side[IRDM_SIDE_HI].v[i] = w->side[IRDM_SIDE_LO].v[i] = -INFINITY;
	if (irdm_tf_point_at(tf, r, &a))
		return INT_MIN;
	while (theta < M_PI) {
		step = fmin(fmin(step, M_PI - theta), step_limit(r, &a));
		double next = theta + step >= M_PI * (1 - 1e-15) ? M_PI : theta + step;
		double complex z = next == M_PI ? -r : r * cexp(I * next);
		if (step < ARC_MIN_RAD || ++w->points > WALK_MAX_POINTS || irdm_tf_point_at(tf, z, &b))
			return INT_MIN;
		if (!arc_ok(r, next - theta, &a, &b)) {
			step /= 2;
			continue;
		}
		turn += carg(b.det / a.det);
		track_peaks(w, z, &b);
		a = b;
		theta = next;
		step *= 2;
	}
	/* det H is real at +-r: the half circle turns by a multiple of pi,
	 * the whole circle twice as much */
	double n = turn / M_PI;
	if (fabs(n - round(n)) > 1e-3)
		return INT_MIN;
	return (int)lround(n);
}
