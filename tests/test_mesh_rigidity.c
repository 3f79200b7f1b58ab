/* SPDX-License-Identifier: MIT */
/*
 * Rigid modes on any mesh: which modes are rigid is decided by
 * the mesh's connectivity and geometry (irdm_mesh_check_rigidity()), not by
 * an eigenvalue threshold scaled by the stiffest element.
 *
 *  - A graded tetgen mesh (a 10 cm cube whose top face has a vertex 1 um
 *    from a corner: tetgen grades from micrometre to centimetre elements)
 *    is grounded at its base: no false rigid mode, and its 10x scaled copy
 *    has the same spectrum scaled by 1/100 in omega^2 (K ~ E L, M ~ rho
 *    L^3), to rounding (the eigensolver chosen for such a mesh must be
 *    Lanczos: a dense solve misses by 1e-6).  The precondition is checked: its softest mode lies
 *    below 1e-9 max(K_ii / M_ii), where the old threshold called it rigid.
 *  - Floating, the same mesh has exactly 6 rigid modes, and they span the
 *    analytic translations and rotations.
 *  - Loose parts, on small hand-made meshes: what the check must refuse
 *    (nothing fixed; two or three collinear fixed nodes; a tet hinged on an
 *    edge; two bodies declared one floating object) and accept (a face
 *    shared; three non-collinear fixed nodes).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "fem/fem.h"
#include "mesh/mesh.h"
#include "modal/modal.h"
#include "support/model_fixture.h"
#include "support/test_files.h"

static char dir[256], off_path[320];
/* AUTO: on this graded mesh it must choose Lanczos (a dense solve
 * resolves its low modes to 1e-6 only, measured) */
static enum irdm_eig_method EIG = IRDM_EIG_AUTO;
static const struct irdm_material steel_like = { 2e5, 0.3, 1000 };

/* The 10 cm cube with a vertex 1 um from a top corner, fanned to the top. */
static void write_graded_off(const char *path)
{
	static const char text[] =
		"OFF\n9 14 0\n0 0 0\n0.1 0 0\n0.1 0.1 0\n0 0.1 0\n0 0 0.1\n0.1 0 0.1\n"
		"0.1 0.1 0.1\n0 0.1 0.1\n1e-06 1e-06 0.1\n"
		"3 0 2 1\n3 0 3 2\n3 0 1 5\n3 0 5 4\n3 1 2 6\n3 1 6 5\n3 2 3 7\n3 2 7 6\n"
		"3 3 0 4\n3 3 4 7\n3 4 5 8\n3 5 6 8\n3 6 7 8\n3 7 4 8\n";

	tf_write_text(path, text);
}

static double max_k_over_m(const struct irdm_fem *fem)
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

struct solved {
	struct irdm_mesh mesh;
	struct irdm_fem fem;
	struct irdm_modes modes;
	bool *fixed;
};

/* The graded mesh at scale, grounded at its base or floating, n modes. */
static void solve(struct solved *s, double scale, bool floating, size_t n)
{
	char err[512];

	memset(s, 0, sizeof(*s));
	assert_int_equal(irdm_mesh_read(off_path, scale, NULL, &s->mesh, err, sizeof(err)), 0);
	s->fixed = calloc(s->mesh.n_nodes, sizeof(bool));
	assert_non_null(s->fixed);
	for (size_t i = 0; !floating && i < s->mesh.n_nodes; i++)
		s->fixed[i] = s->mesh.pos_m[3 * i + 2] <= 1e-12 * scale;
	if (irdm_mesh_check_rigidity(&s->mesh, s->fixed, floating, err, sizeof(err)))
		fail_msg("%s", err);
	assert_int_equal(irdm_fem_assemble(&s->mesh, &steel_like, IRDM_MASS_LUMPED,
					   floating ? NULL : s->fixed, &s->fem, err, sizeof(err)),
			 0);
	if (irdm_modes_solve(&s->fem, n, floating, EIG, NULL, NULL, &s->modes, err,
			     sizeof(err)))
		fail_msg("%s", err);
}

