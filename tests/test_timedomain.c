/* SPDX-License-Identifier: MIT */
/*
 * Time-domain responses (tools/timedomain) against independent references:
 * the exact zero-order-hold response of each damped mode (dense generalised
 * eigen-decomposition done here by Jacobi), reciprocity, the static limit
 * (dense Cholesky here), rigid-motion removal, thread independence and
 * input validation.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "fem/fem.h"
#include "timedomain/rigid_fit.h"
#include "timedomain/timedomain.h"

static const struct irdm_material soft = { 2000.0, 0.45, 110.0 };

/* ---- meshes (built here so this test does not depend on tools/mesh) ----- */

static void mesh_release(struct irdm_mesh *m)
{
	free(m->pos_m);
	free(m->tets);
	memset(m, 0, sizeof(*m));
}

static double tet_volume6(const struct irdm_mesh *m, const uint32_t *t)
{
	const double *a = &m->pos_m[3 * t[0]];
	double e[3][3];

	for (int i = 0; i < 3; i++)
		for (int k = 0; k < 3; k++)
			e[i][k] = m->pos_m[3 * t[i + 1] + k] - a[k];
	return e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) + e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
}

/*
 * Box [0,lx]x[0,ly]x[0,lz] on an nx x ny x nz grid, each hex cut into the 6
 * Kuhn tets around its main diagonal (conforming).  grade != 1 spaces the
 * grid as (i/n)^grade, giving uneven node masses.
 */
static void box_mesh(struct irdm_mesh *m, double lx, double ly, double lz, unsigned nx,
		     unsigned ny, unsigned nz, double grade)
{
	static const int perm[6][3] = { { 0, 1, 2 }, { 0, 2, 1 }, { 1, 0, 2 }, { 1, 2, 0 }, { 2, 0, 1 }, { 2, 1, 0 } };
	unsigned sx = nx + 1, sy = ny + 1, sz = nz + 1;
	const double len[3] = { lx, ly, lz }, nn[3] = { nx, ny, nz };
	size_t t = 0;

	memset(m, 0, sizeof(*m));
	m->n_nodes = (size_t)sx * sy * sz;
	m->n_tets = 6 * (size_t)nx * ny * nz;
	m->pos_m = malloc(3 * m->n_nodes * sizeof(double));
	m->tets = malloc(4 * m->n_tets * sizeof(uint32_t));
	assert_non_null(m->pos_m);
	assert_non_null(m->tets);
	for (unsigned k = 0; k < sz; k++)
		for (unsigned j = 0; j < sy; j++)
			for (unsigned i = 0; i < sx; i++) {
				unsigned ijk[3] = { i, j, k };
				size_t id = i + sx * (j + (size_t)sy * k);

				for (int a = 0; a < 3; a++)
					m->pos_m[3 * id + a] = len[a] * pow(ijk[a] / nn[a], grade);
			}
	for (unsigned k = 0; k < nz; k++)
		for (unsigned j = 0; j < ny; j++)
			for (unsigned i = 0; i < nx; i++)
				for (int p = 0; p < 6; p++) {
					unsigned c[3] = { i, j, k };
					uint32_t *tet = &m->tets[4 * t++];

					for (int v = 0; v < 4; v++) {
						if (v > 0)
							c[perm[p][v - 1]]++;
						tet[v] = c[0] + sx * (c[1] + sy * c[2]);
					}
					if (tet_volume6(m, tet) < 0) {
						uint32_t x = tet[2];

						tet[2] = tet[3];
						tet[3] = x;
					}
				}
	snprintf(m->name, sizeof(m->name), "box%ux%ux%u", nx, ny, nz);
}

/* FEM with the z = 0 face fixed (or nothing fixed). */
static void box_fem(const struct irdm_mesh *m, enum irdm_mass_kind kind, bool grounded,
		    struct irdm_fem *fem)
{
	bool *fixed = calloc(m->n_nodes, sizeof(bool));
	char err[256] = "";

	assert_non_null(fixed);
	for (size_t i = 0; i < m->n_nodes; i++)
		fixed[i] = grounded && m->pos_m[3 * i + 2] == 0.0;
	if (irdm_fem_assemble(m, &soft, kind, fixed, fem, err, sizeof(err)))
		fail_msg("%s", err);
	free(fixed);
}

/* ---- dense linear algebra references -------------------------------------- */

/* Lower Cholesky of SPD a (n x n, symmetric, any major) in place into l. */
static void dense_cholesky(size_t n, const double *a, double *l)
{
	memset(l, 0, n * n * sizeof(double));
	for (size_t j = 0; j < n; j++) {
		double s = a[j * n + j];

		for (size_t k = 0; k < j; k++)
			s -= l[j * n + k] * l[j * n + k];
		assert_true(s > 0);
		l[j * n + j] = sqrt(s);
		for (size_t i = j + 1; i < n; i++) {
			double t = a[i * n + j];

			for (size_t k = 0; k < j; k++)
				t -= l[i * n + k] * l[j * n + k];
			l[i * n + j] = t / l[j * n + j];
		}
	}
}

/* x = L^-1 b (lower, row-major). */
static void lower_solve(size_t n, const double *l, double *x)
{
	for (size_t i = 0; i < n; i++) {
		for (size_t k = 0; k < i; k++)
			x[i] -= l[i * n + k] * x[k];
		x[i] /= l[i * n + i];
	}
}

