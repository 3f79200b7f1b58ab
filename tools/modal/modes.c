/* SPDX-License-Identifier: MIT */
/* Choosing an eigensolver, separating rigid modes, checking the result. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "modal/modal.h"

/* Dense is cheaper than Lanczos below this many DoFs, and always used when
 * every mode is wanted. */
#define DENSE_MAX_DOF 2400
/* Eigenvalues below this fraction of max(K_ii / M_ii) count as rigid. */
#define RIGID_TOL 1e-9

void irdm_modes_free(struct irdm_modes *m)
{
	free(m->omega2);
	free(m->phi);
	free(m->rigid_phi);
	memset(m, 0, sizeof(*m));
}

/* Upper estimate of the largest eigenvalue: max_i K_ii / M_ii. */
static double stiffness_scale(const struct irdm_fem *fem)
{
	double s = 0;

	for (size_t j = 0; j < fem->K.n; j++) {
		double k = 0, m = 0;
		for (int64_t p = fem->K.colptr[j]; p < fem->K.colptr[j + 1]; p++)
			if ((size_t)fem->K.rowind[p] == j)
				k = fem->K.val[p];
		for (int64_t p = fem->M.colptr[j]; p < fem->M.colptr[j + 1]; p++)
			if ((size_t)fem->M.rowind[p] == j)
				m = fem->M.val[p];
		if (m > 0)
			s = fmax(s, k / m);
	}
	return s;
}

static int split_rigid(struct irdm_modes *out, size_t n_req, const double *w2,
		       const double *phi, double scale, bool floating, char *err, size_t errlen)
{
	size_t n = out->n, r = 0;

	while (r < n_req && w2[r] < RIGID_TOL * scale)
		r++;
	if (!floating && r > 0) {
		snprintf(err, errlen,
			 "model: %zu zero-stiffness mode(s) in a grounded object (lowest eigenvalue %g): fix more nodes or declare it floating",
			 r, w2[0]);
		return IRDM_EINVAL;
	}
	if (floating && r != 6) {
		snprintf(err, errlen,
			 "model: a floating object must have 6 rigid modes, found %zu (is the mesh in one piece?)",
			 r);
		return IRDM_EINVAL;
	}
	out->n_rigid = r;
	out->n_modes = n_req - r;
	out->omega2 = malloc(out->n_modes * sizeof(double));
	out->phi = malloc(n * out->n_modes * sizeof(double));
	out->rigid_phi = malloc(n * (r ? r : 1) * sizeof(double));
	if (!out->omega2 || !out->phi || !out->rigid_phi) {
		snprintf(err, errlen, "modes: out of memory");
		return IRDM_ENOMEM;
	}
	memcpy(out->omega2, w2 + r, out->n_modes * sizeof(double));
	memcpy(out->phi, phi + n * r, n * out->n_modes * sizeof(double));
	memcpy(out->rigid_phi, phi, n * r * sizeof(double));
	return 0;
}

int irdm_modes_solve(const struct irdm_fem *fem, size_t n_wanted, bool floating,
		     enum irdm_eig_method method, irdm_progress_fn progress, void *ctx,
		     struct irdm_modes *out, char *err, size_t errlen)
{
	size_t n = fem->K.n, n_rigid = floating ? 6 : 0, n_req;
	double scale = stiffness_scale(fem);
	double *w2 = NULL, *phi = NULL;
	int ret;

	memset(out, 0, sizeof(*out));
	out->n = n;
	if (n_wanted == 0 || n_wanted + n_rigid >= n)
		n_wanted = n > n_rigid ? n - n_rigid : 0;
	if (n_wanted == 0) {
		snprintf(err, errlen, "model: no elastic modes (%zu free DoFs)", n);
		return IRDM_EINVAL;
	}
	n_req = n_wanted + n_rigid;
	if (method == IRDM_EIG_AUTO)
		method = (n <= DENSE_MAX_DOF || n_req * 3 > n) ? IRDM_EIG_DENSE : IRDM_EIG_LANCZOS;
	if (method == IRDM_EIG_LANCZOS && n_req * 2 + 20 > n)
		method = IRDM_EIG_DENSE;
	w2 = malloc(n_req * sizeof(double));
	phi = malloc(n * n_req * sizeof(double));
	if (!w2 || !phi) {
		snprintf(err, errlen, "modes: out of memory for %zu modes of %zu DoFs", n_req, n);
		ret = IRDM_ENOMEM;
		goto out_free;
	}
	if (progress)
		progress(ctx, method == IRDM_EIG_DENSE ? "dense eigensolve" : "Lanczos eigensolve", 0.0);
	if (method == IRDM_EIG_DENSE)
		ret = irdm_eig_dense(fem, n_req, w2, phi, err, errlen);
	else    /* a negative shift keeps K - sigma M definite for floating bodies */
		ret = irdm_eig_lanczos(fem, n_req, floating ? -1e-6 * scale : 0.0, progress, ctx,
				       w2, phi, err, errlen);
	if (ret)
		goto out_free;
	if (progress)
		progress(ctx, "eigensolve", 1.0);
	ret = split_rigid(out, n_req, w2, phi, scale, floating, err, errlen);
	out->n_elastic_total = n - out->n_rigid;
out_free:
	if (ret)
		irdm_modes_free(out);
	free(w2);
	free(phi);
	return ret;
}
