/* SPDX-License-Identifier: MIT */
#include <complex.h>
#include <limits.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "modal/fft.h"
#include "modal/lapack.h"
#include "modal/mat3c.h"
#include "modal/stability.h"

#define MAX_FFT (1u << 19)

/* Winding number of det Q on |w| = r sampled at n points, or INT_MIN if det
 * vanishes at a sample; *worst: the largest phase step seen. */
static int winding(const double *R, size_t T, double r, size_t n, double complex *q,
		   double *worst)
{
	/* Normalise by the largest power of r so nothing overflows. */
	double lr = log(r), top = r > 1 ? lr * (double)(T - 1) : 0.0, total = 0;
	double complex prev = 0;

	*worst = 0;
	for (int e = 0; e < 9; e++) {
		double complex *x = &q[(size_t)e * n];
		memset(x, 0, n * sizeof(*x));
		for (size_t s = 0; s < T; s++)
			x[s % n] += R[9 * s + (size_t)e] * exp(lr * (double)s - top);
		irdm_fft_inverse_sign(x, n);
	}
	for (size_t m = 0; m <= n; m++) {
		double complex a[9];
		for (int e = 0; e < 9; e++)
			a[e] = q[(size_t)e * n + m % n];
		double complex d = irdm_det3c(a);
		if (cabs(d) == 0.0)
			return INT_MIN;
		if (m > 0) {
			double step = carg(d / prev);
			total += step;
			*worst = fmax(*worst, fabs(step));
		}
		prev = d;
	}
	return (int)lround(total / (2 * M_PI));
}

/*
 * Zeros of det Q inside |w| < r.  The sampled winding number is exact when
 * no true phase step between samples exceeds pi; we accept a count only when
 * every sampled step is below pi/2, doubling the sampling until it is.
 * -1 when that needs more than 8x the starting points (at least 2^16) (a zero too close
 * to the circle, or rounding noise in det Q near it): the caller stays on
 * the side it has already certified.
 */
/* Past 8x the starting sampling (at least 2^16) large phase steps are
 * rounding noise next to a zero, which finer sampling does not remove. */
static size_t fft_cap(size_t n0)
{
	size_t cap = 8 * n0 > ((size_t)1 << 16) ? 8 * n0 : ((size_t)1 << 16);

	return cap < MAX_FFT ? cap : MAX_FFT;
}

static int zeros_inside(const double *R, size_t T, double r, double complex *buf,
			size_t *n_fft)
{
	/* give up at the cap: the caller stays on its certified side */
	size_t cap = fft_cap(*n_fft);

	for (size_t n = *n_fft; n <= cap; n *= 2) {
		double worst;
		int c = winding(R, T, r, n, buf, &worst);
		if (c != INT_MIN && worst < M_PI / 2) {
			*n_fft = n;
			return c;
		}
	}
	return -1;
}

static size_t pow2_at_least(size_t n)
{
	size_t p = 1;

	while (p < n)
		p *= 2;
	return p;
}

double irdm_stability_fir(const double *R, size_t T)
{
	size_t n_fft = pow2_at_least(4 * T + 16);
	double complex *buf = malloc(9 * fft_cap(n_fft) * sizeof(*buf));
	/* search w radius r = 1/rho in [1/RHO_MAX, 1/RHO_MIN] */
	double r_lo = 1.0 / IRDM_STAB_RHO_MAX, r_hi = 1.0 / IRDM_STAB_RHO_MIN, rho = -1;

	if (!buf)
		return -1;
	int c_lo = zeros_inside(R, T, r_lo, buf, &n_fft);
	if (c_lo != 0) { /* unresolved or zeros already beyond rho max */
		rho = IRDM_STAB_RHO_MAX;
		goto out_free;
	}
	size_t n0 = pow2_at_least(4 * T + 16);
	n_fft = n0;
	if (zeros_inside(R, T, r_hi, buf, &n_fft) == 0) {
		rho = IRDM_STAB_RHO_MIN;
		goto out_free;
	}
	/* Invariant: no zero inside r_lo (certain); some zero inside r_hi or unresolved. */
	for (int it = 0; it < 48 && r_hi / r_lo > 1 + 1e-7; it++) {
		double r = sqrt(r_lo * r_hi);
		n_fft = n0;
		int c = zeros_inside(R, T, r, buf, &n_fft);
		if (c == 0)
			r_lo = r; /* certified: no zero inside r */
		else
			r_hi = r; /* zeros inside, or too close to one to tell:
				     * either way only below r can be certified */
	}
	rho = 1.0 / r_lo;
out_free:
	free(buf);
	return rho;
}

static double max_abs_eig(double *a, int n)
{
	int lwork = -1, info = 0, one = 1;
	double wq = 0, dummy = 0, rho = -1;
	double *wr = malloc((size_t)n * sizeof(double)), *wi = malloc((size_t)n * sizeof(double));

	if (!wr || !wi)
		goto out_free;
	dgeev_("N", "N", &n, a, &n, wr, wi, &dummy, &one, &dummy, &one, &wq, &lwork, &info);
	lwork = (int)wq;
	double *work = malloc((size_t)lwork * sizeof(double));
	if (!work)
		goto out_free;
	dgeev_("N", "N", &n, a, &n, wr, wi, &dummy, &one, &dummy, &one, work, &lwork, &info);
	free(work);
	if (info)
		goto out_free;
	rho = 0;
	for (int i = 0; i < n; i++)
		rho = fmax(rho, hypot(wr[i], wi[i]));
out_free:
	free(wr);
	free(wi);
	return rho;
}

