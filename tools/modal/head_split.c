/* SPDX-License-Identifier: MIT */
/* Which modes a hybrid image keeps (head_split.h). */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

#include "irdm/error.h"
#include "modal/decay.h"
#include "modal/head_split.h"

struct left {
	double left;
	size_t d;
};

static int most_left(const void *a, const void *b)
{
	const struct left *x = a, *y = b;

	if (x->left != y->left)
		return (x->left < y->left) - (x->left > y->left);
	return (x->d > y->d) - (x->d < y->d);
}

int irdm_head_split_rank(const struct irdm_modes *m, const struct irdm_rayleigh *damp,
			 double horizon_s, size_t *rank)
{
	size_t n = m->n_modes;
	struct left *l = malloc((n ? n : 1) * sizeof(*l));

	if (!l)
		return IRDM_ENOMEM;
	for (size_t d = 0; d < n; d++) {
		double w = sqrt(fmax(m->omega2[d], 0.0));
		double rate = irdm_decay_rate(w, w > 0 ? irdm_rayleigh_ratio(damp, w) : 0.0);

		l[d] = (struct left){ irdm_decay_left(rate, horizon_s), d };
	}
	qsort(l, n, sizeof(*l), most_left);
	for (size_t i = 0; i < n; i++)
		rank[i] = l[i].d;
	free(l);
	return IRDM_OK;
}

void irdm_head_split_order(const size_t *rank, size_t n, size_t k, size_t *order, bool *dropped)
{
	size_t j = 0;

	for (size_t d = 0; d < n; d++)
		dropped[d] = false;
	for (size_t i = k; i < n; i++)
		dropped[rank[i]] = true;
	for (size_t d = 0; d < n; d++)
		if (!dropped[d])
			order[j++] = d;
	for (size_t d = 0; d < n; d++)
		if (dropped[d])
			order[j++] = d;
}
