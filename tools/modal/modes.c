/* SPDX-License-Identifier: MIT */
/* Choosing an eigensolver, separating rigid modes, checking the result. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "modal/eig_dense_priv.h"
#include "modal/modal.h"
#include "modal/symmetry.h"
#include "util/memory.h"

/* Dense is cheaper than Lanczos below this many DoFs, and always used when
 * every mode is wanted. */
#define DENSE_MAX_DOF 2400
/*
 * Which modes are rigid is not decided by an eigenvalue threshold: on a
 * graded mesh the eigenvalues' scale is set by the smallest element and
 * says nothing about the softest mode (a 3.9 Hz mode of a CAD part was
 * once taken for rigid that way).  irdm_mesh_check_rigidity() proves
 * before the eigensolve that a grounded mesh has none and a floating one
 * exactly six; here the six lowest of a floating object are its rigid
 * modes, and what is checked is that they stand apart: the seventh
 * eigenvalue at least RIGID_GAP times the largest rigid one.  A grounded
 * object's lowest eigenvalue must be positive and above ZERO_TOL times
 * the mesh's typical K_ii / M_ii (a last guard: the mesh check makes it
 * hold).
 */
#define RIGID_GAP 1e3
/* max(K_ii / M_ii) above this many times the median: a graded mesh (a
 * uniform one is within 10; test_mesh_rigidity's is 1.3e5). */
#define GRADED 1e3
#define ZERO_TOL 1e-14

struct irdm_modes_rest {
	struct irdm_eig_rest *eig;
	bool *every;   /* n: the DoFs every column holds */
	size_t *z_col; /* each column's vector in the solve */
	bool *whole;   /* each column whole */
};

/* Does need (bytes) fit the memory budget (util/memory.h)?  If not, say
 * so in err: "modes: <solve> needs ...". */
static bool fits(double need, const char *solve, char *err, size_t errlen)
{
	const char *what;
	double budget = irdm_memory_budget(&what);

	if (!(budget > 0) || need <= budget)
		return true;
	snprintf(err, errlen, "modes: %s needs %.3g GiB, more than the %.3g GiB of %s", solve,
		 need / (1 << 30), budget / (1 << 30), what);
	return false;
}

/*
 * Does the dense eigensolve of n DoFs for n_req modes fit?  It holds the
 * n_req vectors, and the matrix and the eigenvectors of its tridiagonal
 * (or the Cholesky factor): about 8 n (2 n + n_req) bytes, 2.1 GiB for
 * every mode of the paper's cuboid (its measured peak: 2.5 GiB).  Split
 * by symmetry (eig_dense_at.c), a block's matrix and vectors are of its
 * own size: 8 (n n_req + 2 sum_sq), sum_sq the blocks' sizes squared,
 * summed.
 */
static bool dense_fits(size_t n, size_t n_req, double sum_sq, char *err, size_t errlen)
{
	char solve[160];

	snprintf(solve, sizeof(solve), "the dense eigensolve of %zu modes of %zu free DoFs%s", n_req,
		 n, sum_sq < (double)n * (double)n ? " (split by symmetry)" : "");
	return fits(8.0 * ((double)n * (double)n_req + 2.0 * sum_sq), solve, err, errlen);
}

/*
 * Does the Lanczos solve of n_req modes of n DoFs fit?  ARPACK holds a
 * basis of ncv = 2 n_req + 20 vectors (eig_lanczos.c), three more, ncv^2
 * of work, and the n_req vectors returned: about 8 (n (3 n_req + 24) +
 * ncv^2) bytes, beside the sparse factor of K (known only once
 * factorised, not counted).
 */
static bool lanczos_fits(size_t n, size_t n_req, char *err, size_t errlen)
{
	double ncv = 2.0 * (double)n_req + 20;
	char solve[128];

	snprintf(solve, sizeof(solve), "the Lanczos solve of %zu modes of %zu free DoFs", n_req, n);
	return fits(8.0 * ((double)n * (3.0 * (double)n_req + 24) + ncv * ncv), solve, err, errlen);
}

