/* SPDX-License-Identifier: MIT */
/*
 * The modal stability certificate by the argument principle (issue 11).
 *
 * det(zI - A_cl) = det(zI - A) det H(z) / det R0 (node_tf.h), so the
 * closed-loop poles inside |z| < r number
 *   N(r) = (open-loop poles inside r, in closed form) + wind_r(det H),
 * the winding number counting zeros minus poles of det H; pole-zero
 * cancellations cancel in the sum.  The spectral radius is the least r
 * with N(r) = 2K.
 *
 * Winding: a walk along the upper half circle (H(conj z) = conj H(z))
 * whose every arc from z carries the bound
 *   ||H(z)^-1||_F (sup_arc ||H(w) - H(z)||_2 + rounding) <= 1/2,
 * so on the arc H(w) = H(z)(I + E), ||E|| <= 1/2: every eigenvalue of I + E
 * stays within pi/6 of the positive axis and det H(w) turns by less than
 * pi/2 from det H(z).  The principal phase step between the arc's ends is
 * then the true one, and the sum is the exact winding number, however
 * close a zero, a pole or a near-double root lies (the arcs shrink near
 * it; below ARC_MIN_RAD the count is given up as unresolved).  The
 * rounding allowance is an a-priori bound of the error of H, not a
 * running error analysis.
 *
 * Radius: bisection on r, with Newton on det H from the sharpest point of
 * each circle found to enclose too few poles; a Newton root z* is then
 * bracketed by circles at |z*| (1 -+ REL_TOL / 4).  The result rho is a
 * certified upper bound; rho_lo a certified lower bound when the count
 * there was resolved.
 */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>

#include "modal/mat3c.h"
#include "modal/node_tf.h"
#include "modal/stability.h"

/* -DIRDM_STAB_TRACE: every circle and Newton root on stderr */
#ifdef IRDM_STAB_TRACE
#define TRACE(...) fprintf(stderr, __VA_ARGS__)
#else
#define TRACE(...) ((void)0)
#endif

#define REL_TOL 1e-8            /* bracket width rho / rho_lo - 1 */
#define ARC_MIN_RAD 1e-13       /* shorter arcs: unresolved */
#define WALK_MAX_POINTS 2000000 /* per circle: unresolved beyond */

struct point {
	double complex det;
	double complex ld;   /* (det H)' / det H = tr(H^-1 H') */
	double pole_dist;    /* to the nearest pole of H */
};

static int point_at(const struct irdm_node_tf *tf, double complex z, struct point *p)
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

/*
 * On a circle outside every closed-loop pole, the phase velocity of det H,
 * v = d arg / d theta = Re(z (log det H)'), peaks by about r / delta at
 * the angle of a zero delta inside: the highest peaks are the zeros nearest
 * the circle, the largest first.  On a circle with poles outside, v dips
 * by about r / delta next to a zero delta outside.  The walk keeps the
 * N_PEAKS highest local maxima and deepest local minima as Newton starts.
 */
#define N_PEAKS 4

struct peaks {
	double complex z[N_PEAKS];
	double v[N_PEAKS];      /* -INFINITY: none */
};

enum { SIDE_HI, SIDE_LO };      /* peaks (all poles inside), dips */

struct walk {
	struct peaks side[2];
	double complex prev_z;
	double prev_v, prev2_v;
	size_t points;
};

static void keep_peak(struct peaks *p, double complex z, double v)
{
	int low = 0;

	for (int i = 1; i < N_PEAKS; i++)
		if (p->v[i] < p->v[low])
			low = i;
	if (v > p->v[low]) {
		p->v[low] = v;
		p->z[low] = z;
	}
}