/* x = L^-T b. */
static void upper_solve(size_t n, const double *l, double *x)
{
	for (size_t i = n; i-- > 0;) {
		for (size_t k = i + 1; k < n; k++)
			x[i] -= l[k * n + i] * x[k];
		x[i] /= l[i * n + i];
	}
}

/* Cyclic Jacobi: symmetric a (row-major) -> diagonal; v gets eigenvectors
 * as columns. */
static void jacobi_eig(size_t n, double *a, double *v)
{
	memset(v, 0, n * n * sizeof(double));
	for (size_t i = 0; i < n; i++)
		v[i * n + i] = 1.0;
	for (int sweep = 0; sweep < 100; sweep++) {
		double off = 0, diag = 0;

		for (size_t p = 0; p < n; p++) {
			diag += a[p * n + p] * a[p * n + p];
			for (size_t q = p + 1; q < n; q++)
				off += a[p * n + q] * a[p * n + q];
		}
		if (off <= 1e-32 * diag)
			return;
		for (size_t p = 0; p < n; p++)
			for (size_t q = p + 1; q < n; q++) {
				double apq = a[p * n + q];

				if (apq == 0.0)
					continue;
				double th = (a[q * n + q] - a[p * n + p]) / (2 * apq);
				double t = copysign(1.0, th) / (fabs(th) + hypot(th, 1.0));
				double c = 1 / sqrt(t * t + 1), s = t * c;

				for (size_t k = 0; k < n; k++) {
					double kp = a[k * n + p], kq = a[k * n + q];

					a[k * n + p] = c * kp - s * kq;
					a[k * n + q] = s * kp + c * kq;
				}
				for (size_t k = 0; k < n; k++) {
					double pk = a[p * n + k], qk = a[q * n + k];

					a[p * n + k] = c * pk - s * qk;
					a[q * n + k] = s * pk + c * qk;
					pk = v[k * n + p];
					qk = v[k * n + q];
					v[k * n + p] = c * pk - s * qk;
					v[k * n + q] = s * pk + c * qk;
				}
			}
	}
	fail_msg("Jacobi did not converge");
}

/* K phi = w^2 M phi, phi M-orthonormal (columns of phi, row-major n x n). */
struct modes {
	size_t n;
	double *w; /* rad/s */
	double *phi;
};

static void modes_compute(const struct irdm_fem *fem, struct modes *md)
{
	size_t n = fem->K.n;
	double *k = irdm_csc_to_dense(&fem->K), *m = irdm_csc_to_dense(&fem->M);
	double *l = malloc(n * n * sizeof(double)), *q = malloc(n * n * sizeof(double));
	double *col = malloc(n * sizeof(double));

	assert_true(k && m && l && q && col);
	md->n = n;
	md->w = malloc(n * sizeof(double));
	md->phi = malloc(n * n * sizeof(double));
	assert_true(md->w && md->phi);
	dense_cholesky(n, m, l);
	/* a = L^-1 K L^-T, built column by column (K symmetric) */
	for (size_t j = 0; j < n; j++)
		lower_solve(n, l, &k[j * n]); /* rows of k now hold L^-1 K columns */
	for (size_t j = 0; j < n; j++) {
		for (size_t i = 0; i < n; i++)
			col[i] = k[i * n + j];
		lower_solve(n, l, col);
		for (size_t i = 0; i < n; i++)
			m[i * n + j] = col[i];
	}
	jacobi_eig(n, m, q);
	for (size_t j = 0; j < n; j++) {
		assert_true(m[j * n + j] > 0);
		md->w[j] = sqrt(m[j * n + j]);
		for (size_t i = 0; i < n; i++)
			col[i] = q[i * n + j];
		upper_solve(n, l, col);
		for (size_t i = 0; i < n; i++)
			md->phi[i * n + j] = col[i];
	}
	free(k);
	free(m);
	free(l);
	free(q);
	free(col);
}

static void modes_free(struct modes *md)
{
	free(md->w);
	free(md->phi);
}

/* Exact unit-step response of q'' + 2 z w q' + w^2 q = 1 from rest. */
static double step_response(double w, double z, double t)
{
	double zw = z * w;

	if (z < 1 - 1e-9) {
		double wd = w * sqrt(1 - z * z);

		return (1 - exp(-zw * t) * (cos(wd * t) + zw / wd * sin(wd * t))) / (w * w);
	}
	if (z > 1 + 1e-9) {
		double r = w * sqrt(z * z - 1), l1 = -zw + r, l2 = -zw - r;

		return (1 + (l2 * exp(l1 * t) - l1 * exp(l2 * t)) / (l1 - l2)) / (w * w);
	}
	return (1 - exp(-w * t) * (1 + w * t)) / (w * w);
}