/* The dense solve's blocks' sizes squared, summed: n^2 unless it is the
 * every-mode solve of a lumped mass, which splits by symmetry (dense_at). */
static double blocks_sum_sq(const struct irdm_fem *fem, const struct irdm_modes_want *want,
			    size_t n_req)
{
	struct irdm_sym_class cls[1 << IRDM_SYM_MAX_GENS];
	double n = (double)fem->K.n, sum = 0;

	if (!want || !want->every || !want->sym || !want->sym->n_gens || n_req != fem->K.n ||
	    !irdm_eig_mass_is_diagonal(&fem->M) || irdm_sym_classes(want->sym, cls))
		return n * n;
	for (unsigned p = 0; p < 1u << want->sym->n_gens; p++) {
		sum += (double)cls[p].n * (double)cls[p].n;
		irdm_sym_class_free(&cls[p]);
	}
	return sum;
}

static void rest_free(struct irdm_modes_rest *r)
{
	if (!r)
		return;
	irdm_eig_rest_free(r->eig);
	free(r->every);
	free(r->z_col);
	free(r->whole);
	free(r);
}

void irdm_modes_free(struct irdm_modes *m)
{
	rest_free(m->rest);
	free(m->omega2);
	free(m->phi);
	free(m->rigid_phi);
	free(m->compliance);
	memset(m, 0, sizeof(*m));
}

bool irdm_modes_whole(const struct irdm_modes *m, size_t k)
{
	return !m->rest || m->rest->whole[k];
}

int irdm_modes_rest_permute(struct irdm_modes *m, const size_t *order)
{
	struct irdm_modes_rest *r = m->rest;
	size_t n = m->n_modes;
	size_t *z = r ? malloc((n ? n : 1) * sizeof(*z)) : NULL;
	bool *w = r ? malloc((n ? n : 1) * sizeof(*w)) : NULL;

	if (!r)
		return IRDM_OK;
	if (!z || !w) {
		free(z);
		free(w);
		return IRDM_ENOMEM;
	}
	for (size_t k = 0; k < n; k++) {
		z[k] = r->z_col[order[k]];
		w[k] = r->whole[order[k]];
	}
	memcpy(r->z_col, z, n * sizeof(*z));
	memcpy(r->whole, w, n * sizeof(*w));
	free(z);
	free(w);
	return IRDM_OK;
}

/* Whether every one of dofs (-1: none) is held by every column. */
static bool held_everywhere(const struct irdm_modes_rest *r, const int64_t *dofs, size_t n_dofs)
{
	for (size_t i = 0; i < n_dofs; i++)
		if (dofs[i] >= 0 && !r->every[dofs[i]])
			return false;
	return true;
}

#define COMPLETE_CHUNK 512 /* columns made whole at a time: bounds the scratch */

int irdm_modes_complete(struct irdm_modes *m, size_t first, size_t count, const int64_t *dofs,
			size_t n_dofs, char *err, size_t errlen)
{
	struct irdm_modes_rest *r = m->rest;
	size_t n = m->n, idx[COMPLETE_CHUNK], zc[COMPLETE_CHUNK], k = first;
	double *buf;
	int ret = IRDM_OK;

	if (!r || held_everywhere(r, dofs, n_dofs))
		return IRDM_OK;
	buf = malloc(n * COMPLETE_CHUNK * sizeof(double));
	if (!buf) {
		snprintf(err, errlen, "modes: out of memory making %zu modes whole", count);
		return IRDM_ENOMEM;
	}
	while (k < first + count && !ret) {
		size_t c = 0;

		for (; k < first + count && c < COMPLETE_CHUNK; k++)
			if (!r->whole[k]) {
				idx[c] = k;
				zc[c++] = r->z_col[k];
			}
		ret = irdm_eig_rest_fill(r->eig, zc, c, buf);
		for (size_t j = 0; j < c && !ret; j++) {
			memcpy(&m->phi[idx[j] * n], &buf[j * n], n * sizeof(double));
			r->whole[idx[j]] = true;
		}
	}
	free(buf);
	if (ret)
		snprintf(err, errlen, "modes: making %zu modes whole failed (%s)", count,
			 ret == IRDM_ENOMEM ? "out of memory" : "LAPACK dormtr");
	return ret;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;

	return (x > y) - (x < y);
}

