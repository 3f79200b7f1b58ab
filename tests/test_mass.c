/* SPDX-License-Identifier: MIT */
/*
 * A floating body's mass, centre and inertia come from the mass matrix the
 * model uses (they came from the lumped masses even under a
 * consistent M, and an off-centre push spun the cube too slowly).
 *
 * Reference: a uniform box a x b x c of density rho, m = rho a b c, centre
 * at its middle, I = m/12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2).  A
 * consistent mass matrix of linear tets integrates rho N_i N_j exactly,
 * so its rigid-body inertia is the box's to rounding; lumped masses put
 * the mass on the nodes, which overstates I on coarse meshes (on a flat
 * 6 x 6 x 1 box the thin axis is off by a quarter), and the lumped matrix
 * gives exactly the lumped formula.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "fem/fem.h"
#include "mesh/mesh.h"

static const struct irdm_material mat = { 2e5, 0.3, 1100 };

static void box_reference(double a, double b, double c, double *m, double com[3], double in[9])
{
	*m = mat.density_kg_m3 * a * b * c;
	com[0] = a / 2, com[1] = b / 2, com[2] = c / 2;
	memset(in, 0, 9 * sizeof(double));
	in[0] = *m / 12 * (b * b + c * c);
	in[4] = *m / 12 * (a * a + c * c);
	in[8] = *m / 12 * (a * a + b * b);
}

/* Largest |I - I_ref| over |I_ref|'s largest entry; and the mass, centre. */
static double rel_err(const double *x, const double *ref, int n, double scale)
{
	double e = 0;

	for (int k = 0; k < n; k++)
		e = fmax(e, fabs(x[k] - ref[k]));
	return e / scale;
}

static void check(unsigned nx, unsigned ny, unsigned nz, double a, double b, double c)
{
	struct irdm_mesh mesh;
	struct irdm_fem fem[2];
	double m[2], com[2][3], in[2][9], lm, lcom[3], lin[9], rm, rcom[3], rin[9];
	char err[256];

	assert_int_equal(irdm_mesh_gen_box(a, b, c, nx, ny, nz, 5, &mesh, err, sizeof(err)), 0);
	box_reference(a, b, c, &rm, rcom, rin);
	for (int k = 0; k < 2; k++) {
		assert_int_equal(irdm_fem_assemble(&mesh, &mat, k ? IRDM_MASS_CONSISTENT : IRDM_MASS_LUMPED, NULL, &fem[k],
						   err, sizeof(err)),
				 0);
		assert_int_equal(irdm_mass_properties_of_matrix(&mesh, &fem[k], &m[k], com[k],
								in[k]),
				 0);
	}
	irdm_mass_properties(&mesh, fem[0].lumped_mass_kg, &lm, lcom, lin);
	double e_cons = rel_err(in[1], rin, 9, rin[8]);
	double e_lump = rel_err(in[0], rin, 9, rin[8]);
	print_message("%ux%ux%u box %gx%gx%g m: consistent M: mass %.1e, centre %.1e, inertia %.1e "
		      "off the box; lumped: inertia %.1e off (lumped formula vs lumped M %.1e)\n",
		      nx, ny, nz, a, b, c, fabs(m[1] - rm) / rm,
		      rel_err(com[1], rcom, 3, fmax(a, fmax(b, c))), e_cons, e_lump,
		      rel_err(in[0], lin, 9, lin[8]));
	/* consistent: the continuum's values, to rounding (measured <= 6e-15) */
	assert_true(fabs(m[1] - rm) <= 1e-13 * rm);
	assert_true(rel_err(com[1], rcom, 3, fmax(a, fmax(b, c))) <= 1e-13);
	assert_true(e_cons <= 1e-13);
	/* lumped matrix: exactly the lumped formula (the old path) */
	assert_true(fabs(m[0] - lm) <= 1e-12 * lm && rel_err(in[0], lin, 9, lin[8]) <= 1e-12);
	/* and the lumped inertia is not the box's: the test could tell */
	assert_true(e_lump > 1e-3);
	irdm_fem_free(&fem[0]);
	irdm_fem_free(&fem[1]);
	irdm_mesh_free(&mesh);
}

static void test_box_inertia(void **state)
{
	(void)state;
	check(3, 3, 3, 0.12, 0.12, 0.12); /* the paper's cube */
	check(6, 6, 1, 0.12, 0.12, 0.02); /* flat: lumped worst */
	check(2, 3, 5, 0.05, 0.08, 0.2);  /* no symmetry to hide behind */
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_box_inertia),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
