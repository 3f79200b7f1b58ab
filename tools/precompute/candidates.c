/* SPDX-License-Identifier: MIT */
/* representation = auto's candidates (candidates.h). */
#include <math.h>
#include <stdlib.h>

#include "modal/decay.h"
#include "precompute/candidates.h"

/* The heads tried: short ones tick cheaply but keep more modes. */
static const unsigned heads[] = { 16, 32, 64, 128, 256 };

/*
 * Per-unit costs estimated from docs/measurements/bench_tick.md, one
 * touching node: every mode of the 6x6x12 cuboid (1764 modes) ticks in
 * 10.2 us, 5.8 ns a mode; the hybrid 300 + 128 head ticks 2.2 us above
 * modal 300 + static correction over 256 samples of age, 8.6 ns each.
 */
#define NS_PER_MODE 5.8
#define NS_PER_HEAD_SAMPLE 8.6

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

size_t irdm_auto_candidates(const struct irdm_modes *m, const struct irdm_rayleigh *damp,
			    double dt_s, double tol, struct irdm_auto_candidate *out)
{
	size_t n = 0, *order = malloc((m->n_modes ? m->n_modes : 1) * sizeof(*order));

	for (size_t i = 0; order && i < sizeof(heads) / sizeof(heads[0]); i++) {
		size_t k = irdm_modes_by_decay(m, damp, heads[i] * dt_s, tol, order);

		if (k >= m->n_modes)
			continue; /* nothing rings down within it: every mode */
		out[n].modes = k ? k : 1;
		out[n].head = heads[i];
		out[n].tick_us = irdm_auto_tick_us(out[n].modes, heads[i]);
		out[n].kept_max_hz = max_hz(m, order, out[n].modes);
		n++;
	}
	free(order);
	if (m->n_modes > IRDM_AUTO_TRUNCATED) {
		/* the lowest modes and the static correction, no head: the
		 * cheapest tick, right where the dropped modes matter little */
		out[n].modes = IRDM_AUTO_TRUNCATED;
		out[n].head = 0;
		out[n].tick_us = irdm_auto_tick_us(IRDM_AUTO_TRUNCATED, 0);
		out[n].kept_max_hz = sqrt(m->omega2[IRDM_AUTO_TRUNCATED - 1]) / (2 * M_PI);
		n++;
	}
	out[n].modes = m->n_modes;
	out[n].head = 0;
	out[n].tick_us = irdm_auto_tick_us(m->n_modes, 0);
	out[n].kept_max_hz = m->n_modes ? sqrt(m->omega2[m->n_modes - 1]) / (2 * M_PI) : 0;
	n++;
	qsort(out, n, sizeof(*out), by_cost);
	return n;
}
