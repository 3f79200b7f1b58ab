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
