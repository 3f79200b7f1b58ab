/* SPDX-License-Identifier: MIT */
#ifndef IRDM_TOOLS_FFT_H
#define IRDM_TOOLS_FFT_H
#include <complex.h>
#include <stddef.h>
/* n must be a power of two. */
void irdm_fft_inverse_sign(double complex *x, size_t n);
#endif
