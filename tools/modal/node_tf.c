/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "modal/node_tf.h"

/* Roots of z^2 - t z + d, the mode's open-loop poles (the eigenvalues of
 * A_k), the larger in modulus first when real; stable for t^2 >> d. */
static void mode_poles(double t, double d, double complex l[2])
{
	double disc = t * t - 4 * d;

	if (disc < 0) {
		l[0] = CMPLX(t / 2, sqrt(-disc) / 2);
		l[1] = conj(l[0]);
		return;
	}
	double s = t + copysign(sqrt(disc), t);
	l[0] = s / 2;
	l[1] = s != 0 ? 2 * d / s : 0;
}

static int alloc_modes(struct irdm_node_tf *tf, size_t K)
{
	size_t n = K > 0 ? K : 1;

	memset(tf, 0, sizeof(*tf));
	tf->K = K;
	tf->t = malloc(4 * n * sizeof(double));
	tf->p = malloc(6 * n * sizeof(double));
	tf->pole = malloc(2 * n * sizeof(double complex));
	if (!tf->t || !tf->p || !tf->pole) {
		irdm_node_tf_free(tf);
		return -1;
	}
	tf->d = tf->t + n;
	tf->beta1 = tf->t + 2 * n;
	tf->beta0 = tf->t + 3 * n;
	return 0;
}

int irdm_node_tf_init(struct irdm_node_tf *tf, const struct irdm_mode *zoh, size_t K,
		      const double *phi_c, const double *D)
{
	static const int row[6] = { 0, 0, 0, 1, 1, 2 }, col[6] = { 0, 1, 2, 1, 2, 2 };

	if (alloc_modes(tf, K))
		return -1;
	for (size_t k = 0; k < K; k++) {
		const double *a = zoh[k].a, *b = zoh[k].b;
		double phi[3] = { phi_c[k], phi_c[K + k], phi_c[2 * K + k] };
		tf->t[k] = a[0] + a[3];
		tf->d[k] = a[0] * a[3] - a[1] * a[2];
		/* h - b0 over the common denominator: its z^2 terms cancel */
		tf->beta1[k] = a[0] * b[0] + a[1] * b[1];
		tf->beta0[k] = -b[0] * tf->d[k];
		for (int e = 0; e < 6; e++)
			tf->p[6 * k + (size_t)e] = phi[row[e]] * phi[col[e]];
		mode_poles(tf->t[k], tf->d[k], &tf->pole[2 * k]);
		/* R0 summed in the same order as irdm_stability_modal */
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++)
				tf->r0[3 * i + j] += phi[i] * phi[j] * b[0];
	}
	for (int e = 0; e < 9; e++)
		tf->r0[e] += D ? D[e] : 0.0;
	return 0;
}

void irdm_node_tf_free(struct irdm_node_tf *tf)
{
	free(tf->t);
	free(tf->p);
	free(tf->pole);
	tf->t = tf->p = NULL;
	tf->pole = NULL;
}

/* 6 symmetric entries -> row-major 3x3, plus a constant */
static void unpack_sym(const double complex s[6], const double *c, double complex out[9])
{
	static const int map[9] = { 0, 1, 2, 1, 3, 4, 2, 4, 5 };

	for (int e = 0; e < 9; e++)
		out[e] = s[map[e]] + (c ? c[e] : 0.0);
}

void irdm_node_tf_eval(const struct irdm_node_tf *tf, double complex z, double complex H[9],
		       double complex dH[9])
{
	double x = creal(z), y = cimag(z), sr[6] = { 0 }, si[6] = { 0 }, dr[6] = { 0 }, di[6] = { 0 };

	/* real arithmetic: this loop is the whole cost of the certificate */
	for (size_t k = 0; k < tf->K; k++) {
		double den_r = x * x - y * y - tf->t[k] * x + tf->d[k], den_i = (2 * x - tf->t[k]) * y;
		double num_r = tf->beta1[k] * x + tf->beta0[k], num_i = tf->beta1[k] * y;
		double inv = 1.0 / (den_r * den_r + den_i * den_i);
		double g_r = (num_r * den_r + num_i * den_i) * inv, g_i = (num_i * den_r - num_r * den_i) * inv;
		const double *p = &tf->p[6 * k];
		for (int e = 0; e < 6; e++) {
			sr[e] += p[e] * g_r;
			si[e] += p[e] * g_i;
		}
		if (dH) {
			/* g' = (beta1 - g (2z - t)) / den */
			double q_r = tf->beta1[k] - (g_r * (2 * x - tf->t[k]) - g_i * 2 * y);
			double q_i = -(g_r * 2 * y + g_i * (2 * x - tf->t[k]));
			double dg_r = (q_r * den_r + q_i * den_i) * inv, dg_i = (q_i * den_r - q_r * den_i) * inv;
			for (int e = 0; e < 6; e++) {
				dr[e] += p[e] * dg_r;
				di[e] += p[e] * dg_i;
			}
		}
	}
	double complex s[6], ds[6];
	for (int e = 0; e < 6; e++) {
		s[e] = CMPLX(sr[e], si[e]);
		ds[e] = CMPLX(dr[e], di[e]);
	}
	unpack_sym(s, tf->r0, H);
	if (dH)
		unpack_sym(ds, NULL, dH);
}

size_t irdm_node_tf_poles_inside(const struct irdm_node_tf *tf, double r)
{
	size_t n = 0;

	for (size_t k = 0; k < 2 * tf->K; k++)
		n += cabs(tf->pole[k]) < r;
	return n;
}
