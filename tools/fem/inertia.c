/* SPDX-License-Identifier: MIT */
/* Modes below a frequency by the inertia of K - sigma M (inertia.h). */
#include <stdio.h>

#include "fem/factor.h"
#include "fem/inertia.h"

int irdm_fem_count_below(const struct irdm_fem *fem, double sigma, size_t *count, char *err,
			 size_t errlen)
{
	cholmod_common cc;
	cholmod_factor *L = NULL;
	int ret;

	*count = 0;
	cholmod_l_start(&cc);
	/* the simplicial LDL^T keeps D apart (a supernodal or LL^T factor
	 * would stop at the first negative pivot) */
	cc.supernodal = CHOLMOD_SIMPLICIAL;
	cc.final_ll = 0;
	ret = irdm_fem_factor(fem, 1.0, -sigma, "inertia", &cc, &L, err, errlen);
	if (ret)
		goto out_finish;
	if (L->is_ll || L->is_super || L->xtype != CHOLMOD_REAL) {
		snprintf(err, errlen, "inertia: CHOLMOD gave no LDL^T factor");
		ret = IRDM_ENUMERIC;
		goto out_free;
	}
	/* each column's first entry is D(j, j) */
	for (size_t j = 0; j < L->n; j++)
		*count += ((const double *)L->x)[((const SuiteSparse_long *)L->p)[j]] < 0;
out_free:
	cholmod_l_free_factor(&L, &cc);
out_finish:
	cholmod_l_finish(&cc);
	return ret;
}