/* Exact ZOH responses, same layout as irdm_td_responses(). */
static void modal_reference(const struct irdm_fem *fem, const struct modes *md,
			    const struct irdm_rayleigh *ray, double dt, unsigned T,
			    const int64_t *in, size_t n_in, const uint32_t *out, size_t n_out,
			    double *R)
{
	size_t n = md->n;

	for (size_t i = 0; i < n_in; i++) {
		size_t fi = (size_t)fem->map.free_of[in[i]];

		for (unsigned s = 0; s < T; s++)
			for (size_t o = 0; o < n_out; o++)
				for (size_t a = 0; a < 3; a++) {
					int64_t fo = fem->map.free_of[3 * (size_t)out[o] + a];
					double acc = 0;

					for (size_t k = 0; fo >= 0 && k < n; k++) {
						double z = irdm_rayleigh_ratio(ray, md->w[k]);
						double r = step_response(md->w[k], z, (s + 1) * dt) - step_response(md->w[k], z, s * dt);

						acc += md->phi[(size_t)fo * n + k] * md->phi[fi * n + k] * r;
					}
					R[(i * T + s) * 3 * n_out + 3 * o + a] = acc;
				}
	}
}

static double max_abs(const double *x, size_t n)
{
	double m = 0;

	for (size_t i = 0; i < n; i++)
		m = fmax(m, fabs(x[i]));
	return m;
}

static double rel_err(const double *x, const double *ref, size_t n)
{
	double e = 0;

	for (size_t i = 0; i < n; i++)
		e = fmax(e, fabs(x[i] - ref[i]));
	return e / max_abs(ref, n);
}

static void td_run(const struct irdm_mesh *mesh, const struct irdm_fem *fem,
		   const struct irdm_td_opts *o, const int64_t *in, size_t n_in,
		   const uint32_t *out, size_t n_out, double *R)
{
	char err[256] = "";

	if (irdm_td_responses(mesh, fem, o, in, n_in, out, n_out, R, err, sizeof(err)))
		fail_msg("irdm_td_responses: %s", err);
}

/*
 * Newmark against the exact modal ZOH response for substeps m, 2m, 4m, ...:
 * relative errors go to errs[].
 */
static void convergence(const struct irdm_mesh *mesh, const struct irdm_fem *fem,
			const struct irdm_rayleigh *ray, double dt, unsigned T,
			const int64_t *in, size_t n_in, const uint32_t *out, size_t n_out,
			unsigned m0, int levels, double *errs)
{
	size_t len = n_in * T * 3 * n_out;
	double *ref = malloc(len * sizeof(double)), *R = malloc(len * sizeof(double));
	struct modes md;

	assert_true(ref && R);
	modes_compute(fem, &md);
	modal_reference(fem, &md, ray, dt, T, in, n_in, out, n_out, ref);
	for (int l = 0; l < levels; l++) {
		struct irdm_td_opts o = { .dt_s = dt, .n_samples = T, .substeps = m0 << l, .damping = *ray, .threads = 1 };

		td_run(mesh, fem, &o, in, n_in, out, n_out, R);
		errs[l] = rel_err(R, ref, len);
		print_message("  substeps %4u: max rel error %.3e\n", m0 << l, errs[l]);
		if (l)
			print_message("                 ratio %.3f\n", errs[l - 1] / errs[l]);
	}
	modes_free(&md);
	free(ref);
	free(R);
}

/* ---- 1. one free node vs the exact modal response ------------------------ */

static void test_single_node_modal(void **state)
{
	(void)state;
	struct irdm_mesh mesh = { 0 };
	struct irdm_fem fem;
	double p[12] = { 0, 0, 0, 0.1, 0, 0, 0, 0.1, 0, 0.02, 0.03, 0.1 };
	uint32_t tet[4] = { 0, 1, 2, 3 };
	const bool fixed[4] = { true, true, true, false };
	const struct irdm_rayleigh ray = { 4.0, 1e-4 };
	const int64_t in[3] = { 9, 10, 11 };
	const uint32_t out[1] = { 3 };
	char err[256];
	double errs[4], wmax = 0;
	struct modes md;

	mesh.n_nodes = 4;
	mesh.n_tets = 1;
	mesh.pos_m = p;
	mesh.tets = tet;
	if (irdm_fem_assemble(&mesh, &soft, IRDM_MASS_LUMPED, fixed, &fem, err, sizeof(err)))
		fail_msg("%s", err);
	assert_int_equal(fem.map.n_free, 3);
	modes_compute(&fem, &md);
	for (size_t k = 0; k < 3; k++) {
		wmax = fmax(wmax, md.w[k]);
		print_message("  mode %zu: w = %.4g rad/s, zeta = %.4f\n", k, md.w[k],
			      irdm_rayleigh_ratio(&ray, md.w[k]));
	}
	modes_free(&md);
	/* w_max dt = 0.4: a coarse sample so substeps matter; 40 samples */
	convergence(&mesh, &fem, &ray, 0.4 / wmax, 40, in, 3, out, 1, 8, 4, errs);
	assert_true(errs[3] <= 1e-4);
	for (int l = 1; l < 4; l++) {
		assert_true(errs[l - 1] / errs[l] >= 3.5);
		assert_true(errs[l - 1] / errs[l] <= 4.5);
	}
	irdm_fem_free(&fem);
}

/* Consistent (non-diagonal) mass on a small grounded box: exercises the
 * a0-free formulation where M^-1 f is not trivial. */
