/* SPDX-License-Identifier: MIT */
/*
 * A floating object (the paper's 12 cm cube, section 5.2) grabbed at a top
 * node and driven by a prescribed world trajectory of that point: a swing,
 * a tap and a swirl (paper Fig. 9-10).  The engine (modal state recursion,
 * midpoint rigid-body step, linearised solve + Newton) against a reference
 * built here by other methods: direct double convolution of the image's
 * responses for the deformation, classical RK4 with 64 sub-steps for the
 * rigid motion under the same zero-order-held force and torque, and a
 * finite-difference Newton solve of the exact end-of-tick position.
 * The target: relative RMS force error <= 1e-4.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "image/image_response.h"
#include "support/engine_fixture.h"
#include "irdm/posix/image_map.h"

static char dir[64];
static struct irdm_image cube;
#define N_TICKS 2000

/* ---- reference rigid body: RK4 on (x, v, q, w_body) ---- */

struct body {
	double x[3], v[3], q[4], w[3];
};

static double mass, inertia[9], inv_inertia[9], com0[3];

static void quat_rotate(const double q[4], const double v[3], double o[3])
{
	double w = q[0], x = q[1], y = q[2], z = q[3];
	double R[9] = {
		1 - 2 * (y * y + z * z),
		2 * (x * y - w * z),
		2 * (x * z + w * y),
		2 * (x * y + w * z),
		1 - 2 * (x * x + z * z),
		2 * (y * z - w * x),
		2 * (x * z - w * y),
		2 * (y * z + w * x),
		1 - 2 * (x * x + y * y),
	};
	for (int r = 0; r < 3; r++)
		o[r] = R[3 * r] * v[0] + R[3 * r + 1] * v[1] + R[3 * r + 2] * v[2];
}

static void quat_rotate_inv(const double q[4], const double v[3], double o[3])
{
	double qc[4] = { q[0], -q[1], -q[2], -q[3] };
	quat_rotate(qc, v, o);
}

static void mat_vec(const double m[9], const double v[3], double o[3])
{
	for (int r = 0; r < 3; r++)
		o[r] = m[3 * r] * v[0] + m[3 * r + 1] * v[1] + m[3 * r + 2] * v[2];
}

/* derivative under world force f and world torque tau (constant) */
static void deriv(const struct body *b, const double f[3], const double tau[3], struct body *d)
{
	double tb[3], iw[3], gyro[3], rhs[3];
	double nq = sqrt(b->q[0] * b->q[0] + b->q[1] * b->q[1] + b->q[2] * b->q[2] + b->q[3] * b->q[3]);
	double q[4] = { b->q[0] / nq, b->q[1] / nq, b->q[2] / nq, b->q[3] / nq };

	for (int a = 0; a < 3; a++) {
		d->x[a] = b->v[a];
		d->v[a] = f[a] / mass;
	}
	quat_rotate_inv(q, tau, tb);
	mat_vec(inertia, b->w, iw);
	gyro[0] = b->w[1] * iw[2] - b->w[2] * iw[1];
	gyro[1] = b->w[2] * iw[0] - b->w[0] * iw[2];
	gyro[2] = b->w[0] * iw[1] - b->w[1] * iw[0];
	for (int a = 0; a < 3; a++)
		rhs[a] = tb[a] - gyro[a];
	mat_vec(inv_inertia, rhs, d->w);
	/* q' = q (0, w) / 2 */
	const double *w = b->w;
	d->q[0] = 0.5 * (-b->q[1] * w[0] - b->q[2] * w[1] - b->q[3] * w[2]);
	d->q[1] = 0.5 * (b->q[0] * w[0] + b->q[2] * w[2] - b->q[3] * w[1]);
	d->q[2] = 0.5 * (b->q[0] * w[1] + b->q[3] * w[0] - b->q[1] * w[2]);
	d->q[3] = 0.5 * (b->q[0] * w[2] + b->q[1] * w[1] - b->q[2] * w[0]);
}

