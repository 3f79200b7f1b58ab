/* SPDX-License-Identifier: MIT */
/*
 * Two contacts at once: an image's force error against the exact model
 * when two touchable nodes are grabbed together.  The certificate and
 * the measurement of measure.h are of one contact; with two, the image's
 * 6x6 response couples them through the blocks between the two columns,
 * and a static correction that drops a block leaves that coupling to the
 * kept modes alone (plus the far field, at sample 0).
 *
 * The columns: n of them, every pair of them.  At each pair the two runs
 * of measure.h (a step, a release) at both nodes at once, the same push
 * at both.  The exact model: every mode of m, discretised (zoh), each
 * block R_ab[s] = sum_d phi_d(a) phi_d(b)^T h_d[s] summed while mode d is
 * over 1e-12 of its own peak; the forces solved by direct convolution of
 * the 6x6 system in double.  The image runs in the force engine on its
 * stored values (run.h), as the firmware runs it.  Grounded objects only.
 */
#ifndef IRDM_TOOLS_ACCURACY_PAIRS_H
#define IRDM_TOOLS_ACCURACY_PAIRS_H

#include <stddef.h>
#include <stdint.h>

#include "irdm/image.h"
#include "modal/modal.h"

#define IRDM_PAIRS_COLS 8 /* columns spread over the surface: 28 pairs */
/* A pair's relative RMS force error above this is no approximation: its
 * force recursion diverges (the precompute refuses the image). */
#define IRDM_PAIRS_DIVERGED 1.0

struct irdm_pairs {
	double worst;      /* relative RMS force error over both contacts */
	uint32_t nodes[2]; /* its pair (mesh nodes) */
	const char *run;   /* "step" or "release" */
	size_t n_pairs, ticks;
	double seconds;
};

/*
 * cols: n columns of img (n <= IRDM_PAIRS_COLS), which are m's columns in
 * the same order (col_dofs: 3 free DoFs or -1 each, per column of img).
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_EINVAL (a floating image, fewer than
 * two columns, a singular exact R[0]); the runner's errors.
 */
int irdm_pairs_measure(const struct irdm_image *img, const struct irdm_modes *m,
		       const struct irdm_mode *zoh, const int64_t *col_dofs, const uint32_t *cols,
		       size_t n, struct irdm_pairs *res, char *err, size_t errlen);

#endif
