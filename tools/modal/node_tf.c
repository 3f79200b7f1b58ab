/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "modal/node_tf.h"

/* Roots of z^2 - t z + d, the mode's open-loop poles (the eigenvalues of
 * A_k), the larger in modulus first when real; stable for t^2 >> d. */
static void mode_poles(double t, double d, double complex l[2])
{
	double disc = t * t - 4 * d;

	if (disc < 0) {
		l[0] = t / 2 + I * (sqrt(-disc) / 2); /* finite: I * x is exact */
		l[1] = conj(l[0]);
		return;
	}
	double s = t + copysign(sqrt(disc), t);
	l[0] = s / 2;
	l[1] = s != 0 ? 2 * d / s : 0;
}

/* Mode arrays padded to an even count with modes of g = 0 (beta = 0,
 * den = z^2: finite on every circle searched) for the 2-wide loop. */
static int alloc_modes(struct irdm_node_tf *tf, size_t K)
{
	size_t n = (K + 1) / 2 * 2 + 2;

	memset(tf, 0, sizeof(*tf));
	tf->K = K;
	tf->n_pad = n;
	tf->t = calloc(14 * n, sizeof(double));
	tf->pole = malloc(2 * (K > 0 ? K : 1) * sizeof(double complex));
	if (!tf->t || !tf->pole) {
		irdm_node_tf_free(tf);
		return -1;
	}
	tf->d = tf->t + n;
	tf->beta1 = tf->t + 2 * n;
	tf->beta0 = tf->t + 3 * n;
	tf->p = tf->t + 4 * n;
	tf->pole_xy = tf->t + 10 * n;
	return 0;
}

int irdm_node_tf_init(struct irdm_node_tf *tf, const struct irdm_mode *zoh, size_t K,
		      const double *phi_c, const double *D)
{
	return irdm_node_tf_init_head(tf, zoh, K, phi_c, D, D ? 1 : 0);
}

int irdm_node_tf_init_head(struct irdm_node_tf *tf, const struct irdm_mode *zoh, size_t K,
			   const double *phi_c, const double *head, size_t n_head)
{
	static const int row[6] = { 0, 0, 0, 1, 1, 2 }, col[6] = { 0, 1, 2, 1, 2, 2 };

	if (alloc_modes(tf, K))
		return -1;
	size_t n = tf->n_pad;
	for (size_t k = 0; k < K; k++) {
		const double *a = zoh[k].a, *b = zoh[k].b;
		double phi[3] = { phi_c[k], phi_c[K + k], phi_c[2 * K + k] };
		tf->t[k] = a[0] + a[3];
		tf->d[k] = a[0] * a[3] - a[1] * a[2];
		/* h - b0 over the common denominator: its z^2 terms cancel */
		tf->beta1[k] = a[0] * b[0] + a[1] * b[1];
		tf->beta0[k] = -b[0] * tf->d[k];
		for (int e = 0; e < 6; e++)
			tf->p[(size_t)e * n + k] = phi[row[e]] * phi[col[e]];
		mode_poles(tf->t[k], tf->d[k], &tf->pole[2 * k]);
		/* a mode the node does not see is no pole of H: far away */
		bool seen = phi[0] != 0 || phi[1] != 0 || phi[2] != 0;
		for (int j = 0; j < 2; j++) {
			tf->pole_xy[(size_t)(2 * j) * n + k] = seen ? creal(tf->pole[2 * k + j]) : 1e150;
			tf->pole_xy[(size_t)(2 * j + 1) * n + k] = seen ? cimag(tf->pole[2 * k + j]) : 0;
		}
		/* R0 summed in the same order as irdm_stability_modal */
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++)
				tf->r0[3 * i + j] += phi[i] * phi[j] * b[0];
	}
	if (!head)
		n_head = 0;
	for (int e = 0; e < 9; e++)
		tf->r0[e] += n_head ? head[e] : 0.0;
	tf->head = head;
	tf->n_head = n_head;
	return 0;
}

void irdm_node_tf_free(struct irdm_node_tf *tf)
{
	free(tf->t);
	free(tf->pole);
	tf->t = NULL;
	tf->pole = NULL;
}

/* 6 symmetric entries -> row-major 3x3, plus a constant */
static void unpack_sym(const double complex s[6], const double *c, double complex out[9])
{
	static const int map[9] = { 0, 1, 2, 1, 3, 4, 2, 4, 5 };

	for (int e = 0; e < 9; e++)
		out[e] = s[map[e]] + (c ? c[e] : 0.0);
}

/* two modes at a time (GNU vector extension, gcc and clang; SSE2 on x86-64) */
typedef double v2d __attribute__((vector_size(16)));
typedef long long v2di __attribute__((vector_size(16)));

static inline v2d load2(const double *p)
{
	v2d v;

	memcpy(&v, p, sizeof(v));
	return v;
}

static inline double sum2(v2d v)
{
	return v[0] + v[1];
}