static void test_box_consistent_modal(void **state)
{
	(void)state;
	struct irdm_mesh mesh;
	struct irdm_fem fem;
	const struct irdm_rayleigh ray = { 2.0, 2e-4 };
	int64_t in[4];
	uint32_t out[12];
	double errs[4];

	box_mesh(&mesh, 0.05, 0.05, 0.1, 1, 1, 2, 1.0);
	box_fem(&mesh, IRDM_MASS_CONSISTENT, true, &fem);
	for (uint32_t i = 0; i < mesh.n_nodes; i++)
		out[i] = i; /* includes the fixed nodes: must read 0 */
	in[0] = 3 * 11 + 0;
	in[1] = 3 * 11 + 2;
	in[2] = 3 * 6 + 1;
	in[3] = 3 * 9 + 0;
	convergence(&mesh, &fem, &ray, 1e-3, 60, in, 4, out, mesh.n_nodes, 8, 4, errs);
	assert_true(errs[3] <= 1e-4);
	for (int l = 1; l < 4; l++) {
		assert_true(errs[l - 1] / errs[l] >= 3.5);
		assert_true(errs[l - 1] / errs[l] <= 4.5);
	}
	irdm_fem_free(&fem);
	mesh_release(&mesh);
}

/* ---- 2. reciprocity, R[0] SPD --------------------------------------------- */

/* Input set on the 2x2x4 box: DoFs spread over the free nodes. */
static const uint32_t recip_nodes[6] = { 44, 40, 22, 26, 33, 10 };

static void test_reciprocity(void **state)
{
	(void)state;
	struct irdm_mesh mesh;
	struct irdm_fem fem;
	const unsigned T = 200;
	const size_t n = 6;
	int64_t in[6];
	double *R, worst = 0, r0[36], l0[36];

	box_mesh(&mesh, 0.1, 0.1, 0.2, 2, 2, 4, 1.0);
	box_fem(&mesh, IRDM_MASS_LUMPED, true, &fem);
	for (size_t i = 0; i < n; i++)
		in[i] = 3 * (int64_t)recip_nodes[i] + (int64_t)(i % 3);
	R = malloc(n * T * 3 * n * sizeof(double));
	assert_non_null(R);
	struct irdm_td_opts o = { .dt_s = 2e-3, .n_samples = T, .substeps = 4, .damping = { 1.0, 1e-3 }, .threads = 2 };

	td_run(&mesh, &fem, &o, in, n, recip_nodes, n, R);
	double scale = max_abs(R, n * T * 3 * n);

	for (unsigned s = 0; s < T; s++)
		for (size_t i = 0; i < n; i++)
			for (size_t j = 0; j < n; j++) {
				/* response at DoF j from input i, and the reverse */
				double ij = R[(i * T + s) * 3 * n + 3 * j + j % 3];
				double ji = R[(j * T + s) * 3 * n + 3 * i + i % 3];

				worst = fmax(worst, fabs(ij - ji) / scale);
				if (s == 0)
					r0[i * n + j] = ij;
			}
	print_message("  reciprocity: max |R_ij - R_ji| / max|R| = %.3e\n", worst);
	assert_true(worst <= 1e-10);
	dense_cholesky(n, r0, l0); /* asserts R[0] is positive definite */
	free(R);
	irdm_fem_free(&fem);
	mesh_release(&mesh);
}

/* ---- 3. static limit ------------------------------------------------------- */

static void test_static_limit(void **state)
{
	(void)state;
	struct irdm_mesh mesh;
	struct irdm_fem fem;
	struct irdm_rayleigh ray;
	struct modes md;
	const unsigned T = 300;
	const int64_t in[2] = { 3 * 44 + 0, 3 * 42 + 2 };
	uint32_t out[45];
	char err[256];
	double w1 = INFINITY, worst = 0;

	box_mesh(&mesh, 0.1, 0.1, 0.2, 2, 2, 4, 1.0);
	box_fem(&mesh, IRDM_MASS_LUMPED, true, &fem);
	size_t n = fem.K.n, no = mesh.n_nodes;

	for (uint32_t i = 0; i < no; i++)
		out[i] = i;
	modes_compute(&fem, &md);
	for (size_t k = 0; k < n; k++)
		w1 = fmin(w1, md.w[k]);
	modes_free(&md);
	/* critical damping at w1 and 10 w1: everything settles by 30 / w1 */
	assert_int_equal(irdm_rayleigh_from_ratios(1.0, w1, 1.0, 10 * w1, &ray, err,
						   sizeof(err)),
			 0);
	double *R = malloc(2 * T * 3 * no * sizeof(double));
	double *k = irdm_csc_to_dense(&fem.K), *l = malloc(n * n * sizeof(double));
	double *x = malloc(n * sizeof(double));

	assert_true(R && k && l && x);
	struct irdm_td_opts o = { .dt_s = 30.0 / w1 / T, .n_samples = T, .substeps = 2, .damping = ray };

	td_run(&mesh, &fem, &o, in, 2, out, no, R);
	dense_cholesky(n, k, l);
	for (size_t i = 0; i < 2; i++) {
		double xmax;

		memset(x, 0, n * sizeof(double));
		x[fem.map.free_of[in[i]]] = 1.0;
		lower_solve(n, l, x);
		upper_solve(n, l, x);
		xmax = max_abs(x, n);
		for (size_t g = 0; g < 3 * no; g++) {
			double sum = 0, ref = fem.map.free_of[g] < 0 ? 0 : x[fem.map.free_of[g]];

			for (unsigned s = 0; s < T; s++)
				sum += R[(i * T + s) * 3 * no + g];
			worst = fmax(worst, fabs(sum - ref) / xmax);
		}
	}
	print_message("  static limit: max |sum_s R[s] - K^-1 e_i| / max|K^-1 e_i| = %.3e\n",
		      worst);
	assert_true(worst <= 1e-6);
	free(R);
	free(k);
	free(l);
	free(x);
	irdm_fem_free(&fem);
	mesh_release(&mesh);
}

