/* SPDX-License-Identifier: MIT */
/*
 * Where a modal image that drops modes is worst: its force error
 * predicted (split.h: the grab's forces on the column's exact response
 * to itself and on the image's, both by direct convolution in double) at
 * every touchable column, on shorter runs, so that the error measurement
 * (measure.h) and auto's sizing look where the error is and not only
 * where a spread over the surface puts them.
 *
 * What makes every column affordable: the runs last irdm_screen_ticks()
 * (300 ticks, or 4 heads when longer; the measurement's are about a
 * second), and each mode's response and miss are cut where they stay
 * under 1e-12 of their peak (the dropped modes that decay within a few
 * ticks cost a few samples, not the run).  It ranks the columns; the
 * measurement at the columns it ranks first has the last word.
 */
#ifndef IRDM_TOOLS_ACCURACY_SCREEN_H
#define IRDM_TOOLS_ACCURACY_SCREEN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "modal/modal.h"

/* The runs' length for a head of H at the measurement's N ticks. */
size_t irdm_screen_ticks(unsigned H, size_t N);

/*
 * The k columns of the largest prediction, largest first, for an image that
 * drops the modes of m marked in dropped (every elastic mode solved;
 * w^2 = 0 never counts as dropped) into a head of H samples (0: the
 * static correction) and keeps the rest, at columns
 * col_dofs (3 free DoFs or -1 each, n_cols of them), for the
 * measurement's runs of N ticks;
 * zoh: every mode of m discretised.  cols: k entries; est (NULL or k
 * entries): their predictions on the shorter runs (INFINITY where the
 * image's first sample is singular).
 * Return: how many (fewer than k when there are fewer columns, none when
 * nothing is dropped or out of memory).
 */
size_t irdm_screen_columns(const struct irdm_modes *m, const struct irdm_mode *zoh, const bool *dropped,
			   unsigned H, const int64_t *col_dofs, size_t n_cols, size_t N, size_t k,
			   uint32_t *cols, double *est);

#endif