/* inv of a 3x3 row-major; returns 0 when singular */
static int inv3(const double a[9], double b[9])
{
	double det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) + a[2] * (a[3] * a[7] - a[4] * a[6]);

	if (!(fabs(det) > 0) || !isfinite(det))
		return -1;
	b[0] = (a[4] * a[8] - a[5] * a[7]) / det;
	b[1] = (a[2] * a[7] - a[1] * a[8]) / det;
	b[2] = (a[1] * a[5] - a[2] * a[4]) / det;
	b[3] = (a[5] * a[6] - a[3] * a[8]) / det;
	b[4] = (a[0] * a[8] - a[2] * a[6]) / det;
	b[5] = (a[2] * a[3] - a[0] * a[5]) / det;
	b[6] = (a[3] * a[7] - a[4] * a[6]) / det;
	b[7] = (a[1] * a[6] - a[0] * a[7]) / det;
	b[8] = (a[0] * a[4] - a[1] * a[3]) / det;
	return 0;
}

double irdm_stability_fir_companion(const double *R, size_t T)
{
	/* F[t] = -sum_{s>=1} R0^-1 R[s] F[t-s]: state (F[t-1] .. F[t-T+1]) */
	int n = 3 * (int)(T - 1);
	double r0i[9], rho = -1;

	if (T < 2)
		return 0.0;
	if (inv3(R, r0i))
		return -1;
	double *a = calloc((size_t)n * n, sizeof(double));
	if (!a)
		return -1;
	for (size_t s = 1; s < T; s++)
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++) {
				double v = 0;
				for (int k = 0; k < 3; k++)
					v -= r0i[3 * i + k] * R[9 * s + 3 * (size_t)k + (size_t)j];
				/* column-major: row i, column 3(s-1)+j */
				a[(size_t)(3 * (s - 1) + (size_t)j) * n + (size_t)i] = v;
			}
	for (int i = 3; i < n; i++)
		a[(size_t)(i - 3) * n + (size_t)i] = 1.0; /* shift register */
	rho = max_abs_eig(a, n);
	free(a);
	return rho;
}

/* R0 = sum_k phi_k phi_k^T b_k,0 + D_0, summed in node_tf.c's order; its
 * inverse, or -1 if singular. */
static int modal_r0_inv(const struct irdm_mode *zoh, size_t K, const double *phi_c,
			const double *D0, double r0i[9])
{
	double r0[9] = { 0 };

	for (size_t k = 0; k < K; k++)
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++)
				r0[3 * i + j] += phi_c[(size_t)i * K + k] * phi_c[(size_t)j * K + k] * zoh[k].b[0];
	if (D0)
		for (int e = 0; e < 9; e++)
			r0[e] += D0[e];
	return inv3(r0, r0i);
}

/*
 * f[t] = -W X[t], X = (x_1 .. x_K, f[t-1] .. f[t-H+1]): W = R0^-1 (C A,
 * D_1 .. D_{H-1}), 3 x n row-major.
 */
static void modal_force_gain(const struct irdm_mode *zoh, size_t K, const double *phi_c,
			     const double *head, size_t n_head, const double r0i[9], double *w,
			     size_t n)
{
	for (size_t k = 0; k < K; k++)
		for (int i = 0; i < 3; i++)
			for (int col = 0; col < 2; col++) {
				double v = 0;
				for (int l = 0; l < 3; l++)
					v += r0i[3 * i + l] * phi_c[(size_t)l * K + k];
				w[(size_t)i * n + 2 * k + (size_t)col] = v * zoh[k].a[col];
			}
	for (size_t s = 1; s < n_head; s++)
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++) {
				double v = 0;
				for (int l = 0; l < 3; l++)
					v += r0i[3 * i + l] * head[9 * s + 3 * (size_t)l + (size_t)j];
				w[(size_t)i * n + 2 * K + 3 * (s - 1) + (size_t)j] = v;
			}
}

double irdm_stability_modal_head(const struct irdm_mode *zoh, size_t K, const double *phi_c,
				 const double *head, size_t n_head)
{
	if (!head)
		n_head = 0;
	size_t ring = n_head > 1 ? 3 * (n_head - 1) : 0, n = 2 * K + ring;
	double r0i[9];

	if (modal_r0_inv(zoh, K, phi_c, n_head ? head : NULL, r0i))
		return -1;
	double *a = calloc(n * n, sizeof(double));
	double *w = malloc(3 * n * sizeof(double));
	double rho = -1;
	if (!a || !w)
		goto out_free;
	modal_force_gain(zoh, K, phi_c, head, n_head, r0i, w, n);
	/* x[t+1] = A x - B W X, B rows (2k, 2k+1) = b_k phi_ck^T; column-major a */
	for (size_t k = 0; k < K; k++)
		for (int row = 0; row < 2; row++) {
			size_t r = 2 * k + (size_t)row;
			for (int col = 0; col < 2; col++)
				a[(2 * k + (size_t)col) * n + r] = zoh[k].a[2 * row + col];
			for (size_t c = 0; c < n; c++) {
				double bw = 0;
				for (int i = 0; i < 3; i++)
					bw += phi_c[(size_t)i * K + k] * w[(size_t)i * n + c];
				a[c * n + r] -= zoh[k].b[row] * bw;
			}
		}
	/* the ring: f[t] = -W X into its first slot, the others shift down */
	for (size_t c = 0; ring && c < n; c++)
		for (size_t i = 0; i < 3; i++)
			a[c * n + 2 * K + i] = -w[i * n + c];
	for (size_t i = 2 * K + 3; i < n; i++)
		a[(i - 3) * n + i] = 1.0;
	rho = max_abs_eig(a, (int)n);
out_free:
	free(a);
	free(w);
	return rho;
}

double irdm_stability_modal(const struct irdm_mode *zoh, size_t K, const double *phi_c,
			    const double *D)
{
	return irdm_stability_modal_head(zoh, K, phi_c, D, D ? 1 : 0);
}