static void axpy(struct body *o, const struct body *b, double h, const struct body *d)
{
	const double *bp = (const double *)b, *dp = (const double *)d;
	double *op = (double *)o;
	for (size_t k = 0; k < sizeof(*b) / sizeof(double); k++)
		op[k] = bp[k] + h * dp[k];
}

static void rk4_tick(struct body *b, const double f[3], const double tau[3], double dt)
{
	const int sub = 64;
	double h = dt / sub;

	for (int k = 0; k < sub; k++) {
		struct body k1, k2, k3, k4, t;
		deriv(b, f, tau, &k1);
		axpy(&t, b, h / 2, &k1);
		deriv(&t, f, tau, &k2);
		axpy(&t, b, h / 2, &k2);
		deriv(&t, f, tau, &k3);
		axpy(&t, b, h, &k3);
		deriv(&t, f, tau, &k4);
		double *bp = (double *)b;
		const double *a1 = (double *)&k1, *a2 = (double *)&k2, *a3 = (double *)&k3, *a4 = (double *)&k4;
		for (size_t i = 0; i < sizeof(*b) / sizeof(double); i++)
			bp[i] += h / 6 * (a1[i] + 2 * a2[i] + 2 * a3[i] + a4[i]);
	}
	double nq = sqrt(b->q[0] * b->q[0] + b->q[1] * b->q[1] + b->q[2] * b->q[2] + b->q[3] * b->q[3]);
	for (int a = 0; a < 4; a++)
		b->q[a] /= nq;
}

/* world position of the body point p (relative to the COM) */
static void world_of(const struct body *b, const double p[3], double o[3])
{
	quat_rotate(b->q, p, o);
	for (int a = 0; a < 3; a++)
		o[a] += b->x[a];
}

/* ---- the reference run ---- */

struct ref {
	struct body b;
	const double *R; /* N x 9 responses of the contact node to itself */
	double *fb;      /* N x 3 body-frame force history */
	double rest[3];  /* contact rest point */
};

/*
 * The body-frame deformation of the point at the end of tick t under world
 * force F (body-frame fb) with the history so far, and the tick's rigid
 * step of b: the force acts where the point is deformed to at the end of
 * the tick (this tick's force included), in the pose at the start.
 */
static void step_with(const struct ref *r, size_t t, const double F[3], struct body *b, double u[3])
{
	double fb[3], p[3], xn[3], arm[3], tau[3];

	quat_rotate_inv(b->q, F, fb);
	memset(u, 0, 3 * sizeof(double));
	for (size_t s = 1; s <= t; s++)
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++)
				u[i] += r->R[9 * s + 3 * (size_t)i + (size_t)j] * r->fb[3 * (t - s) + (size_t)j];
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
			u[i] += r->R[3 * i + j] * fb[j];
	for (int a = 0; a < 3; a++)
		p[a] = r->rest[a] - com0[a] + u[a];
	world_of(b, p, xn);
	for (int a = 0; a < 3; a++)
		arm[a] = xn[a] - b->x[a];
	tau[0] = arm[1] * F[2] - arm[2] * F[1];
	tau[1] = arm[2] * F[0] - arm[0] * F[2];
	tau[2] = arm[0] * F[1] - arm[1] * F[0];
	rk4_tick(b, F, tau, cube.meta->dt_s);
}

/* end-of-tick world position of the point for world force F at tick t */
static void end_position(const struct ref *r, size_t t, const double F[3], double x[3])
{
	struct body b = r->b;
	double u[3], p[3];

	step_with(r, t, F, &b, u);
	for (int a = 0; a < 3; a++)
		p[a] = r->rest[a] - com0[a] + u[a];
	world_of(&b, p, x);
}

