/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "modal/modal.h"
#include "stab_cert.h"

double stab_cert_check(const char *what, size_t c, double dense, const struct irdm_stab_cert *cert)
{
	assert_true(dense >= 0);
	/* the search's bounds are reported as such */
	dense = fmin(fmax(dense, IRDM_STAB_RHO_MIN), IRDM_STAB_RHO_MAX);
	if ((dense < 1) != (cert->rho < 1))
		fail_msg("%s case %zu: dense %.12f, certificate %.12f: verdicts differ", what, c, dense,
			 cert->rho);
	assert_true(cert->lo_certified || cert->lo_newton);
	if (cert->rho == IRDM_STAB_RHO_MIN) { /* every pole inside the lower bound */
		if (!(dense == IRDM_STAB_RHO_MIN && cert->rho_lo == 0))
			fail_msg("%s case %zu: dense %.15f, certificate below %g", what, c, dense,
				 IRDM_STAB_RHO_MIN);
		return dense;
	}
	double lo_tol = cert->lo_certified ? STAB_DENSE_TOL : STAB_NEWTON_LO_TOL;
	if (!(cert->rho >= dense * (1 - STAB_DENSE_TOL) && cert->rho_lo <= dense * (1 + lo_tol) && cert->rho <= cert->rho_lo * (1 + STAB_CERT_WIDTH)))
		fail_msg("%s case %zu: dense %.15f outside [%.15f, %.15f]", what, c, dense, cert->rho_lo,
			 cert->rho);
	return dense;
}

void stab_dropped_head(const struct irdm_mode *zoh, const double *phi, size_t n_all, size_t k0,
		       size_t k1, size_t n_head, double *head)
{
	double *h = malloc(n_head * sizeof(double));

	assert_non_null(h);
	memset(head, 0, 9 * n_head * sizeof(double));
	for (size_t k = k0; k < k1; k++) {
		irdm_zoh_response(&zoh[k], n_head, h);
		for (size_t s = 0; s < n_head; s++)
			for (size_t i = 0; i < 3; i++)
				for (size_t j = 0; j < 3; j++)
					head[9 * s + 3 * i + j] += phi[i * n_all + k] * phi[j * n_all + k] * h[s];
	}
	free(h);
}
