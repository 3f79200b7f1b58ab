/* SPDX-License-Identifier: MIT */
/*
 * A hybrid image's force error predicted from the model's modes before
 * the image is built, so that representation = auto can size a hybrid
 * (how many modes it keeps) without building and measuring each try.
 *
 * The prediction runs the measurement's runs (accuracy/measure.h: a step
 * and a release of a grab contact along the same push) at a few probed
 * columns on two responses of the column to itself, in double:
 *   the exact one, every mode's ZOH response;
 *   the hybrid's: the same, less what the head misses of each dropped
 *   mode d past the head: its response from 2H on, the taper's cut over
 *   [H, 2H), and the static remainder the head adds back along the sine
 *   bump (modal/exact_head.h), all times phi_d phi_d^T; with no head
 *   (H = 0: the modes kept and the static correction), all of its
 *   response but its static compliance at the first sample.
 * The forces come from direct convolution, as the reference's
 * (accuracy/reference.h).  What it leaves out: the far field and the
 * sparse static correction's dropped blocks (they do not touch a
 * column's own block), storage precision, the engine's arithmetic.  The
 * real measurement, after the build, has the last word.
 */
#ifndef IRDM_TOOLS_ACCURACY_SPLIT_H
#define IRDM_TOOLS_ACCURACY_SPLIT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "modal/modal.h"

struct irdm_split_probe {
	size_t n_cols;               /* probed columns */
	size_t n_modes;              /* every mode of the model */
	size_t N;                    /* ticks of each run */
	const struct irdm_mode *zoh; /* every mode, discretised */
	const double *omega2;        /* every mode's w^2 */
	double *phi;                 /* [d][c][3]: the modes at the probed columns */
	double *R;                   /* [c][s][9]: the exact responses, s < N */
	double *F;                   /* [c][run][s][3]: the exact forces */
	double *Rh;                  /* [c][s][9]: the hybrid's responses so far */
	double *Rt;                  /* [c][s][9]: the ones tried */
	double *Fh;                  /* [s][3] scratch: its forces */
	double *h, *e;               /* [s] scratch: one mode's response, its miss */
};

/*
 * Probe m's every mode (zoh: them discretised) at n_cols columns
 * (col_dofs: 3 free DoFs or -1 each) over runs of N ticks.
 * Return: IRDM_OK; IRDM_ENOMEM (p freed); IRDM_EINVAL if a column's
 * first response sample is singular (a fixed column).
 */
int irdm_split_probe_init(struct irdm_split_probe *p, const struct irdm_modes *m,
			  const struct irdm_mode *zoh, const int64_t *col_dofs, size_t n_cols,
			  size_t N);

/*
 * Sizing a hybrid with a head of H samples, dropping modes a few at a
 * time: begin from the exact responses (nothing dropped); try dropping
 * n_drop more (drop: mode indices; a free mass, w = 0, must not be one)
 * on top of what was committed, which gives the predicted error (relative
 * RMS force, the worst of the columns and runs; INFINITY if the first
 * response sample turned singular); commit the last try.  Every try
 * between a begin and its commits must use the same H.
 */
void irdm_split_begin(struct irdm_split_probe *p);
double irdm_split_try(struct irdm_split_probe *p, const size_t *drop, size_t n_drop, unsigned H);
void irdm_split_commit(struct irdm_split_probe *p);

void irdm_split_probe_free(struct irdm_split_probe *p);

/*
 * The grab's forces F (N x 3) on a column's response to itself R (N x
 * 3x3), in a step run or a release run (measure.h): each active tick the
 * force that puts the column at its target, given every earlier force.
 * Return: false if R[0] is singular.
 */
bool irdm_split_forces(const double *R, size_t N, bool release, double *F);

/*
 * What the hybrid misses of one dropped mode (zoh: it discretised, omega2
 * its w^2 > 0) over N samples, as above (H = 0: the static correction);
 * h: N of scratch, e: the N missed samples.
 */
void irdm_split_miss(const struct irdm_mode *zoh, double omega2, unsigned H, size_t N, double *h,
		     double *e);

#endif