static void solve3(double a[9], double b[3])
{
	double d = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) + a[2] * (a[3] * a[7] - a[4] * a[6]);
	double x[3];
	x[0] = (b[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (b[1] * a[8] - a[5] * b[2]) + a[2] * (b[1] * a[7] - a[4] * b[2])) / d;
	x[1] = (a[0] * (b[1] * a[8] - a[5] * b[2]) - b[0] * (a[3] * a[8] - a[5] * a[6]) + a[2] * (a[3] * b[2] - b[1] * a[6])) / d;
	x[2] = (a[0] * (a[4] * b[2] - b[1] * a[7]) - a[1] * (a[3] * b[2] - b[1] * a[6]) + b[0] * (a[3] * a[7] - a[4] * a[6])) / d;
	memcpy(b, x, sizeof(x));
}

/* Newton with a finite-difference Jacobian on the exact end position. */
static void ref_tick(struct ref *r, size_t t, const double target[3], double F[3])
{
	double goal[3];

	for (int a = 0; a < 3; a++)
		goal[a] = r->rest[a] + target[a];
	for (int it = 0; it < 20; it++) {
		double x[3], g[3], J[9], big = 0;
		end_position(r, t, F, x);
		for (int a = 0; a < 3; a++) {
			g[a] = goal[a] - x[a];
			big = fmax(big, fabs(g[a]));
		}
		if (big < 1e-15)
			break;
		for (int k = 0; k < 3; k++) {
			double Fh[3] = { F[0], F[1], F[2] }, xh[3], h = 1e-4 * (1e-3 + fabs(F[k]));
			Fh[k] += h;
			end_position(r, t, Fh, xh);
			for (int a = 0; a < 3; a++)
				J[3 * a + k] = (xh[a] - x[a]) / h;
		}
		solve3(J, g);
		for (int a = 0; a < 3; a++)
			F[a] += g[a];
	}
	/* commit the tick */
	double u[3];
	quat_rotate_inv(r->b.q, F, &r->fb[3 * t]);
	step_with(r, t, F, &r->b, u);
}

static void reference(const struct irdm_contact_site *site, const double *target, double *F,
		      struct body *end)
{
	struct ref r;
	double f[3] = { 0, 0, 0 };

	memset(&r, 0, sizeof(r));
	r.R = malloc(N_TICKS * 9 * sizeof(double));
	r.fb = calloc(N_TICKS * 3, sizeof(double));
	assert_int_equal(irdm_image_response(&cube, site->col[0], site->row[0], N_TICKS, (double *)r.R), 0);
	memcpy(r.rest, site->rest_m, sizeof(r.rest));
	memcpy(r.b.x, com0, sizeof(com0));
	r.b.q[0] = 1;
	for (size_t t = 0; t < N_TICKS; t++) {
		const double *u = &target[3 * t];
		if (isnan(u[0])) {
			/* released: free flight, no force */
			double zero[3] = { 0, 0, 0 };
			rk4_tick(&r.b, zero, zero, cube.meta->dt_s);
			memset(&F[3 * t], 0, 3 * sizeof(double));
			continue;
		}
		ref_tick(&r, t, u, f);
		memcpy(&F[3 * t], f, sizeof(f));
	}
	if (end)
		*end = r.b;
	free((void *)r.R);
	free(r.fb);
}

/* The run; with keep, the session stays open (the caller closes it). */
static struct irdm_session *engine_run_keep(const struct irdm_contact_site *site,
					    const double *target, double *F, bool keep)
{
	struct irdm_engine_config cfg;
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];

	irdm_engine_config_default(&cfg);
	cfg.max_contacts = 1;
	struct irdm_session *ses = efx_session(&cube, &cfg);
	struct irdm_engine *e = ses->eng;
	for (size_t t = 0; t < N_TICKS; t++) {
		memset(cmd, 0, sizeof(cmd));
		if (!isnan(target[3 * t])) {
			if (irdm_engine_contact(e, 0)->mode == IRDM_CONTACT_OFF)
				assert_int_equal(irdm_engine_contact_begin(e, 0, site, IRDM_CONTACT_GRAB), 0);
			cmd[0].mode = IRDM_CONTACT_GRAB;
			memcpy(cmd[0].target_m, &target[3 * t], 3 * sizeof(double));
		}
		assert_int_equal(irdm_engine_tick(e, cmd), 0);
		memcpy(&F[3 * t], irdm_engine_contact(e, 0)->force_n, 3 * sizeof(double));
	}
	if (keep)
		return ses;
	irdm_session_close(ses);
	return NULL;
}

