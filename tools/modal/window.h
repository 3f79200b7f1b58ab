/* SPDX-License-Identifier: MIT */
/*
 * The window that ends a response without a jump: a Hann taper over the
 * L samples after a kept head, and the sine bump along which the taps'
 * missing sum is put back (precompute/fir_tail.c's FIR tail and
 * modal/exact_head.c's hybrid head share it).
 */
#ifndef IRDM_TOOLS_WINDOW_H
#define IRDM_TOOLS_WINDOW_H

#include <stddef.h>

/* Taper weight of window sample i (0..L-1) and its DC bump shape. */
double irdm_window_taper(size_t i, size_t L);
double irdm_window_bump(size_t i, size_t L);

#endif