/*
 * The mesh's typical element stiffness over mass: the median of
 * K_ii / M_ii (the maximum is set by the smallest element, a factor 1e12
 * above the median on a graded CAD mesh); *max_out the maximum.  0 if it
 * cannot be had.
 */
static double typical_scale(const struct irdm_fem *fem, double *max_out)
{
	double *r = malloc((fem->K.n ? fem->K.n : 1) * sizeof(double)), s;
	size_t n = 0;

	*max_out = 0;
	if (!r)
		return 0;
	for (size_t j = 0; j < fem->K.n; j++) {
		double k = 0, m = 0;
		for (int64_t p = fem->K.colptr[j]; p < fem->K.colptr[j + 1]; p++)
			if ((size_t)fem->K.rowind[p] == j)
				k = fem->K.val[p];
		for (int64_t p = fem->M.colptr[j]; p < fem->M.colptr[j + 1]; p++)
			if ((size_t)fem->M.rowind[p] == j)
				m = fem->M.val[p];
		if (m > 0 && k > 0)
			r[n++] = k / m;
	}
	qsort(r, n, sizeof(double), cmp_double);
	s = n ? r[n / 2] : 0;
	*max_out = n ? r[n - 1] : 0;
	free(r);
	return s;
}

static int split_rigid(struct irdm_modes *out, size_t n_req, const double *w2,
		       double **phi_owned, double scale, bool floating, char *err, size_t errlen)
{
	double *phi = *phi_owned;
	size_t n = out->n, r = floating ? 6 : 0;

	if (!floating && !(w2[0] > ZERO_TOL * scale)) {
		snprintf(err, errlen,
			 "model: a zero-stiffness mode in a grounded object (lowest eigenvalue %g, "
			 "typical K/M %g): fix more nodes or declare it floating",
			 w2[0], scale);
		return IRDM_EINVAL;
	}
	if (floating) {
		double rigid = 0;

		for (size_t k = 0; k < 6; k++)
			rigid = fmax(rigid, fabs(w2[k]));
		if (!(w2[6] > RIGID_GAP * rigid)) {
			snprintf(err, errlen,
				 "model: a floating object's 6 rigid modes do not stand apart (6th "
				 "eigenvalue %g, 7th %g): a part nearly free to move?",
				 w2[5], w2[6]);
			return IRDM_EINVAL;
		}
	}
	out->n_rigid = r;
	out->n_modes = n_req - r;
	out->omega2 = malloc(out->n_modes * sizeof(double));
	if (!out->omega2) {
		snprintf(err, errlen, "modes: out of memory");
		return IRDM_ENOMEM;
	}
	memcpy(out->omega2, w2 + r, out->n_modes * sizeof(double));
	if (!phi) /* an MPI rank other than 0: eigenvalues only */
		return 0;
	out->rigid_phi = malloc(n * (r ? r : 1) * sizeof(double));
	if (!out->rigid_phi) {
		snprintf(err, errlen, "modes: out of memory");
		return IRDM_ENOMEM;
	}
	/* the elastic vectors taken over where they lie, moved down past the
	 * rigid ones: every mode of a large model is no second copy */
	memcpy(out->rigid_phi, phi, n * r * sizeof(double));
	memmove(phi, phi + n * r, n * out->n_modes * sizeof(double));
	out->phi = phi;
	*phi_owned = NULL;
	return 0;
}

/*
 * Every mode densely, each at the DoFs every[] marks only (the rest on
 * demand: *eig); a floating object's rigid modes, the first n_rigid, whole
 * at once (they project every static load).
 */
static int dense_at(const struct irdm_fem *fem, const struct irdm_modes_want *want, size_t n_rigid,
		    irdm_progress_fn progress, void *ctx, double *w2, double *phi,
		    struct irdm_eig_rest **eig, char *err, size_t errlen)
{
	size_t n = fem->K.n, n_at = 0, rigid[6] = { 0, 1, 2, 3, 4, 5 };
	int64_t *at = malloc((n ? n : 1) * sizeof(*at));
	int ret;

