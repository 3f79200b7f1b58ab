/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "model_fixture.h"
#include "precompute/precompute.h"

void dpotrf_(const char *uplo, const int *n, double *a, const int *lda, int *info);
void dpotrs_(const char *uplo, const int *n, const int *nrhs, const double *a, const int *lda,
	     double *b, const int *ldb, int *info);

void fixture_model(struct irdm_model *m, double lx, double ly, double lz, unsigned nx,
		   unsigned ny, unsigned nz, unsigned tph, double poisson, bool floating,
		   size_t n_modes, enum irdm_eig_method eig, double dt_s)
{
	struct irdm_scene sc;
	char err[512], mesh[128];

	irdm_scene_defaults(&sc);
	snprintf(mesh, sizeof(mesh), "box:%.17g,%.17g,%.17g", lx, ly, lz);
	assert_int_equal(irdm_scene_set(&sc, "mesh", mesh, "test", err, sizeof(err)), 0);
	sc.res[0] = nx;
	sc.res[1] = ny;
	sc.res[2] = nz;
	sc.tets_per_hex = tph;
	sc.mat.poisson = poisson;
	sc.dt_s = dt_s;
	sc.eigensolver = eig;
	if (floating)
		assert_int_equal(irdm_scene_set(&sc, "floating", "yes", "test", err, sizeof(err)), 0);
	int rc = irdm_model_build(&sc, n_modes, NULL, NULL, m, err, sizeof(err));
	if (rc)
		fail_msg("model build failed: %s", err);
}

int64_t fixture_free_dof(const struct irdm_model *m, uint32_t node, int axis)
{
	int64_t d = m->fem.map.free_of[3 * (size_t)node + (size_t)axis];

	assert_true(d >= 0);
	return d;
}

uint32_t fixture_nearest_node(const struct irdm_mesh *mesh, const double p[3])
{
	double best = 1e300;
	uint32_t bi = 0;

	for (size_t i = 0; i < mesh->n_nodes; i++) {
		double d = 0;
		for (int a = 0; a < 3; a++) {
			double t = mesh->pos_m[3 * i + (size_t)a] - p[a];
			d += t * t;
		}
		if (d < best) {
			best = d;
			bi = (uint32_t)i;
		}
	}
	return bi;
}

void fixture_dense_compliance(const struct irdm_fem *fem, int64_t j, double *x)
{
	int n = (int)fem->K.n, one = 1, info = 0;
	double *a = irdm_csc_to_dense(&fem->K);

	assert_non_null(a);
	memset(x, 0, (size_t)n * sizeof(double));
	x[j] = 1.0;
	dpotrf_("L", &n, a, &n, &info);
	assert_int_equal(info, 0);
	dpotrs_("L", &n, &one, a, &n, x, &n, &info);
	assert_int_equal(info, 0);
	free(a);
}

double fixture_rigid_outside(const struct irdm_mesh *mesh, const struct irdm_fem *fem,
			     const struct irdm_modes *modes, const double centre[3])
{
	size_t n = modes->n, nn = mesh->n_nodes;
	double *v = malloc(n * sizeof(double)), *mv = malloc(n * sizeof(double)), worst = 0;

	assert_true(v && mv && n == 3 * nn);
	for (int f = 0; f < 6; f++) {
		double vv = 0, proj = 0;

		for (size_t i = 0; i < nn; i++) {
			const double *p = &mesh->pos_m[3 * i];
			double r[3] = { p[0] - centre[0], p[1] - centre[1], p[2] - centre[2] };
			double u[3] = { 0, 0, 0 };

			if (f < 3) {
				u[f] = 1;
			} else {
				int a = f - 3; /* e_a x r */
				u[(a + 1) % 3] = -r[(a + 2) % 3];
				u[(a + 2) % 3] = r[(a + 1) % 3];
			}
			memcpy(&v[3 * i], u, sizeof(u));
		}
		irdm_csc_matvec(&fem->M, v, mv);
		for (size_t i = 0; i < n; i++)
			vv += v[i] * mv[i];
		for (size_t r = 0; r < modes->n_rigid; r++) {
			double d = 0;
			for (size_t i = 0; i < n; i++)
				d += modes->rigid_phi[r * n + i] * mv[i];
			proj += d * d;
		}
		worst = fmax(worst, fabs(proj - vv) / vv);
	}
	free(v);
	free(mv);
	return worst;
}

void fixture_soft_scene(struct irdm_scene *sc, const char *const *keys)
{
	static const char *const soft[] = { "resolution", "4,4,8", "touch", "z>=0.2", "display",
					    "touch", "dt", "0.002", "young", "2e3", "poisson",
					    "0.4999", "density", "2e4", NULL };
	char err[256];

	irdm_scene_defaults(sc);
	for (const char *const *kv = soft; *kv; kv += 2)
		assert_int_equal(irdm_scene_set(sc, kv[0], kv[1], "test", err, sizeof(err)), 0);
	for (const char *const *kv = keys; kv && *kv; kv += 2)
		assert_int_equal(irdm_scene_set(sc, kv[0], kv[1], "test", err, sizeof(err)), 0);
}

int fixture_exact_by_precompute(void *ctx, const struct irdm_scene *rsc, const char *path,
				char *err, size_t errlen)
{
	struct irdm_precompute_opts o = { .out_path = path };
	struct irdm_precompute_report rep;

	(void)ctx;
	return irdm_precompute(rsc, &o, &rep, err, errlen);
}
