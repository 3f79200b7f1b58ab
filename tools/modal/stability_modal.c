/* SPDX-License-Identifier: MIT */
/*
 * The modal stability certificate by the argument principle.
 *
 * det(zI - A_cl) = det(zI - A) det H(z) / det R0 (node_tf.h), so the
 * closed-loop poles inside |z| < r number
 *   N(r) = (open-loop poles inside r, in closed form) + wind_r(det H),
 * the winding number counting zeros minus poles of det H; pole-zero
 * cancellations cancel in the sum.  The spectral radius is the least r
 * with N(r) = 2K.  A head of H samples (node_tf.h) adds the ring's 3(H-1)
 * open-loop poles at z = 0, inside every circle searched (r >=
 * IRDM_STAB_RHO_MIN > 0), to both counts: N(r) = 2K + 3(H-1) when all are
 * inside.  Counted explicitly, N stays >= 0 (the search's -1 means
 * unresolved) when more than 2K ring poles are outside.
 *
 * Radius (the winding number is det_winding.c's): Newton on det H from
 * the phase-velocity peaks of the last circle with every pole inside and
 * the dips of the last one with poles outside, and on det H times one
 * mode's denominator from beside the top open-loop poles.  The largest
 * root z* in the bracket gets a circle at |z*| (1 + REL_TOL / 4): all
 * poles inside makes that the upper bound rho, and |z*| (a closed-loop
 * pole, to Newton's tolerance) the lower bound.  Without a root in the
 * bracket: bisection on r.
 */
#include <limits.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>

#include "modal/det_winding.h"
#include "modal/mat3c.h"
#include "modal/node_tf.h"
#include "modal/stability.h"

/* -DIRDM_STAB_TRACE: every circle and Newton root on stderr */
#ifdef IRDM_STAB_TRACE
#define TRACE(...) fprintf(stderr, __VA_ARGS__)
#else
#define TRACE(...) ((void)0)
#endif

#define REL_TOL 1e-8 /* bracket width rho / rho_lo - 1 */

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
		struct irdm_tf_point p;
		if (irdm_tf_point_at(tf, z, &p)) {
			*root = z; /* det H exactly 0 (or not finite: checked below) */
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
			return -1; /* diverging: no root of interest there */
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
	long n_all; /* 2K + 3(n_head - 1) closed-loop poles */
	double lo, hi;
	bool lo_certified, lo_newton;
	/* the last hi circle's peaks, the last lo circle's dips; fresh until tried */
	struct irdm_peaks start[2];
	bool fresh[2];
	/* moduli of the roots Newton found beside the top open-loop poles
	 * (the pole itself when the node does not see the mode), or 0 */
	double pole_root[N_POLE_STARTS];
	struct irdm_stab_cert *out;
};

/* Count on |z| = r and move the bracket. */
static void probe(struct search *s, double r)
{
	struct irdm_walk w;

	if (!(r > s->lo && r < s->hi))
		return;
	int wind = irdm_tf_winding(s->tf, r, &w);
	long n = wind == INT_MIN ? -1 : (long)irdm_node_tf_poles_inside(s->tf, r) + wind;
	s->out->circles++;
	s->out->points += w.points;
	TRACE("r %.12f n %ld / %ld points %zu lo %.12f hi %.12f\n", r, n, s->n_all, w.points,
	      s->lo, s->hi);
	int side = n == s->n_all ? IRDM_SIDE_HI : IRDM_SIDE_LO;
	if (side == IRDM_SIDE_HI)
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
			TRACE("newton beside pole %.12f%+.12fi -> %.12f%+.12fi\n", creal(l), cimag(l),
			      creal(root), cimag(root));
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
	for (int side = IRDM_SIDE_HI; side <= IRDM_SIDE_LO; side++)
		for (int i = 0; s->fresh[side] && i < IRDM_N_PEAKS; i++) {
			const struct irdm_peaks *p = &s->start[side];
			double complex root;
			if (p->v[i] == -INFINITY || newton(s->tf, p->z[i], NO_MODE, &root))
				continue;
			s->out->newton++;
			TRACE("newton from %g%+gi -> %.12f%+.12fi\n", creal(p->z[i]), cimag(p->z[i]),
			      creal(root), cimag(root));
			if (cabs(root) > s->lo && cabs(root) < s->hi)
				best = fmax(best, cabs(root));
		}
	s->fresh[IRDM_SIDE_HI] = s->fresh[IRDM_SIDE_LO] = false;
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

int irdm_stability_modal_cert_head(const struct irdm_mode *zoh, size_t K, const double *phi_c,
				   const double *head, size_t n_head, struct irdm_stab_cert *out)
{
	struct irdm_node_tf tf;
	double complex r0[9];

	*out = (struct irdm_stab_cert){ .rho = -1 };
	if (irdm_node_tf_init_head(&tf, zoh, K, phi_c, head, n_head))
		return -1;
	for (int e = 0; e < 9; e++)
		r0[e] = tf.r0[e];
	double det_r0 = creal(irdm_det3c(r0));
	if (!(fabs(det_r0) > 0) || !isfinite(det_r0)) { /* as irdm_stability_modal */
		irdm_node_tf_free(&tf);
		return -1;
	}
	/* open bracket just outside the bounds so the bounds themselves are probed */
	struct search s = { .tf = &tf, .n_all = (long)irdm_node_tf_order(&tf), .lo = IRDM_STAB_RHO_MIN / 2, .hi = IRDM_STAB_RHO_MAX * 2, .out = out };
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

double irdm_stability_modal_ap_head(const struct irdm_mode *zoh, size_t K, const double *phi_c,
				    const double *head, size_t n_head)
{
	struct irdm_stab_cert c;

	return irdm_stability_modal_cert_head(zoh, K, phi_c, head, n_head, &c) ? -1 : c.rho;
}

int irdm_stability_modal_cert(const struct irdm_mode *zoh, size_t K, const double *phi_c,
			      const double *D, struct irdm_stab_cert *out)
{
	return irdm_stability_modal_cert_head(zoh, K, phi_c, D, D ? 1 : 0, out);
}

double irdm_stability_modal_ap(const struct irdm_mode *zoh, size_t K, const double *phi_c,
			       const double *D)
{
	return irdm_stability_modal_ap_head(zoh, K, phi_c, D, D ? 1 : 0);
}
