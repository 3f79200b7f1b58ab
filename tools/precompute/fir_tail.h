/* SPDX-License-Identifier: MIT */
/*
 * An FIR that is stable and keeps its head: the response computed L
 * samples past T, those samples tapered to zero by a Hann window, and the
 * taps' sum restored to the static compliance by a smooth bump over the
 * same samples (modal/window.h).  Samples 0..T-1 are untouched, so the force of the first
 * T ticks after any contact is the exact one; the held force is the
 * static one.  Stability is not assumed: the precompute certifies the
 * result like any FIR (docs/architecture.md, "Numerical hazards").
 */
#ifndef IRDM_TOOLS_FIR_TAIL_H
#define IRDM_TOOLS_FIR_TAIL_H

#include <stddef.h>

#include "precompute/model.h"

/*
 * fir: [col][row][s][3][3] over T + L samples (build.c's layout), the
 * exact response in every sample; the last L become the window.  The
 * static compliance at (row, col) is m's grounded K^-1 or the floating
 * object's elastic compliance (modal/static.c).
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_ENUMERIC if the compliance solve
 * fails (err says why).
 */
int irdm_fir_tail_window(const struct irdm_model *m, bool floating, size_t T, size_t L,
			 double *fir, char *err, size_t errlen);

#endif