static void solved_free(struct solved *s)
{
	irdm_modes_free(&s->modes);
	irdm_fem_free(&s->fem);
	irdm_mesh_free(&s->mesh);
	free(s->fixed);
}

static void test_graded_mesh_and_its_scaled_copy(void **state)
{
	struct solved a, b;
	double worst = 0, vmin = INFINITY, vmax = 0;

	(void)state;
	solve(&a, 1.0, false, 10);
	solve(&b, 10.0, false, 10);
	for (size_t t = 0; t < a.mesh.n_tets; t++) {
		const uint32_t *v = &a.mesh.tets[4 * t];
		double e[3][3], vol;
		for (int k = 0; k < 3; k++)
			for (int i = 0; i < 3; i++)
				e[k][i] = a.mesh.pos_m[3 * v[k + 1] + i] - a.mesh.pos_m[3 * v[0] + i];
		vol = fabs(e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
			   e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
			   e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) /
		      6;
		vmin = fmin(vmin, vol);
		vmax = fmax(vmax, vol);
	}
	print_message("graded mesh: %zu nodes, %zu tets, volumes %.2e..%.2e m^3; softest mode "
		      "omega^2 %.4g = %.1e of max K_ii/M_ii\n",
		      a.mesh.n_nodes, a.mesh.n_tets, vmin,
		      vmax, a.modes.omega2[0], a.modes.omega2[0] / max_k_over_m(&a.fem));
	/* the case the old rule (rigid below 1e-9 max K_ii/M_ii) got wrong */
	assert_true(a.modes.omega2[0] < 1e-9 * max_k_over_m(&a.fem));
	assert_int_equal(a.modes.n_rigid, 0);
	assert_int_equal(b.modes.n_rigid, 0);
	assert_int_equal(a.modes.n_modes, b.modes.n_modes);
	for (size_t k = 0; k < a.modes.n_modes; k++)
		worst = fmax(worst, fabs(b.modes.omega2[k] * 100 - a.modes.omega2[k]) /
					    a.modes.omega2[k]);
	print_message("10x copy: omega^2 x 100 vs the original, worst of %zu modes %.1e\n",
		      a.modes.n_modes, worst);
	/* measured 5.8e-15 (rounding); 1.4e-6 with a dense solve */
	assert_true(worst <= 1e-13);
	solved_free(&a);
	solved_free(&b);
}

/* The six lowest modes of the floating graded mesh span the rigid fields. */
static void test_graded_floating_has_six_rigid_modes(void **state)
{
	struct solved s;
	double worst = 0;

	(void)state;
	solve(&s, 1.0, true, 10);
	assert_int_equal(s.modes.n_rigid, 6);
	worst = fixture_rigid_outside(&s.mesh, &s.fem, &s.modes, (const double[3]){ 0.05, 0.05, 0.05 });
	print_message("floating graded mesh: 6 rigid modes, first elastic %.4f Hz; rigid fields "
		      "outside their span: %.1e\n",
		      sqrt(s.modes.omega2[0]) / (2 * M_PI), worst);
	assert_true(worst <= 1e-8);
	solved_free(&s);
}

/* ---- loose parts ---- */

/* Tets over the points given; tets 4 at a time. */
static void small_mesh(struct irdm_mesh *m, const double *pos, size_t n_nodes,
		       const uint32_t *tets, size_t n_tets)
{
	memset(m, 0, sizeof(*m));
	m->n_nodes = n_nodes;
	m->pos_m = (double *)pos;
	m->n_tets = n_tets;
	m->tets = (uint32_t *)tets;
}

static void expect(const struct irdm_mesh *m, const bool *fixed, bool floating, const char *want)
{
	char err[512] = "";
	int rc = irdm_mesh_check_rigidity(m, fixed, floating, err, sizeof(err));

	if (!want) {
		if (rc)
			fail_msg("refused: %s", err);
		return;
	}
	if (!rc)
		fail_msg("accepted, expected '%s'", want);
	if (!strstr(err, want))
		fail_msg("'%s' does not say '%s'", err, want);
}

