/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

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
	double lo_tol = cert->lo_certified ? STAB_DENSE_TOL : STAB_NEWTON_LO_TOL;
	if (!(cert->rho >= dense * (1 - STAB_DENSE_TOL) && cert->rho_lo <= dense * (1 + lo_tol)
	      && cert->rho <= cert->rho_lo * (1 + STAB_CERT_WIDTH)))
		fail_msg("%s case %zu: dense %.15f outside [%.15f, %.15f]", what, c, dense, cert->rho_lo,
			 cert->rho);
	return dense;
}