/* the walk's last three velocities: the middle one a local max or min? */
static void track_peaks(struct walk *w, double complex z, const struct point *b)
{
	double v = creal(z * b->ld);

	if (w->prev_v >= w->prev2_v && w->prev_v >= v)
		keep_peak(&w->side[SIDE_HI], w->prev_z, w->prev_v);
	if (w->prev_v <= w->prev2_v && w->prev_v <= v)
		keep_peak(&w->side[SIDE_LO], w->prev_z, -w->prev_v);
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

static double step_limit(double r, const struct point *a)
{
	return fmin(MAX_LOG_STEP / cabs(a->ld), MAX_POLE_STEP * a->pole_dist) / r;
}

static bool arc_ok(double r, double step, const struct point *a, const struct point *b)
{
	return fabs(carg(b->det / a->det)) < MAX_TURN && step <= step_limit(r, a)
	       && step <= step_limit(r, b);
}

/* Winding number of det H on |z| = r, or INT_MIN if unresolved. */
static int winding(const struct irdm_node_tf *tf, double r, struct walk *w)
{
	struct point a, b;
	double theta = 0, step = M_PI / 64, turn = 0;

	*w = (struct walk){ .points = 1, .prev_v = NAN, .prev2_v = NAN };
	for (int i = 0; i < N_PEAKS; i++)
		w->side[SIDE_HI].v[i] = w->side[SIDE_LO].v[i] = -INFINITY;
	if (point_at(tf, r, &a))
		return INT_MIN;
	while (theta < M_PI) {
		step = fmin(fmin(step, M_PI - theta), step_limit(r, &a));
		double next = theta + step >= M_PI * (1 - 1e-15) ? M_PI : theta + step;
		double complex z = next == M_PI ? -r : r * cexp(I * next);
		if (step < ARC_MIN_RAD || ++w->points > WALK_MAX_POINTS || point_at(tf, z, &b))
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

/*
 * Newton on F = det H den_m (den_m the denominator of mode m, or 1 when
 * m == NO_MODE): z -= F / F' = 1 / ((log det H)' + den_m' / den_m).
 * Taking out mode m's poles lets Newton started next to them reach a zero
 * of det H that nearly cancels one (a mode the node barely sees).
 */
#define NO_MODE ((size_t)-1)
/* Newton's last step, relative: 1e-10 is reached at a double root too
 * (linear convergence, and rounding limits it to ~1e-8 anyway): degenerate
 * modes of a symmetric body give double closed-loop poles */
#define NEWTON_TOL 1e-10

static int newton(const struct irdm_node_tf *tf, double complex z, size_t m, double complex *root)
{
	for (int it = 0; it < 50; it++) {
		struct point p;
		if (point_at(tf, z, &p)) {
			*root = z;      /* det H exactly 0 (or not finite: checked below) */
			return isfinite(cabs(z)) ? 0 : -1;
		}
		double complex ld = p.ld;
		if (m != NO_MODE)
			ld += (2 * z - tf->t[m]) / ((z - tf->t[m]) * z + tf->d[m]);
		double complex step = 1 / ld;
		if (!isfinite(cabs(step)))
			return -1;
		z -= step;
		if (!(cabs(z) < 2 * IRDM_STAB_RHO_MAX))
			return -1;      /* diverging: no root of interest there */
		if (cabs(step) <= NEWTON_TOL * cabs(z)) {
			*root = z;
			return 0;
		}
	}
	return -1;
}

/* Newton starts beside the open-loop poles of largest modulus */
#define N_POLE_STARTS 4

struct search {
	const struct irdm_node_tf *tf;
	long n_all;                /* 2K closed-loop poles */
	double lo, hi;
	bool lo_certified, lo_newton;
	/* the last hi circle's peaks, the last lo circle's dips; fresh until tried */
	struct peaks start[2];
	bool fresh[2];
	/* moduli of the roots Newton found beside the top open-loop poles
	 * (the pole itself when the node does not see the mode), or 0 */
	double pole_root[N_POLE_STARTS];
	struct irdm_stab_cert *out;
};

/* Count on |z| = r and move the bracket. */
static void probe(struct search *s, double r)
{
	struct walk w;

	if (!(r > s->lo && r < s->hi))
		return;
	int wind = winding(s->tf, r, &w);
	long n = wind == INT_MIN ? -1 : (long)irdm_node_tf_poles_inside(s->tf, r) + wind;
	s->out->circles++;
	s->out->points += w.points;
	TRACE("r %.12f n %ld / %ld points %zu lo %.12f hi %.12f\n", r, n, s->n_all, w.points, s->lo, s->hi);
	int side = n == s->n_all ? SIDE_HI : SIDE_LO;
	if (side == SIDE_HI)
		s->hi = r;
	else {
		s->lo = r;
		s->lo_certified = n >= 0;
		s->lo_newton = false;
	}
	s->start[side] = w.side[side];
	s->fresh[side] = n >= 0;
}

/* The modes of the N_POLE_STARTS open-loop poles of largest modulus. */
static void top_pole_modes(const struct irdm_node_tf *tf, size_t mode[N_POLE_STARTS])
{
	double mod[N_POLE_STARTS];

	for (int i = 0; i < N_POLE_STARTS; i++) {
		mode[i] = NO_MODE;
		mod[i] = -1;
	}
	for (size_t k = 0; k < 2 * tf->K; k += 2) {
		double m = cabs(tf->pole[k]);
		int low = 0;
		for (int i = 1; i < N_POLE_STARTS; i++)
			if (mod[i] < mod[low])
				low = i;
		if (m > mod[low]) {
			mod[low] = m;
			mode[low] = k / 2;
		}
	}
}

static void pole_roots(struct search *s)
{
	size_t mode[N_POLE_STARTS];

	top_pole_modes(s->tf, mode);
	for (int i = 0; i < N_POLE_STARTS; i++) {
		double complex root, l = mode[i] == NO_MODE ? 0 : s->tf->pole[2 * mode[i]];
		s->pole_root[i] = 0;
		if (mode[i] != NO_MODE && !newton(s->tf, l * (1 + 1e-7), mode[i], &root)) {
			s->out->newton++;
			s->pole_root[i] = cabs(root);
			TRACE("newton beside pole %.12f%+.12fi -> %.12f%+.12fi |z| %.12f\n", creal(l), cimag(l), creal(root), cimag(root), cabs(root));
		}
	}
}

/* Newton from the fresh peaks and dips (and the pole roots); the largest
 * root in the bracket is then tested by a circle just outside it. */
static bool try_root(struct search *s)
{
	double best = 0;

	for (int i = 0; i < N_POLE_STARTS; i++)
		if (s->pole_root[i] > s->lo && s->pole_root[i] < s->hi)
			best = fmax(best, s->pole_root[i]);
	for (int side = SIDE_HI; side <= SIDE_LO; side++)
		for (int i = 0; s->fresh[side] && i < N_PEAKS; i++) {
			const struct peaks *p = &s->start[side];
			double complex root;
			if (p->v[i] == -INFINITY || newton(s->tf, p->z[i], NO_MODE, &root))
				continue;
			s->out->newton++;
			TRACE("newton from %g%+gi (%g) -> %.12f%+.12fi |z| %.12f\n", creal(p->z[i]), cimag(p->z[i]), p->v[i], creal(root), cimag(root), cabs(root));
			if (cabs(root) > s->lo && cabs(root) < s->hi)
				best = fmax(best, cabs(root));
		}
	s->fresh[SIDE_HI] = s->fresh[SIDE_LO] = false;
	if (best == 0)
		return false;
	probe(s, best * (1 + REL_TOL / 4));
	if (s->hi != best * (1 + REL_TOL / 4))
		return true;
	/* a closed-loop pole at |root| to about Newton's last step: the lower bound,
	 * without a circle next to it */
	s->lo = best;
	s->lo_certified = false;
	s->lo_newton = true;
	return true;
}

static void bracket(struct search *s)
{
	for (int it = 0; it < 200 && s->hi / s->lo > 1 + REL_TOL; it++)
		if (!try_root(s))
			probe(s, sqrt(s->lo * s->hi));
}

int irdm_stability_modal_cert(const struct irdm_mode *zoh, size_t K, const double *phi_c,
			      const double *D, struct irdm_stab_cert *out)
{
	struct irdm_node_tf tf;
	double r0[9];

	*out = (struct irdm_stab_cert){ .rho = -1 };
	if (irdm_node_tf_init(&tf, zoh, K, phi_c, D))
		return -1;
	for (int e = 0; e < 9; e++)
		r0[e] = tf.r0[e];
	double det_r0 = r0[0] * (r0[4] * r0[8] - r0[5] * r0[7]) - r0[1] * (r0[3] * r0[8] - r0[5] * r0[6])
			+ r0[2] * (r0[3] * r0[7] - r0[4] * r0[6]);
	if (!(fabs(det_r0) > 0) || !isfinite(det_r0)) {
		irdm_node_tf_free(&tf);
		return -1;
	}
	/* open bracket just outside the bounds so the bounds themselves are probed */
	struct search s = { .tf = &tf, .n_all = 2 * (long)K, .lo = IRDM_STAB_RHO_MIN / 2,
			    .hi = IRDM_STAB_RHO_MAX * 2, .out = out };
	probe(&s, IRDM_STAB_RHO_MAX);
	if (s.hi == IRDM_STAB_RHO_MAX) {
		probe(&s, IRDM_STAB_RHO_MIN);
		if (s.hi != IRDM_STAB_RHO_MIN) {
			pole_roots(&s);
			bracket(&s);
		}
	}
	out->rho = fmin(s.hi, IRDM_STAB_RHO_MAX);
	out->rho_lo = s.hi == IRDM_STAB_RHO_MIN ? 0 : fmin(s.lo, IRDM_STAB_RHO_MAX);
	out->lo_certified = s.hi == IRDM_STAB_RHO_MIN || s.lo_certified;
	out->lo_newton = s.lo_newton;
	irdm_node_tf_free(&tf);
	return 0;
}

double irdm_stability_modal_ap(const struct irdm_mode *zoh, size_t K, const double *phi_c,
			       const double *D)
{
	struct irdm_stab_cert c;

	return irdm_stability_modal_cert(zoh, K, phi_c, D, &c) ? -1 : c.rho;
}
