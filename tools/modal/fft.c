/* SPDX-License-Identifier: MIT */
/* In-place iterative radix-2 FFT, x[m] = sum_s x[s] e^{+2 pi i s m / n}. */
#include <complex.h>
#include <math.h>

#include "modal/fft.h"

void irdm_fft_inverse_sign(double complex *x, size_t n)
{
	for (size_t i = 1, j = 0; i < n; i++) {
		size_t bit = n >> 1;
		for (; j & bit; bit >>= 1)
			j ^= bit;
		j ^= bit;
		if (i < j) {
			double complex t = x[i];
			x[i] = x[j];
			x[j] = t;
		}
	}
	for (size_t len = 2; len <= n; len <<= 1) {
		double ang = 2 * M_PI / (double)len;
		for (size_t k = 0; k < len / 2; k++) {
			/* twiddle computed directly: no drift for long n */
			double complex w = cexp(I * ang * (double)k);
			for (size_t i = 0; i < n; i += len) {
				double complex u = x[i + k], v = x[i + k + len / 2] * w;
				x[i + k] = u + v;
				x[i + k + len / 2] = u - v;
			}
		}
	}
}
