/* SPDX-License-Identifier: MIT */
/* representation = auto's candidates (candidates.h). */
#include <math.h>
#include <stdlib.h>

#include "modal/head_split.h"
#include "precompute/candidates.h"

/* The heads tried: short ones tick cheaply but keep more modes. */
static const unsigned heads[] = { 1, 2, 4, 8, 16, 32, 64, 128, 256 };
_Static_assert(sizeof(heads) / sizeof(heads[0]) == IRDM_AUTO_N_HEADS, "IRDM_AUTO_N_HEADS");

/*
 * Per-unit costs estimated from docs/measurements/bench_tick.md, a point
 * on a triangle in contact (the proxy's usual contact, three nodes):
 * every mode of the 6x6x12 cuboid (1764 modes) ticks in 4.92 us, 2.79 ns
 * a mode; the hybrid 300 + 128 head ticks 1.85 us above modal 300 +
 * static correction over 256 samples of age, 7.23 ns each.  Their ratio
 * orders the candidates; the sums are printed as estimates, not timings.
 */
#define NS_PER_MODE 2.79
#define NS_PER_HEAD_SAMPLE 7.23

double irdm_auto_tick_us(size_t modes, unsigned head)
{
	return (NS_PER_MODE * (double)modes + NS_PER_HEAD_SAMPLE * 2.0 * head) * 1e-3;
}

static double max_hz(const struct irdm_modes *m, const size_t *order, size_t k)
{
	double w2 = 0;

	for (size_t i = 0; i < k; i++)
		w2 = fmax(w2, m->omega2[order[i]]);
	return sqrt(w2) / (2 * M_PI);
}

static int by_cost(const void *a, const void *b)
{
	const struct irdm_auto_candidate *x = a, *y = b;

	return (x->tick_us > y->tick_us) - (x->tick_us < y->tick_us);
}

size_t irdm_auto_fewest(struct irdm_split_probe *p, const size_t *rank, size_t n, size_t lo,
			unsigned H, double budget, double *predicted)
{
	size_t hi = n - 1;
	double e;

	irdm_split_begin(p);
	e = irdm_split_try(p, &rank[hi], n - hi, H);
	if (!(e <= budget))
		return 0;
	irdm_split_commit(p);
	*predicted = e;
	while (lo < hi) {
		size_t mid = lo + (hi - lo) / 2;

		e = irdm_split_try(p, &rank[mid], hi - mid, H);
		if (e <= budget) {
			irdm_split_commit(p);
			*predicted = e;
			hi = mid;
		} else {
			lo = mid + 1;
		}
	}
	return hi;
}

static size_t hybrids(const struct irdm_modes *m, const struct irdm_rayleigh *damp, double dt_s,
		      double tol, struct irdm_split_probe *probe, size_t *rank,
		      struct irdm_auto_candidate *out)
{
	size_t n = 0, n_free = 0;

	for (size_t d = 0; d < m->n_modes; d++)
		n_free += !(m->omega2[d] > 0);
	for (size_t i = 0; i < sizeof(heads) / sizeof(heads[0]) && m->n_modes > 1; i++) {
		double predicted = 0;
		size_t k;

		if (irdm_head_split_rank(m, damp, heads[i] * dt_s, rank))
			break;
		k = irdm_auto_fewest(probe, rank, m->n_modes, n_free > 1 ? n_free : 1, heads[i],
				     tol * IRDM_AUTO_PREDICTED_SHARE, &predicted);
		if (!k)
			continue; /* not even every mode but one */
		out[n].modes = k;
		out[n].head = heads[i];
		out[n].predicted = predicted;
		out[n].tick_us = irdm_auto_tick_us(k, heads[i]);
		out[n].kept_max_hz = max_hz(m, rank, k);
		n++;
	}
	return n;
}

/* The truncated candidate's predicted error: the modes past the lowest
 * IRDM_AUTO_TRUNCATED dropped to the static correction. */
static double predict_truncated(const struct irdm_modes *m, struct irdm_split_probe *probe)
{
	size_t n_drop = m->n_modes - IRDM_AUTO_TRUNCATED;
	size_t *drop = malloc(n_drop * sizeof(*drop));
	double e;

	if (!drop)
		return 0; /* built and measured instead */
	for (size_t i = 0; i < n_drop; i++)
		drop[i] = IRDM_AUTO_TRUNCATED + i;
	irdm_split_begin(probe);
	e = irdm_split_try(probe, drop, n_drop, 0);
	free(drop);
	return e;
}

size_t irdm_auto_candidates(const struct irdm_modes *m, const struct irdm_rayleigh *damp,
			    double dt_s, double tol, bool with_hybrids, struct irdm_split_probe *probe,
			    struct irdm_auto_candidate *out)
{
	size_t n = 0, *rank = malloc((m->n_modes ? m->n_modes : 1) * sizeof(*rank));
	double truncated;

	if (rank && with_hybrids)
		n = hybrids(m, damp, dt_s, tol, probe, rank, out);
	free(rank);
	if (m->n_modes > IRDM_AUTO_TRUNCATED &&
	    (truncated = predict_truncated(m, probe)) <= tol) {
		/* the lowest modes and the static correction, no head: the
		 * cheapest tick, right where the dropped modes matter little;
		 * not built when predicted over the target */
		out[n].modes = IRDM_AUTO_TRUNCATED;
		out[n].head = 0;
		out[n].predicted = truncated;
		out[n].tick_us = irdm_auto_tick_us(IRDM_AUTO_TRUNCATED, 0);
		out[n].kept_max_hz = sqrt(m->omega2[IRDM_AUTO_TRUNCATED - 1]) / (2 * M_PI);
		n++;
	}
	out[n].modes = m->n_modes;
	out[n].head = 0;
	out[n].predicted = -1;
	out[n].tick_us = irdm_auto_tick_us(m->n_modes, 0);
	out[n].kept_max_hz = m->n_modes ? sqrt(m->omega2[m->n_modes - 1]) / (2 * M_PI) : 0;
	n++;
	qsort(out, n, sizeof(*out), by_cost);
	return n;
}