/* ---- 4. rigid fits ---------------------------------------------------------- */

static void rotation_axis_angle(const double axis[3], double ang, double r[9])
{
	double n = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
	double x = axis[0] / n, y = axis[1] / n, z = axis[2] / n;
	double c = cos(ang), s = sin(ang), t = 1 - c;

	r[0] = t * x * x + c;
	r[1] = t * x * y - s * z;
	r[2] = t * x * z + s * y;
	r[3] = t * x * y + s * z;
	r[4] = t * y * y + c;
	r[5] = t * y * z - s * x;
	r[6] = t * x * z - s * y;
	r[7] = t * y * z + s * x;
	r[8] = t * z * z + c;
}

/* Weighted centroid, and the 6 rigid modes M-orthonormalised (Gram-Schmidt). */
static void rigid_modes(size_t nn, const double *p, const double *w, double *phi)
{
	double c[3] = { 0, 0, 0 }, tw = 0;

	for (size_t i = 0; i < nn; i++) {
		tw += w[i];
		for (int k = 0; k < 3; k++)
			c[k] += w[i] * p[3 * i + k];
	}
	for (int k = 0; k < 3; k++)
		c[k] /= tw;
	for (int m = 0; m < 6; m++) {
		double *v = &phi[(size_t)m * 3 * nn];

		for (size_t i = 0; i < nn; i++) {
			double r[3] = { p[3 * i] - c[0], p[3 * i + 1] - c[1], p[3 * i + 2] - c[2] };
			double e[3] = { 0, 0, 0 };

			e[m % 3] = 1;
			if (m < 3) {
				memcpy(&v[3 * i], e, sizeof(e));
			} else { /* e x r */
				v[3 * i] = e[1] * r[2] - e[2] * r[1];
				v[3 * i + 1] = e[2] * r[0] - e[0] * r[2];
				v[3 * i + 2] = e[0] * r[1] - e[1] * r[0];
			}
		}
		/* twice, for orthogonality to the last bit */
		for (int pass = 0; pass < 2; pass++)
			for (int q = 0; q < m; q++) {
				const double *u = &phi[(size_t)q * 3 * nn];
				double d = 0;

				for (size_t i = 0; i < 3 * nn; i++)
					d += w[i / 3] * u[i] * v[i];
				for (size_t i = 0; i < 3 * nn; i++)
					v[i] -= d * u[i];
			}
		double nrm = 0;

		for (size_t i = 0; i < 3 * nn; i++)
			nrm += w[i / 3] * v[i] * v[i];
		for (size_t i = 0; i < 3 * nn; i++)
			v[i] /= sqrt(nrm);
	}
}

/* v <- v - Phi Phi^T W v */
static void remove_modes(size_t nn, const double *w, const double *phi, double *v)
{
	for (int m = 0; m < 6; m++) {
		const double *u = &phi[(size_t)m * 3 * nn];
		double d = 0;

		for (size_t i = 0; i < 3 * nn; i++)
			d += w[i / 3] * u[i] * v[i];
		for (size_t i = 0; i < 3 * nn; i++)
			v[i] -= d * u[i];
	}
}

static double vec_max_diff(const double *a, const double *b, size_t n)
{
	double e = 0;

	for (size_t i = 0; i < n; i++)
		e = fmax(e, fabs(a[i] - b[i]));
	return e;
}

