/* SPDX-License-Identifier: MIT */
/* How long a mode rings: the kept modes of a hybrid image (decay.h). */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/error.h"
#include "modal/decay.h"

double irdm_decay_rate(double w, double z)
{
	if (!(w > 0))
		return 0.0;
	if (z <= 1.0)
		return z * w;
	return w / (z + sqrt(z * z - 1.0));
}

double irdm_decay_left(double rate, double t)
{
	return exp(-rate * t);
}

static double left_at(const struct irdm_rayleigh *damp, double horizon_s, double w)
{
	return irdm_decay_left(irdm_decay_rate(w, irdm_rayleigh_ratio(damp, w)), horizon_s);
}

#define CUTOFF_GRID 4096
#define CUTOFF_SPAN 1e6 /* the grid's lowest point: w_max over this */

double irdm_decay_cutoff(const struct irdm_rayleigh *damp, double horizon_s, double left,
			 double w_max)
{
	double ratio = pow(CUTOFF_SPAN, 1.0 / (CUTOFF_GRID - 1)), hi = w_max, lo;

	if (!(w_max > 0))
		return 0;
	if (left_at(damp, horizon_s, w_max) > left)
		return w_max;
	for (int i = 1; i < CUTOFF_GRID; i++, hi = lo) {
		lo = hi / ratio;
		if (!(left_at(damp, horizon_s, lo) > left))
			continue;
		for (int k = 0; k < 60; k++) { /* lo rings over `left`, hi not */
			double mid = sqrt(lo * hi);

			if (left_at(damp, horizon_s, mid) > left)
				lo = mid;
			else
				hi = mid;
		}
		return lo;
	}
	return 0;
}

/* Follow each cycle of the permutation with one column in hand. */
int irdm_modes_permute(struct irdm_modes *m, const size_t *order)
{
	size_t n = m->n_modes, len = m->n;
	bool *done = calloc(n ? n : 1, sizeof(*done));
	double *col = malloc((len ? len : 1) * sizeof(*col));

	if (!done || !col || irdm_modes_rest_permute(m, order)) {
		free(done);
		free(col);
		return IRDM_ENOMEM;
	}
	for (size_t s = 0; s < n; s++) {
		double w2 = m->omega2[s];
		size_t j = s;

		if (done[s] || order[s] == s)
			continue;
		if (m->phi)
			memcpy(col, &m->phi[s * len], len * sizeof(*col));
		for (;;) {
			size_t src = order[j];

			done[j] = true;
			if (src == s)
				break;
			m->omega2[j] = m->omega2[src];
			if (m->phi)
				memcpy(&m->phi[j * len], &m->phi[src * len], len * sizeof(*col));
			j = src;
		}
		m->omega2[j] = w2;
		if (m->phi)
			memcpy(&m->phi[j * len], col, len * sizeof(*col));
	}
	free(done);
	free(col);
	return IRDM_OK;
}