	if (!at) {
		snprintf(err, errlen, "modes: out of memory");
		return IRDM_ENOMEM;
	}
	for (size_t i = 0; i < n; i++)
		if (want->every[i])
			at[n_at++] = (int64_t)i;
	ret = irdm_eig_dense_at(fem, want->sym, at, n_at, progress, ctx, w2, phi, eig, err, errlen);
	free(at);
	if (!ret && *eig && n_rigid) {
		ret = irdm_eig_rest_fill(*eig, rigid, n_rigid, phi);
		if (ret)
			snprintf(err, errlen, "modes: the rigid modes could not be made whole");
	}
	return ret;
}

/* out's columns, none whole yet, each the solve's vector n_rigid on. */
static int rest_init(struct irdm_modes *out, struct irdm_eig_rest *eig, const bool *every,
		     char *err, size_t errlen)
{
	struct irdm_modes_rest *r = calloc(1, sizeof(*r));
	size_t n = out->n, k = out->n_modes;

	if (r) {
		r->eig = eig;
		r->every = malloc((n ? n : 1) * sizeof(bool));
		r->z_col = malloc((k ? k : 1) * sizeof(size_t));
		r->whole = calloc(k ? k : 1, sizeof(bool));
	} else {
		irdm_eig_rest_free(eig);
	}
	if (!r || !r->every || !r->z_col || !r->whole) {
		rest_free(r);
		snprintf(err, errlen, "modes: out of memory");
		return IRDM_ENOMEM;
	}
	memcpy(r->every, every, n * sizeof(bool));
	for (size_t j = 0; j < k; j++)
		r->z_col[j] = j + out->n_rigid;
	out->rest = r;
	return IRDM_OK;
}

int irdm_modes_solve(const struct irdm_fem *fem, size_t n_wanted, bool floating,
		     enum irdm_eig_method method, irdm_progress_fn progress, void *ctx,
		     struct irdm_modes *out, char *err, size_t errlen)
{
	return irdm_modes_solve_kept(fem, n_wanted, floating, method, NULL, NULL, progress, ctx,
				     out, err, errlen);
}

/* Over MPI ranks; a grounded object's static-correction loads solved with
 * the eigensolve's factor of K (sigma = 0) into out->compliance. */
static int solve_slepc(const struct irdm_fem *fem, size_t n_req, bool floating, double scale,
		       const struct irdm_eig_dist *dist, const struct irdm_modes_want *want,
		       irdm_progress_fn progress, void *ctx, double *w2, double *phi,
		       struct irdm_modes *out, char *err, size_t errlen)
{
	size_t n = fem->K.n, n_loads = floating || !want ? 0 : want->n_loads;
	struct irdm_modes_want w = want ? *want : (struct irdm_modes_want){ NULL, NULL, 0, NULL, NULL };
	int ret;

	w.n_loads = n_loads;
	if (n_loads && dist->rank == 0) {
		out->compliance = malloc(n * n_loads * sizeof(double));
		if (!out->compliance) {
			snprintf(err, errlen, "modes: out of memory for %zu static loads", n_loads);
			return IRDM_ENOMEM;
		}
		out->n_compliance = n_loads;
	}
	/* a negative shift keeps K - sigma M definite for floating bodies */
	ret = dist->solve(fem, n_req, floating ? -1e-6 * scale : 0.0, &w, floating ? 6 : 0,
			  progress, ctx, w2, phi, out->compliance, err, errlen);
	return ret;
}