static void test_rigid_fit(void **state)
{
	(void)state;
	struct irdm_mesh mesh;
	struct irdm_fem fem;
	struct irdm_rigid_fit fit, fit_u;
	const double axis[3] = { 1, 2, 3 }, t0[3] = { 0.3, -0.2, 0.5 }, L = 0.1;
	double r0[9], c[3], mass, inertia[9];

	/* graded grid: node masses vary by ~ an order of magnitude */
	box_mesh(&mesh, L, L, L, 3, 3, 3, 2.0);
	box_fem(&mesh, IRDM_MASS_LUMPED, false, &fem);
	size_t nn = mesh.n_nodes, n3 = 3 * nn;
	const double *p = mesh.pos_m, *w = fem.lumped_mass_kg;
	double *d = malloc(n3 * sizeof(double)), *q = malloc(n3 * sizeof(double));
	double *res = malloc(n3 * sizeof(double)), *phi = malloc(6 * n3 * sizeof(double));

	assert_true(d && q && res && phi);
	irdm_mass_properties(&mesh, w, &mass, c, inertia);
	rigid_modes(nn, p, w, phi);
	/* a smooth deformation, made mass-orthogonal to the rigid modes */
	for (size_t i = 0; i < nn; i++) {
		const double *x = &p[3 * i];

		d[3 * i] = 1e-3 * L * sin(3 * x[0] / L + x[2] / L);
		d[3 * i + 1] = 1e-3 * x[0] * x[1] / L;
		d[3 * i + 2] = 1e-3 * (x[2] * x[2] / L - x[1]);
	}
	remove_modes(nn, w, phi, d);
	rotation_axis_angle(axis, M_PI / 6, r0);
	for (size_t i = 0; i < nn; i++) {
		double b[3];

		for (int k = 0; k < 3; k++)
			b[k] = p[3 * i + k] - c[k] + d[3 * i + k];
		for (int a = 0; a < 3; a++)
			q[3 * i + a] = r0[3 * a] * b[0] + r0[3 * a + 1] * b[1] + r0[3 * a + 2] * b[2] + c[a] + t0[a];
	}

	/* mass-weighted Kabsch recovers rotation and deformation */
	assert_int_equal(irdm_rigid_fit_kabsch(nn, p, q, w, &fit), 0);
	irdm_rigid_fit_residual(&fit, nn, p, q, res);
	double erot = vec_max_diff(fit.rot, r0, 9), dmax = max_abs(d, n3);
	double edef = vec_max_diff(res, d, n3) / dmax;

	print_message("  weighted Kabsch: rotation error %.3e, deformation error %.3e (rel)\n",
		      erot, edef);
	assert_true(erot <= 1e-12);
	assert_true(edef <= 1e-9);

	/* the unweighted fit is measurably off on this graded mesh */
	assert_int_equal(irdm_rigid_fit_kabsch(nn, p, q, NULL, &fit_u), 0);
	irdm_rigid_fit_residual(&fit_u, nn, p, q, res);
	double erot_u = vec_max_diff(fit_u.rot, r0, 9);
	double edef_u = vec_max_diff(res, d, n3) / dmax;

	print_message("  unweighted Kabsch: rotation error %.3e, deformation error %.3e (rel)\n",
		      erot_u, edef_u);
	assert_true(edef_u > 1e-3);

	/* linear projection: an infinitesimal rigid field projects to ~0 ... */
	const double th[3] = { 0.7, -0.4, 0.25 }, tr[3] = { 2.0, 1.0, -3.0 };

	for (size_t i = 0; i < nn; i++) {
		double r[3] = { p[3 * i] - c[0], p[3 * i + 1] - c[1], p[3 * i + 2] - c[2] };

		q[3 * i] = tr[0] + th[1] * r[2] - th[2] * r[1];
		q[3 * i + 1] = tr[1] + th[2] * r[0] - th[0] * r[2];
		q[3 * i + 2] = tr[2] + th[0] * r[1] - th[1] * r[0];
	}
	double qmax = max_abs(q, n3);

	assert_int_equal(irdm_rigid_project_linear(nn, p, w, q, res), 0);
	print_message("  linear projection of a rigid field: %.3e (rel)\n",
		      max_abs(res, n3) / qmax);
	assert_true(max_abs(res, n3) <= 1e-13 * qmax);
	/* ... a mass-orthogonal deformation is left alone (projection) ... */
	for (size_t i = 0; i < n3; i++)
		q[i] += d[i] / 1e-3;
	assert_int_equal(irdm_rigid_project_linear(nn, p, w, q, res), 0);
	for (size_t i = 0; i < n3; i++)
		res[i] *= 1e-3;
	double eproj = vec_max_diff(res, d, n3) / dmax;

	print_message("  linear projection keeps the deformation: %.3e (rel)\n", eproj);
	assert_true(eproj <= 1e-12);
	/* ... and the small-eps Kabsch removal tends to it */
	assert_int_equal(irdm_rigid_remove_kabsch(nn, p, w, q, 1e-7, res), 0);
	for (size_t i = 0; i < n3; i++)
		res[i] *= 1e-3;
	double ekab = vec_max_diff(res, d, n3) / dmax;

	print_message("  eps-Kabsch removal vs exact deformation: %.3e (rel)\n", ekab);
	assert_true(ekab <= 1e-5);

	/* a mirror image still gives a proper rotation (reflection guard) */
	for (size_t i = 0; i < n3; i++)
		q[i] = i % 3 == 0 ? -p[i] : p[i];
	assert_int_equal(irdm_rigid_fit_kabsch(nn, p, q, w, &fit), 0);
	double *R9 = fit.rot;
	double det = R9[0] * (R9[4] * R9[8] - R9[5] * R9[7]) - R9[1] * (R9[3] * R9[8] - R9[5] * R9[6]) + R9[2] * (R9[3] * R9[7] - R9[4] * R9[6]);

	assert_true(fabs(det - 1) <= 1e-12);
	/* collinear points: rotation undetermined */
	for (size_t i = 0; i < n3; i++)
		q[i] = i % 3 == 0 ? p[i] : 0.0;
	assert_int_equal(irdm_rigid_fit_kabsch(nn, q, q, w, &fit), IRDM_ENUMERIC);

	free(d);
	free(q);
	free(res);
	free(phi);
	irdm_fem_free(&fem);
	mesh_release(&mesh);
}

