/* SPDX-License-Identifier: MIT */
/*
 * Removing rigid motion from a displacement field of a floating object.
 *
 * All fits are weighted; for IRDM the weights are the lumped node masses,
 * because the rigid motion that the runtime integrates (Newton-Euler) is the
 * motion of the centre of mass and the rotation about it.  An unweighted fit
 * on a mesh with uneven node masses leaves a visible error
 * (docs/architecture.md, "Frames and signs").
 *
 * Points and displacements are packed xyz triples: x[3 * i + axis].
 *
 * Deformations are returned in the BODY frame: d_i = Rot^T (q_i - c') - r_i,
 * r_i = p_i - c.  That is what the runtime wants (it adds the deformation to
 * the rest shape and then applies the rigid pose), and it is the form for
 * which the fit's optimality conditions read exactly
 *     sum_i w_i d_i = 0   and   sum_i w_i r_i x d_i = 0,
 * i.e. d is w-orthogonal to the six rigid modes at the rest configuration.
 * The world-frame residual q_i - (Rot r_i + c') is Rot times this.
 */
#ifndef IRDM_TOOLS_RIGID_FIT_H
#define IRDM_TOOLS_RIGID_FIT_H

#include <stddef.h>

#include "irdm/error.h"

struct irdm_rigid_fit {
	double rot[9];    /* row-major proper rotation: q_i ~ rot (p_i - c_rest) + c_def */
	double c_rest[3]; /* weighted centroid of p */
	double c_def[3];  /* weighted centroid of q */
};

/*
 * Weighted Kabsch fit of rest points p to deformed points q (n points).
 * w: n weights >= 0 (NULL = all 1).  The rotation comes from an SVD of the
 * weighted cross-covariance with the reflection guard (det = +1).
 * Returns IRDM_OK, or IRDM_ENUMERIC if the total weight is not positive or the points are
 * collinear (rotation about the line undetermined) or not finite.
 */
int irdm_rigid_fit_kabsch(size_t n, const double *p, const double *q, const double *w,
			  struct irdm_rigid_fit *fit);

/* Body-frame residual d_i = rot^T (q_i - c_def) - (p_i - c_rest).  d may alias q. */
void irdm_rigid_fit_residual(const struct irdm_rigid_fit *fit, size_t n, const double *p,
			     const double *q, double *d);

/*
 * Remove the rigid part of a (linear, small) displacement field u by a
 * finite Kabsch fit: the field is scaled by eps = rel_eps * diag / max|u'|
 * (diag: bounding-box diagonal of p; u': u minus its weighted mean), so the
 * fit sees a tiny motion, and the residual is scaled back by 1 / eps.  As
 * rel_eps -> 0 this tends to irdm_rigid_project_linear(); the difference is
 * O(rel_eps * (rigid / deformation)) from the rotation's nonlinearity plus
 * O(1e-16 / rel_eps * (rigid / deformation)) from cancellation in forming
 * p + eps u, so no eps makes it exact: for a field that is linear in a load
 * prefer irdm_rigid_project_linear().  1e-6..1e-8 are sensible.  d may
 * alias u.  Returns as irdm_rigid_fit_kabsch().
 */
int irdm_rigid_remove_kabsch(size_t n, const double *p, const double *w, const double *u,
			     double rel_eps, double *d);

/*
 * Linearised removal: d = u - t - theta x r with t the weighted mean of u and
 * theta solving I theta = sum_i w_i r_i x u_i (I: weighted inertia tensor
 * about the weighted centroid).  This is the w-orthogonal projection of u
 * onto the complement of the six infinitesimal rigid modes; exact for linear
 * responses.  d may alias u.  Returns IRDM_OK, or IRDM_ENUMERIC if the total weight is not
 * positive or the inertia tensor is singular (collinear points).
 */
int irdm_rigid_project_linear(size_t n, const double *p, const double *w, const double *u,
			      double *d);

/*
 * 3x3 SVD a = u diag(s) v^T (row-major), s sorted descending, u and v
 * orthogonal (one-sided Jacobi; rank-deficient a gets a completed u).
 * Returns IRDM_OK, or IRDM_ENUMERIC if a is not finite.
 */
int irdm_svd3(const double a[9], double u[9], double s[3], double v[9]);

#endif /* IRDM_TOOLS_RIGID_FIT_H */