static void test_loose_parts(void **state)
{
	/* tet A (0,1,2,3); B shares A's face (1,2,3) with apex 4; C shares
	 * only A's edge (0,1) with nodes 5, 6 */
	static const double pos[] = {
		0,
		0,
		0,
		1,
		0,
		0,
		0,
		1,
		0,
		0,
		0,
		1,
		1,
		1,
		1,
		0.5,
		-1,
		0.2,
		0.6,
		-0.8,
		1,
	};
	static const uint32_t face_pair[] = { 0, 1, 2, 3, 1, 2, 3, 4 };
	static const uint32_t edge_pair[] = { 0, 1, 2, 3, 0, 1, 5, 6 };
	bool three[7] = { true, true, true }, two[7] = { true, true }, none[7] = { false };
	struct irdm_mesh m, box, two_boxes;
	char err[256];

	(void)state;
	small_mesh(&m, pos, 7, face_pair, 2);
	expect(&m, three, false, NULL);                       /* B held by the face */
	expect(&m, two, false, "can move without straining"); /* turns about 0-1 */
	expect(&m, none, false, "2 tet(s) around node 0");
	expect(&m, NULL, true, NULL); /* one rigid body */
	small_mesh(&m, pos, 7, edge_pair, 2);
	expect(&m, three, false, "1 tet(s) around node 0 (0, 0, 0)"); /* C: hinged on 0-1 */
	expect(&m, NULL, true, "must move as one body");

	/* a box of 2 x 1 x 1 hexes: nodes (0,0,0), (0.5,0,0), (1,0,0) are collinear */
	assert_int_equal(irdm_mesh_gen_box(1, 0.5, 0.5, 2, 1, 1, 5, &box, err, sizeof(err)), 0);
	{
		bool *fixed = calloc(box.n_nodes, sizeof(bool));
		assert_non_null(fixed);
		for (size_t i = 0; i < box.n_nodes; i++)
			fixed[i] = box.pos_m[3 * i + 1] == 0 && box.pos_m[3 * i + 2] == 0;
		expect(&box, fixed, false, "can move without straining");
		for (size_t i = 0; i < box.n_nodes; i++)
			fixed[i] = box.pos_m[3 * i + 2] == 0; /* the base: a plane */
		expect(&box, fixed, false, NULL);
		free(fixed);
	}
	expect(&box, NULL, true, NULL);
	/* two disjoint boxes declared one floating object */
	{
		size_t n = box.n_nodes, t = box.n_tets;
		double *p2 = malloc(2 * 3 * n * sizeof(double));
		uint32_t *t2 = malloc(2 * 4 * t * sizeof(uint32_t));
		assert_true(p2 && t2);
		for (size_t i = 0; i < 3 * n; i++) {
			p2[i] = box.pos_m[i];
			p2[3 * n + i] = box.pos_m[i] + (i % 3 == 0 ? 2.0 : 0.0);
		}
		for (size_t i = 0; i < 4 * t; i++) {
			t2[i] = box.tets[i];
			t2[4 * t + i] = box.tets[i] + (uint32_t)n;
		}
		small_mesh(&two_boxes, p2, 2 * n, t2, 2 * t);
		expect(&two_boxes, NULL, true, "must move as one body");
		free(p2);
		free(t2);
	}
	irdm_mesh_free(&box);
}

static int setup(void **state)
{
	(void)state;
	if (tf_tmpdir(dir, sizeof(dir), "rigidity"))
		return -1;
	snprintf(off_path, sizeof(off_path), "%s/graded.off", dir);
	write_graded_off(off_path);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_graded_mesh_and_its_scaled_copy),
		cmocka_unit_test(test_graded_floating_has_six_rigid_modes),
		cmocka_unit_test(test_loose_parts),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