static void engine_run(const struct irdm_contact_site *site, const double *target, double *F)
{
	engine_run_keep(site, target, F, false);
}

static void compare(const char *what, const double *target)
{
	struct irdm_engine_config cfg;
	struct irdm_contact_site site;
	const double top[3] = { 0.06, 0.06, 0.12 };
	double *Fe = malloc(N_TICKS * 3 * sizeof(double)), *Fr = malloc(N_TICKS * 3 * sizeof(double));

	irdm_engine_config_default(&cfg);
	struct irdm_session *ses = efx_session(&cube, &cfg);
	struct irdm_engine *e = ses->eng;
	assert_int_equal(irdm_engine_site_node(e, efx_column_row_near(&cube, top), &site), 0);
	irdm_session_close(ses);
	engine_run(&site, target, Fe);
	reference(&site, target, Fr, NULL);
	double err = efx_rel_rms(Fe, Fr, N_TICKS * 3), peak = 0;
	for (size_t k = 0; k < N_TICKS * 3; k++)
		peak = fmax(peak, fabs(Fr[k]));
	print_message("%-8s peak |F| %.4f N, relative RMS force error %.2e\n", what, peak, err);
	assert_true(err <= 1e-4);
	free(Fe);
	free(Fr);
}

static void test_swing(void **state)
{
	double *u = calloc(N_TICKS * 3, sizeof(double));

	(void)state;
	/* picked up at the top and swung right and left: 3 cm, 1 Hz */
	for (size_t t = 0; t < N_TICKS; t++)
		u[3 * t] = 0.03 * sin(2 * M_PI * 1.0 * (double)(t + 1) * cube.meta->dt_s);
	compare("swing", u);
	free(u);
}

static void test_swirl(void **state)
{
	double *u = calloc(N_TICKS * 3, sizeof(double));

	(void)state;
	/* an elliptic orbit, axes 6 cm and 3 cm (the paper's), 1 Hz */
	for (size_t t = 0; t < N_TICKS; t++) {
		double ph = 2 * M_PI * 1.0 * (double)(t + 1) * cube.meta->dt_s;
		u[3 * t] = 0.03 * (cos(ph) - 1);
		u[3 * t + 1] = 0.015 * sin(ph);
	}
	compare("swirl", u);
	free(u);
}

static void test_tap(void **state)
{
	double *u = malloc(N_TICKS * 3 * sizeof(double));

	(void)state;
	/* a tap on the top: 2 mm in over 10 ms, out over 10 ms, let go */
	for (size_t t = 0; t < N_TICKS; t++) {
		double ms = (double)(t + 1);
		u[3 * t] = u[3 * t + 1] = 0;
		u[3 * t + 2] = -0.002 * (ms <= 10 ? ms / 10 : fmax(0, 2 - ms / 10));
		if (ms > 20)
			u[3 * t] = u[3 * t + 1] = u[3 * t + 2] = NAN;
	}
	compare("tap", u);
	free(u);
}

/*
 * The engine's frames after a swirl (the cube has moved and turned): a
 * point of the object's own frame goes to the world as the reference
 * body carries it, x = com + R(q) (p - com0), and back to itself.  The
 * contact proxy runs in the object's own frame (controller_contact.c).
 */
