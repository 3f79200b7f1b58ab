/* SPDX-License-Identifier: MIT */
/*
 * representation = auto's candidates: for each head length H of a few,
 * the hybrid that keeps in its modal recursion the fewest of the modes
 * ringing longest past the head (modal/head_split.h) whose predicted
 * force error is within half the target (accuracy/split.h), and gives
 * the head the rest; the lowest modes
 * with the static correction alone; then every mode.
 * They are tried cheapest to tick first.
 */
#ifndef IRDM_TOOLS_CANDIDATES_H
#define IRDM_TOOLS_CANDIDATES_H

#include <stdbool.h>
#include <stddef.h>

#include "fem/fem.h"
#include "accuracy/split.h"
#include "modal/modal.h"

#define IRDM_AUTO_N_HEADS 9 /* head lengths tried (candidates.c) */
/* a hybrid per head, the truncated one, every mode */
#define IRDM_AUTO_MAX_CANDIDATES (IRDM_AUTO_N_HEADS + 2)
#define IRDM_AUTO_TRUNCATED 300 /* modes of the truncated candidate */

struct irdm_auto_candidate {
	size_t modes;       /* kept in the recursion; all of them: no head */
	unsigned head;      /* samples of the dropped modes' exact head (0: none) */
	double predicted;   /* its predicted error (-1: every mode, none) */
	double tick_us;     /* estimated tick cost, one touching node */
	double kept_max_hz; /* the highest frequency kept */
};

/*
 * The share of max_error a hybrid is sized to by the prediction: the
 * rest is room for what the prediction leaves out (accuracy/split.h).
 */
#define IRDM_AUTO_PREDICTED_SHARE 0.5

/*
 * The fewest modes of rank (every mode of p's model, n) a head of H (0:
 * the static correction) may keep, at least lo >= 1, with the error
 * predicted on p within budget: halving the step from every mode but
 * one, each drop tried on top of the ones that held (the prediction's
 * error grows as modes are dropped); *predicted: its prediction.
 * Return: 0 if even every mode but one misses it.
 */
size_t irdm_auto_fewest(struct irdm_split_probe *p, const size_t *rank, size_t n, size_t lo,
			unsigned H, double budget, double *predicted);

/*
 * Estimated tick cost (us) of one touching node on an image of `modes`
 * modes and a head of `head` samples (plus as many tapered): the modal
 * recursion costs per mode, the head's sum per sample of age.
 */
double irdm_auto_tick_us(size_t modes, unsigned head);

/*
 * The candidates for m (every elastic mode, ascending) under damp at
 * dt_s for an error target tol: per head length (unless !with_hybrids),
 * the hybrid of the
 * fewest modes by irdm_head_split_rank() whose error predicted on probe
 * (made from m) is within tol / 2, when one keeps fewer than every mode;
 * the lowest IRDM_AUTO_TRUNCATED modes with the static correction and
 * no head (when m has more and its predicted error is within tol); then
 * every mode; ordered by estimated tick cost.  A candidate with a head and fewer than every mode is a hybrid;
 * without a head and fewer, the truncated one.
 * out: IRDM_AUTO_MAX_CANDIDATES entries.
 * Return: how many.
 */
size_t irdm_auto_candidates(const struct irdm_modes *m, const struct irdm_rayleigh *damp,
			    double dt_s, double tol, bool with_hybrids, struct irdm_split_probe *probe,
			    struct irdm_auto_candidate *out);

#endif