static void test_svd3(void **state)
{
	(void)state;
	const double a[3][9] = {
		{ 1, 2, 3, 4, 5, 6, 7, 8, 10 },
		{ 1, 2, 3, 2, 4, 6, 1, 0, 1 }, /* rank 2 */
		{ 0, 0, 0, 0, 0, 0, 0, 0, 0 },
	};

	for (int c = 0; c < 3; c++) {
		double u[9], s[3], v[9], e = 0, o = 0;

		assert_int_equal(irdm_svd3(a[c], u, s, v), 0);
		assert_true(s[0] >= s[1] && s[1] >= s[2] && s[2] >= 0);
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++) {
				double x = 0, uu = 0, vv = 0;

				for (int k = 0; k < 3; k++) {
					x += u[3 * i + k] * s[k] * v[3 * j + k];
					uu += u[3 * k + i] * u[3 * k + j];
					vv += v[3 * k + i] * v[3 * k + j];
				}
				e = fmax(e, fabs(x - a[c][3 * i + j]));
				o = fmax(o, fmax(fabs(uu - (i == j)), fabs(vv - (i == j))));
			}
		assert_true(e <= 1e-13 * (1 + s[0]));
		assert_true(o <= 1e-14);
	}
}

/* ---- 5. floating responses ---------------------------------------------------- */

/* Worst relative net momentum-like sums over n_col response columns. */
static void momentum_residue(const struct irdm_mesh *mesh, const double *w, const double c[3],
			     const double *R, size_t n_col, double *wt, double *wr)
{
	size_t no = mesh->n_nodes;
	const double *p = mesh->pos_m;

	*wt = *wr = 0;
	for (size_t k = 0; k < n_col; k++) {
		const double *u = &R[k * 3 * no];
		double sm[3] = { 0, 0, 0 }, sr[3] = { 0, 0, 0 }, nt = 0, nr = 0;

		for (size_t i = 0; i < no; i++) {
			const double *x = &u[3 * i];
			double r[3] = { p[3 * i] - c[0], p[3 * i + 1] - c[1], p[3 * i + 2] - c[2] };
			double un = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);

			for (int a = 0; a < 3; a++)
				sm[a] += w[i] * x[a];
			sr[0] += w[i] * (r[1] * x[2] - r[2] * x[1]);
			sr[1] += w[i] * (r[2] * x[0] - r[0] * x[2]);
			sr[2] += w[i] * (r[0] * x[1] - r[1] * x[0]);
			nt += w[i] * un;
			nr += w[i] * un * sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
		}
		assert_true(nt > 0);
		*wt = fmax(*wt, sqrt(sm[0] * sm[0] + sm[1] * sm[1] + sm[2] * sm[2]) / nt);
		*wr = fmax(*wr, sqrt(sr[0] * sr[0] + sr[1] * sr[1] + sr[2] * sr[2]) / nr);
	}
}

static void test_floating(void **state)
{
	(void)state;
	struct irdm_mesh mesh;
	struct irdm_fem fem;
	const unsigned T = 100;
	const int64_t in[3] = { 3 * 26 + 0, 3 * 20 + 2, 3 * 8 + 1 };
	uint32_t out[27];
	double c[3], mass, inertia[9];

	box_mesh(&mesh, 0.12, 0.12, 0.12, 2, 2, 2, 1.3);
	box_fem(&mesh, IRDM_MASS_LUMPED, false, &fem);
	size_t no = mesh.n_nodes, len = 3 * T * 3 * no;
	const double *w = fem.lumped_mass_kg;

	for (uint32_t i = 0; i < no; i++)
		out[i] = i;
	irdm_mass_properties(&mesh, w, &mass, c, inertia);
	double *R = malloc(len * sizeof(double)), *RL = malloc(len * sizeof(double));

	assert_true(R && RL);
	struct irdm_td_opts o = { .dt_s = 2e-3, .n_samples = T, .substeps = 4, .damping = { 0.0, 2e-3 }, .floating = true };

	double wt, wr, wtk, wrk;

	td_run(&mesh, &fem, &o, in, 3, out, no, RL); /* default: linear */
	momentum_residue(&mesh, w, c, RL, 3 * T, &wt, &wr);
	print_message("  floating (linear): |sum m u| / sum m|u| = %.3e,"
		      " |sum m r x u| / sum m|r||u| = %.3e\n",
		      wt, wr);
	assert_true(wt <= 1e-12);
	assert_true(wr <= 1e-12);

	o.rigid = IRDM_TD_RIGID_KABSCH;
	td_run(&mesh, &fem, &o, in, 3, out, no, R);
	momentum_residue(&mesh, w, c, R, 3 * T, &wtk, &wrk);
	double dl = rel_err(R, RL, len);

	print_message("  floating (Kabsch, eps %.0e): %.3e, %.3e; vs linear %.3e (rel)\n",
		      IRDM_TD_KABSCH_REL_EPS, wtk, wrk, dl);
	assert_true(wtk <= 1e-6);
	assert_true(wrk <= 1e-6);
	assert_true(dl <= 1e-6);

	/* the raw response does drift: removal is not a no-op */
	o.floating = false;
	td_run(&mesh, &fem, &o, in, 3, out, no, R);
	momentum_residue(&mesh, w, c, R, 3 * T, &wt, &wr);
	assert_true(wt > 0.1);
	free(R);
	free(RL);
	irdm_fem_free(&fem);
	mesh_release(&mesh);
}

/* ---- 6. threads, progress --------------------------------------------------- */

struct progress_log {
	size_t calls;
	size_t last;
	size_t total;
	bool monotone;
};