/*
 * The head's sum_{s=1}^{H-1} D_s w^s, w = 1/z, and its z-derivative
 * -w^2 sum_s s D_s w^(s-1), by Horner in w (value and w-derivative
 * together), all 9 entries (the blocks need not be symmetric); and z = 0,
 * the head's pole, in the pole distance.  |w| <= 1 / IRDM_STAB_RHO_MIN = 2
 * on every circle searched: w^s stays finite for H up to ~1000, and an
 * overflow makes the point non-finite, which the walk counts as
 * unresolved (the safe side).
 */
static void add_head(const struct irdm_node_tf *tf, double complex z, double complex H[9],
		     double complex dH[9], double *pole_dist)
{
	double complex w = 1 / z;
	double wr = creal(w), wi = cimag(w), pr[9] = { 0 }, pi[9] = { 0 }, dr[9] = { 0 },
	       di[9] = { 0 };

	for (size_t s = tf->n_head; s-- > 0;) {
		const double *c = s ? &tf->head[9 * s] : NULL; /* D_0 is in R0 */
		for (int e = 0; e < 9; e++) {
			double t = dr[e] * wr - di[e] * wi + pr[e];
			di[e] = dr[e] * wi + di[e] * wr + pi[e];
			dr[e] = t;
			t = pr[e] * wr - pi[e] * wi + (c ? c[e] : 0.0);
			pi[e] = pr[e] * wi + pi[e] * wr;
			pr[e] = t;
		}
	}
	double complex mw2 = -w * w;
	for (int e = 0; e < 9; e++) {
		H[e] += pr[e] + I * pi[e];
		dH[e] += mw2 * (dr[e] + I * di[e]);
	}
	/* the pad modes (den z^2) happen to put 0 in pole_xy too; the head's
	 * pole does not rely on that */
	*pole_dist = fmin(*pole_dist, cabs(z));
}

void irdm_node_tf_eval(const struct irdm_node_tf *tf, double complex z, double complex H[9],
		       double complex dH[9], double *pole_dist)
{
	const v2d x = { creal(z), creal(z) }, y = { cimag(z), cimag(z) }, one = { 1, 1 };
	const v2d x2y2 = x * x - y * y, y2 = y + y;
	v2d sr[6] = { 0 }, si[6] = { 0 }, dr[6] = { 0 }, di[6] = { 0 };
	v2d near2 = { INFINITY, INFINITY };
	size_t n = tf->n_pad;
	const double *pl = tf->pole_xy;

	/* the whole cost of the certificate: real arithmetic, 2 modes a step */
	for (size_t k = 0; k < n; k += 2) {
		v2d t = load2(&tf->t[k]), b1 = load2(&tf->beta1[k]);
		v2d den_r = x2y2 - t * x + load2(&tf->d[k]), w = x + x - t, den_i = w * y;
		v2d num_r = b1 * x + load2(&tf->beta0[k]), num_i = b1 * y;
		v2d inv = one / (den_r * den_r + den_i * den_i);
		v2d g_r = (num_r * den_r + num_i * den_i) * inv, g_i = (num_i * den_r - num_r * den_i) * inv;
		/* g' = (beta1 - g (2z - t)) / den */
		v2d q_r = b1 - (g_r * w - g_i * y2), q_i = -(g_r * y2 + g_i * w);
		v2d dg_r = (q_r * den_r + q_i * den_i) * inv, dg_i = (q_i * den_r - q_r * den_i) * inv;
		for (int e = 0; e < 6; e++) {
			v2d p = load2(&tf->p[(size_t)e * n + k]);
			sr[e] += p * g_r;
			si[e] += p * g_i;
			dr[e] += p * dg_r;
			di[e] += p * dg_i;
		}
		for (int j = 0; j < 2; j++) {
			v2d ex = x - load2(&pl[(size_t)(2 * j) * n + k]);
			v2d ey = y - load2(&pl[(size_t)(2 * j + 1) * n + k]);
			v2d q = ex * ex + ey * ey;
			v2di less = q < near2;
			near2 = (v2d)((less & (v2di)q) | (~less & (v2di)near2));
		}
	}
	*pole_dist = sqrt(fmin(near2[0], near2[1]));
	double complex s[6], ds[6];
	for (int e = 0; e < 6; e++) {
		s[e] = sum2(sr[e]) + I * sum2(si[e]);
		ds[e] = sum2(dr[e]) + I * sum2(di[e]);
	}
	unpack_sym(s, tf->r0, H);
	unpack_sym(ds, NULL, dH);
	if (tf->n_head > 1)
		add_head(tf, z, H, dH, pole_dist);
}

/* the head's ring of the last n_head - 1 forces: 3 poles at 0 each */
static size_t ring_poles(const struct irdm_node_tf *tf)
{
	return tf->n_head > 1 ? 3 * (tf->n_head - 1) : 0;
}

size_t irdm_node_tf_order(const struct irdm_node_tf *tf)
{
	return 2 * tf->K + ring_poles(tf);
}

size_t irdm_node_tf_poles_inside(const struct irdm_node_tf *tf, double r)
{
	size_t n = r > 0 ? ring_poles(tf) : 0;

	for (size_t k = 0; k < 2 * tf->K; k++)
		n += cabs(tf->pole[k]) < r;
	return n;
}