int irdm_modes_solve_kept(const struct irdm_fem *fem, size_t n_wanted, bool floating,
			  enum irdm_eig_method method, const struct irdm_eig_dist *dist,
			  const struct irdm_modes_want *want, irdm_progress_fn progress,
			  void *ctx, struct irdm_modes *out, char *err, size_t errlen)
{
	size_t n = fem->K.n, n_rigid = floating ? 6 : 0, n_req;
	double max_scale, scale = typical_scale(fem, &max_scale);
	double *w2 = NULL, *phi = NULL;
	struct irdm_eig_rest *eig = NULL;
	/* the slepc path gathers the eigenvectors on rank 0 only */
	bool has_phi;
	int ret;

	memset(out, 0, sizeof(*out));
	out->n = n;
	out->eig_blocks = 1;
	if (n_wanted == 0 || n_wanted + n_rigid >= n)
		n_wanted = n > n_rigid ? n - n_rigid : 0;
	if (n_wanted == 0) {
		snprintf(err, errlen, "model: no elastic modes (%zu free DoFs)", n);
		return IRDM_EINVAL;
	}
	n_req = n_wanted + n_rigid;
	/*
	 * A dense solve resolves an eigenvalue to about eps max(K_ii/M_ii):
	 * on a graded mesh (a tiny element beside large ones) that is far
	 * from the low modes' (1e-6 relative measured on test_mesh_rigidity's),
	 * where shift-and-invert Lanczos is exact to rounding.
	 */
	if (method == IRDM_EIG_AUTO)
		method = (n <= DENSE_MAX_DOF || n_req * 3 > n) && max_scale <= GRADED * scale ? IRDM_EIG_DENSE : IRDM_EIG_LANCZOS;
	if (method == IRDM_EIG_LANCZOS && n_req * 2 + 20 > n)
		method = IRDM_EIG_DENSE;
	if (method == IRDM_EIG_SLEPC && n_req * 2 + 20 > n) {
		/* every rank would hold the whole Krylov basis: no gain */
		snprintf(err, errlen, "slepc: %zu modes of %zu DoFs are too many for a Krylov solver: "
				      "use eigensolver = dense",
			 n_req, n);
		return IRDM_EINVAL;
	}
	if (method == IRDM_EIG_SLEPC && !dist) {
		snprintf(err, errlen, "slepc: no distributed eigensolver given");
		return IRDM_EINVAL;
	}
	if (method == IRDM_EIG_DENSE && !dense_fits(n, n_req, blocks_sum_sq(fem, want, n_req), err, errlen))
		return IRDM_ENOMEM;
	if (method == IRDM_EIG_LANCZOS && !lanczos_fits(n, n_req, err, errlen))
		return IRDM_ENOMEM;
	has_phi = method != IRDM_EIG_SLEPC || dist->rank == 0;
	w2 = malloc(n_req * sizeof(double));
	if (has_phi)
		phi = malloc(n * n_req * sizeof(double));
	if (!w2 || (has_phi && !phi)) {
		snprintf(err, errlen, "modes: out of memory for %zu modes of %zu DoFs", n_req, n);
		ret = IRDM_ENOMEM;
		goto out_free;
	}
	if (progress)
		progress(ctx, method == IRDM_EIG_DENSE ? "dense eigensolve" : method == IRDM_EIG_SLEPC ? "SLEPc eigensolve" :
													 "Lanczos eigensolve",
			 0.0);
	if (method == IRDM_EIG_DENSE && n_req == n && want && want->every)
		ret = dense_at(fem, want, n_rigid, progress, ctx, w2, phi, &eig, err, errlen);
	else if (method == IRDM_EIG_DENSE)
		ret = irdm_eig_dense(fem, n_req, w2, phi, err, errlen);
	else if (method == IRDM_EIG_SLEPC)
		ret = solve_slepc(fem, n_req, floating, scale, dist, want, progress, ctx, w2, phi,
				  out, err, errlen);
	else /* a negative shift keeps K - sigma M definite for floating bodies */
		ret = irdm_eig_lanczos(fem, n_req, floating ? -1e-6 * scale : 0.0, progress, ctx,
				       w2, phi, err, errlen);
	if (ret)
		goto out_free;
	if (progress)
		progress(ctx, "eigensolve", 1.0);
	ret = split_rigid(out, n_req, w2, &phi, scale, floating, err, errlen);
	out->n_elastic_total = n - out->n_rigid;
	if (!ret && eig) {
		out->eig_blocks = irdm_eig_rest_blocks(eig);
		ret = rest_init(out, eig, want->every, err, errlen);
		eig = NULL;
	}
out_free:
	irdm_eig_rest_free(eig);
	if (ret)
		irdm_modes_free(out);
	free(w2);
	free(phi);
	return ret;
}