static void test_frames(void **state)
{
	const double top[3] = { 0.06, 0.06, 0.12 };
	const double pts[4][3] = { { 0, 0, 0 }, { 0.12, 0, 0 }, { 0.12, 0.12, 0.12 }, { 0.06, 0.06, 0.12 } };
	double *u = calloc(N_TICKS * 3, sizeof(double)), *F = malloc(N_TICKS * 3 * sizeof(double));
	double moved = 0, worst = 0, round = 0;
	struct irdm_engine_config cfg;
	struct irdm_contact_site site;
	struct body end;

	(void)state;
	for (size_t t = 0; t < N_TICKS; t++) {
		double ph = 2 * M_PI * 1.0 * (double)(t + 1) * cube.meta->dt_s;
		u[3 * t] = 0.03 * (cos(ph) - 1);
		u[3 * t + 1] = 0.015 * sin(ph);
	}
	irdm_engine_config_default(&cfg);
	struct irdm_session *ses = efx_session(&cube, &cfg);
	assert_int_equal(irdm_engine_site_node(ses->eng, efx_column_row_near(&cube, top), &site), 0);
	irdm_session_close(ses);
	ses = engine_run_keep(&site, u, F, true);
	reference(&site, u, F, &end);
	for (int k = 0; k < 4; k++) {
		double w[3], b[3], ref[3], back[3];

		irdm_engine_object_to_world(ses->eng, pts[k], w);
		irdm_engine_world_to_object(ses->eng, w, back);
		for (int a = 0; a < 3; a++)
			b[a] = pts[k][a] - com0[a];
		quat_rotate(end.q, b, ref);
		for (int a = 0; a < 3; a++) {
			ref[a] += end.x[a];
			moved = fmax(moved, fabs(w[a] - pts[k][a]));
			worst = fmax(worst, fabs(w[a] - ref[a]));
			round = fmax(round, fabs(back[a] - pts[k][a]));
		}
	}
	print_message("frames: points moved up to %.2e m; object->world vs reference %.2e m; "
		      "round trip %.2e m\n",
		      moved, worst, round);
	assert_true(moved > 1e-3); /* the test means something: the cube has moved */
	assert_true(worst <= 1e-6);
	assert_true(round <= 1e-15);
	irdm_session_close(ses);
	free(u);
	free(F);
}

static int setup(void **state)
{
	char p[128];
	double id[9];

	(void)state;
	snprintf(dir, sizeof(dir), "/tmp/irdm-float-XXXXXX");
	if (!mkdtemp(dir))
		return -1;
	snprintf(p, sizeof(p), "%s/cube.img", dir);
	efx_image(&cube, p, "mesh", "cube", "resolution", "3,3,3", "floating", "yes",
		  "representation", "modal:all", "precision", "f64", "touch", "surface", NULL);
	mass = cube.rigid->mass_kg;
	memcpy(inertia, cube.rigid->inertia_kg_m2, sizeof(inertia));
	memcpy(com0, cube.rigid->com_m, sizeof(com0));
	/* inverse of the symmetric inertia by Gauss-Jordan */
	double a[9];
	memcpy(a, inertia, sizeof(a));
	for (int i = 0; i < 9; i++)
		id[i] = (i % 4 == 0);
	for (int c = 0; c < 3; c++) {
		double piv = a[4 * c];
		for (int k = 0; k < 3; k++) {
			a[3 * c + k] /= piv;
			id[3 * c + k] /= piv;
		}
		for (int r = 0; r < 3; r++)
			if (r != c) {
				double f = a[3 * r + c];
				for (int k = 0; k < 3; k++) {
					a[3 * r + k] -= f * a[3 * c + k];
					id[3 * r + k] -= f * id[3 * c + k];
				}
			}
	}
	memcpy(inv_inertia, id, sizeof(id));
	return 0;
}

static int teardown(void **state)
{
	char cmd[128];

	(void)state;
	irdm_image_unmap(&cube);
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", dir);
	return system(cmd) ? -1 : 0;
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_swing),
		cmocka_unit_test(test_tap),
		cmocka_unit_test(test_swirl),
		cmocka_unit_test(test_frames),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