static void progress_cb(void *ctx, size_t done, size_t total)
{
	struct progress_log *pl = ctx;

	pl->calls++;
	pl->monotone = pl->monotone && done > pl->last && done <= total;
	pl->last = done;
	pl->total = total;
}

static void test_threads_bitwise(void **state)
{
	(void)state;
	struct irdm_mesh mesh;
	struct irdm_fem fem;
	const unsigned T = 80;
	int64_t in[10];
	uint32_t out[5] = { 44, 40, 22, 13, 0 };
	struct progress_log pl = { .monotone = true };

	box_mesh(&mesh, 0.1, 0.1, 0.2, 2, 2, 4, 1.0);
	box_fem(&mesh, IRDM_MASS_LUMPED, true, &fem);
	for (size_t i = 0; i < 10; i++)
		in[i] = fem.map.global_of[7 * i + 3];
	size_t len = 10 * T * 3 * 5;
	double *r1 = malloc(len * sizeof(double)), *r2 = malloc(len * sizeof(double));
	double *r3 = malloc(len * sizeof(double));

	assert_true(r1 && r2 && r3);
	struct irdm_td_opts o = { .dt_s = 1e-3, .n_samples = T, .substeps = 3, .damping = { 1.0, 1e-3 }, .threads = 1 };

	td_run(&mesh, &fem, &o, in, 10, out, 5, r1);
	o.threads = 2;
	o.progress = progress_cb;
	o.progress_ctx = &pl;
	td_run(&mesh, &fem, &o, in, 10, out, 5, r2);
	o.threads = 0;
	o.progress = NULL;
	td_run(&mesh, &fem, &o, in, 10, out, 5, r3);
	assert_memory_equal(r1, r2, len * sizeof(double));
	assert_memory_equal(r1, r3, len * sizeof(double));
	/* fixed node 0 reads exactly 0 */
	for (unsigned s = 0; s < T; s++)
		for (int a = 0; a < 3; a++)
			assert_true(r1[(0 * T + s) * 15 + 12 + a] == 0.0);
	print_message("  progress: %zu calls, last %zu / %zu\n", pl.calls, pl.last, pl.total);
	assert_true(pl.calls >= 1 && pl.monotone);
	assert_int_equal(pl.last, 10);
	assert_int_equal(pl.total, 10);
	free(r1);
	free(r2);
	free(r3);
	irdm_fem_free(&fem);
	mesh_release(&mesh);
}

/* ---- 7. validation ---------------------------------------------------------- */

static void expect_error(const struct irdm_mesh *mesh, const struct irdm_fem *fem,
			 const struct irdm_td_opts *o, int64_t in, uint32_t out,
			 const char *needle)
{
	char err[256] = "";
	double R[3 * 4];

	assert_int_equal(irdm_td_responses(mesh, fem, o, &in, 1, &out, 1, R, err,
					   sizeof(err)),
			 IRDM_EINVAL);
	print_message("  rejected: %s\n", err);
	assert_non_null(strstr(err, needle));
}

static void test_bad_input(void **state)
{
	(void)state;
	struct irdm_mesh mesh;
	struct irdm_fem fem;
	const struct irdm_td_opts good = { .dt_s = 1e-3, .n_samples = 4, .substeps = 2 };
	struct irdm_td_opts o;

	box_mesh(&mesh, 0.1, 0.1, 0.1, 1, 1, 1, 1.0);
	box_fem(&mesh, IRDM_MASS_LUMPED, true, &fem);
	o = good;
	o.substeps = 0;
	expect_error(&mesh, &fem, &o, 3 * 7, 7, "substeps");
	o = good;
	o.n_samples = 0;
	expect_error(&mesh, &fem, &o, 3 * 7, 7, "n_samples");
	o = good;
	o.dt_s = 0;
	expect_error(&mesh, &fem, &o, 3 * 7, 7, "dt");
	o.dt_s = -1e-3;
	expect_error(&mesh, &fem, &o, 3 * 7, 7, "dt");
	o.dt_s = NAN;
	expect_error(&mesh, &fem, &o, 3 * 7, 7, "dt");
	o = good;
	o.damping.b_s = -1;
	expect_error(&mesh, &fem, &o, 3 * 7, 7, "damping");
	expect_error(&mesh, &fem, &good, 3 * 0 + 2, 7, "fixed");
	expect_error(&mesh, &fem, &good, 3 * 8, 7, "out of range");
	expect_error(&mesh, &fem, &good, -1, 7, "out of range");
	expect_error(&mesh, &fem, &good, 3 * 7, 8, "output node 8");
	o = good;
	o.floating = true;
	expect_error(&mesh, &fem, &o, 3 * 7, 7, "floating");
	/* nothing asked: fine, nothing written */
	char err[64];

	assert_int_equal(irdm_td_responses(&mesh, &fem, &good, NULL, 0, NULL, 0, NULL, err,
					   sizeof(err)),
			 0);
	irdm_fem_free(&fem);
	mesh_release(&mesh);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_single_node_modal),
		cmocka_unit_test(test_box_consistent_modal),
		cmocka_unit_test(test_reciprocity),
		cmocka_unit_test(test_static_limit),
		cmocka_unit_test(test_svd3),
		cmocka_unit_test(test_rigid_fit),
		cmocka_unit_test(test_floating),
		cmocka_unit_test(test_threads_bitwise),
		cmocka_unit_test(test_bad_input),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
