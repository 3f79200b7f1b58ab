/* SPDX-License-Identifier: MIT */
/* Small models for the numerical tests. */
#ifndef IRDM_TESTS_MODEL_FIXTURE_H
#define IRDM_TESTS_MODEL_FIXTURE_H

#include "precompute/model.h"

/* Box lx*ly*lz (m) with nx*ny*nz hexes of tph tets; grounded at z = 0
 * unless floating.  Aborts the test on failure. */
void fixture_model(struct irdm_model *m, double lx, double ly, double lz, unsigned nx,
		   unsigned ny, unsigned nz, unsigned tph, double poisson, bool floating,
		   size_t n_modes, enum irdm_eig_method eig, double dt_s);

/*
 * The soft, heavy cuboid the hybrid's tests share: the paper cuboid at
 * 4 x 4 x 8 hexes, E 2e3 Pa, nu 0.4999, rho 2e4 kg/m^3 (first mode
 * 0.15 Hz), 2 ms, top face touchable and displayed; then keys
 * (NULL-terminated pairs) over it.  Fails the test on a refused key.
 */
void fixture_soft_scene(struct irdm_scene *sc, const char *const *keys);

/* An irdm_measure_ref_fn (accuracy/measure.h): the exact model as a
 * precompute of its own, not the measured build's reference. */
int fixture_exact_by_precompute(void *ctx, const struct irdm_scene *rsc, const char *path,
				char *err, size_t errlen);

/* Free DoF index of (node, axis), asserting it is free. */
int64_t fixture_free_dof(const struct irdm_model *m, uint32_t node, int axis);

/* Mesh node nearest to p. */
uint32_t fixture_nearest_node(const struct irdm_mesh *mesh, const double p[3]);

/*
 * How far the six rigid fields about centre (3 translations, 3
 * infinitesimal rotations, built here from the node positions) lie outside
 * the span of modes->rigid_phi: the largest | |P v|_M^2 - |v|_M^2 | /
 * |v|_M^2 over the six (0: inside).  Every node free (a floating mesh).
 */
double fixture_rigid_outside(const struct irdm_mesh *mesh, const struct irdm_fem *fem,
			     const struct irdm_modes *modes, const double centre[3]);

/* Dense K^-1 column j by LAPACK (dpotrf/dpotrs): an independent solve. */
void fixture_dense_compliance(const struct irdm_fem *fem, int64_t j, double *x);

#endif
