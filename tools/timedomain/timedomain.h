/* SPDX-License-Identifier: MIT */
/*
 * Time-domain impulse-response precompute (the paper's FIR R[s]) by direct
 * integration of the FEM model  M u'' + C u' + K u = f,  C = a M + b K.
 *
 * Convention (docs/architecture.md, "Sample convention"): R[s] is the
 * displacement at (s + 1) dt caused by a unit force held constant over
 * [0, dt) (zero-order hold) and zero afterwards, starting from rest;
 * u[t] = sum_s R[s] f[t - s].
 *
 * Integrator: Newmark average acceleration (trapezoidal rule, beta = 1/4,
 * gamma = 1/2): unconditionally stable, second order, no numerical damping.
 * `substeps` steps of h = dt / substeps per sample.  One sparse Cholesky
 * factor (CHOLMOD) of S = M + h/2 C + h^2/4 K serves every step and input.
 *
 * Offline only: double precision, allocates, uses threads.
 */
#ifndef IRDM_TOOLS_TIMEDOMAIN_H
#define IRDM_TOOLS_TIMEDOMAIN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "fem/fem.h"
#include "irdm/error.h"
#include "mesh/mesh.h"

/*
 * How a floating object's responses lose their rigid motion.  Both are the
 * mass-weighted least-squares rigid fit (docs/architecture.md, "Frames
 * and signs"); they differ in how the fit meets a response that is linear
 * in the force:
 *
 * LINEAR (default): the fit's exact small-motion limit, the mass-orthogonal
 *   projection off the six rigid modes (rigid_fit.h).  Linear in the force,
 *   so R[s] stays a linear operator; exact to rounding (~1e-14).
 * KABSCH: a finite Kabsch/SVD fit of p + eps u, residual / eps.  It tends to
 *   LINEAR as eps -> 0 but carries eps * (rigid/deformation) of rotation
 *   nonlinearity plus 1e-16 / eps * (rigid/deformation) of cancellation; on
 *   a 2x2x2 floating box the best choice (eps ~ 1e-7) leaves ~1e-7 relative
 *   error and ~1e-7 residual momentum.  Kept for comparison and for
 *   responses that are not small-motion linear.
 */
enum irdm_td_rigid {
	IRDM_TD_RIGID_LINEAR = 0,
	IRDM_TD_RIGID_KABSCH = 1,
};

/* Default relative size of the scaled motion the Kabsch fit sees. */
#define IRDM_TD_KABSCH_REL_EPS 1e-7

struct irdm_td_opts {
	double dt_s;        /* sample period */
	unsigned n_samples; /* T */
	unsigned substeps;  /* integration steps per sample (>= 1) */
	struct irdm_rayleigh damping;
	bool floating;    /* remove rigid motion by mass-weighted best fit */
	unsigned threads; /* worker threads over input DoFs (0 = online CPUs) */
	/* May be NULL.  Called with the number of finished input columns, from
	 * any worker thread but never concurrently (serialised here). */
	void (*progress)(void *ctx, size_t done, size_t total);
	void *progress_ctx;
	enum irdm_td_rigid rigid; /* floating only; 0 = linear projection */
	double kabsch_rel_eps;    /* KABSCH only; 0 = IRDM_TD_KABSCH_REL_EPS */
};

/*
 * Responses to a unit ZOH force at each input global DoF in_dofs[0..n_in)
 * (must be free DoFs), recorded at output nodes out_nodes[0..n_out) (all 3
 * axes; fixed nodes give 0).  R is n_in * T * (3 * n_out) doubles, layout
 * R[(i * T + s) * 3 * n_out + 3 * o + axis].
 *
 * A floating object must have no fixed node; its responses are deformations
 * in the body frame with the rigid part (mass-weighted fit about the centre
 * of mass) removed at every sample.
 *
 * The result does not depend on `threads` (bit for bit).  While it runs,
 * OpenBLAS is switched to one thread process-wide (restored on return), so
 * do not run it concurrently with itself or with other OpenBLAS work that
 * relies on its thread setting.  A one-line reason goes to err.
 * Return: IRDM_OK; IRDM_EINVAL if an option, the model or an index is
 * invalid; IRDM_ENOMEM; IRDM_ENUMERIC if the factorisation, a solve or a
 * rigid-motion fit fails; IRDM_ETHREAD if no mutex can be made.
 */
int irdm_td_responses(const struct irdm_mesh *mesh, const struct irdm_fem *fem,
		      const struct irdm_td_opts *o, const int64_t *in_dofs, size_t n_in,
		      const uint32_t *out_nodes, size_t n_out, double *R,
		      char *err, size_t errlen);

#endif /* IRDM_TOOLS_TIMEDOMAIN_H */
