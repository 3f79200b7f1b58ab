/* SPDX-License-Identifier: MIT */
/*
 * Assembly of linear-elastic tetrahedra (constant strain) into K and M over
 * the free DoFs.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fem/csc_build.h"

int irdm_material_check(const struct irdm_material *mat, char *err, size_t errlen)
{
	if (!isfinite(mat->young_pa) || mat->young_pa <= 0.0) {
		snprintf(err, errlen, "material: Young's modulus E must be > 0 Pa (got %g)",
			 mat->young_pa);
		return IRDM_EINVAL;
	}
	if (!isfinite(mat->poisson) || mat->poisson <= -1.0 || mat->poisson >= 0.5) {
		snprintf(err, errlen,
			 "material: Poisson's ratio must be in (-1, 0.5) (got %g); 0.5 is incompressible and has no displacement-only FEM",
			 mat->poisson);
		return IRDM_EINVAL;
	}
	if (!isfinite(mat->density_kg_m3) || mat->density_kg_m3 <= 0.0) {
		snprintf(err, errlen, "material: density must be > 0 kg/m^3 (got %g)",
			 mat->density_kg_m3);
		return IRDM_EINVAL;
	}
	return 0;
}

int irdm_dofmap_init(struct irdm_dofmap *map, size_t n_nodes, const bool *fixed,
		     char *err, size_t errlen)
{
	memset(map, 0, sizeof(*map));
	map->n_dof = 3 * n_nodes;
	map->free_of = malloc(map->n_dof * sizeof(*map->free_of));
	map->global_of = malloc(map->n_dof * sizeof(*map->global_of));
	if (!map->free_of || !map->global_of) {
		irdm_dofmap_free(map);
		snprintf(err, errlen, "dof map: out of memory");
		return IRDM_ENOMEM;
	}
	for (size_t d = 0; d < map->n_dof; d++) {
		if (fixed && fixed[d / 3]) {
			map->free_of[d] = -1;
		} else {
			map->free_of[d] = (int64_t)map->n_free;
			map->global_of[map->n_free++] = (int64_t)d;
		}
	}
	if (map->n_free == 0) {
		irdm_dofmap_free(map);
		snprintf(err, errlen, "constraints: every node is fixed; nothing can move");
		return IRDM_EINVAL;
	}
	return 0;
}

void irdm_dofmap_free(struct irdm_dofmap *map)
{
	free(map->free_of);
	free(map->global_of);
	memset(map, 0, sizeof(*map));
}

/* Isotropic elasticity matrix (Voigt order xx yy zz xy yz zx, engineering
 * shear strain). */
static void elasticity(const struct irdm_material *mat, double d[6][6])
{
	double e = mat->young_pa, nu = mat->poisson;
	double lam = e * nu / ((1 + nu) * (1 - 2 * nu));
	double mu = e / (2 * (1 + nu));

	memset(d, 0, 36 * sizeof(double));
	for (int i = 0; i < 3; i++) {
		for (int j = 0; j < 3; j++)
			d[i][j] = lam;
		d[i][i] = lam + 2 * mu;
		d[i + 3][i + 3] = mu;
	}
}

/*
 * Shape function gradients of a linear tet: grad[a][k] = dN_a/dx_k.
 * Returns the signed volume.
 */
static double tet_gradients(const double *p[4], double grad[4][3])
{
	double e[3][3], inv[3][3];

	for (int i = 0; i < 3; i++)
		for (int k = 0; k < 3; k++)
			e[i][k] = p[i + 1][k] - p[0][k]; /* rows: edge vectors */
	double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) + e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
	/* inv = E^{-1}; dN_{i+1}/dx = column i of E^{-1}... E maps grad to edge
	 * differences: e_i . grad N = delta, so grad N_{i+1} = row i of E^{-T}. */
	inv[0][0] = (e[1][1] * e[2][2] - e[1][2] * e[2][1]) / det;
	inv[0][1] = (e[0][2] * e[2][1] - e[0][1] * e[2][2]) / det;
	inv[0][2] = (e[0][1] * e[1][2] - e[0][2] * e[1][1]) / det;
	inv[1][0] = (e[1][2] * e[2][0] - e[1][0] * e[2][2]) / det;
	inv[1][1] = (e[0][0] * e[2][2] - e[0][2] * e[2][0]) / det;
	inv[1][2] = (e[0][2] * e[1][0] - e[0][0] * e[1][2]) / det;
	inv[2][0] = (e[1][0] * e[2][1] - e[1][1] * e[2][0]) / det;
	inv[2][1] = (e[0][1] * e[2][0] - e[0][0] * e[2][1]) / det;
	inv[2][2] = (e[0][0] * e[1][1] - e[0][1] * e[1][0]) / det;
	for (int a = 0; a < 3; a++)
		for (int k = 0; k < 3; k++)
			grad[a + 1][k] = inv[k][a];
	for (int k = 0; k < 3; k++)
		grad[0][k] = -(grad[1][k] + grad[2][k] + grad[3][k]);
	return det / 6.0;
}

/* Element stiffness Ke (12x12, DoF order node-major) = V B^T D B. */
static double tet_stiffness(const double *p[4], const double d[6][6], double ke[12][12])
{
	double g[4][3], b[6][12] = { { 0 } }, db[6][12];
	double vol = tet_gradients(p, g);

	for (int a = 0; a < 4; a++) {
		double x = g[a][0], y = g[a][1], z = g[a][2];
		int c = 3 * a;
		b[0][c] = x;
		b[1][c + 1] = y;
		b[2][c + 2] = z;
		b[3][c] = y;
		b[3][c + 1] = x;
		b[4][c + 1] = z;
		b[4][c + 2] = y;
		b[5][c] = z;
		b[5][c + 2] = x;
	}
	for (int i = 0; i < 6; i++)
		for (int j = 0; j < 12; j++) {
			double s = 0;
			for (int k = 0; k < 6; k++)
				s += d[i][k] * b[k][j];
			db[i][j] = s;
		}
	for (int i = 0; i < 12; i++)
		for (int j = 0; j < 12; j++) {
			double s = 0;
			for (int k = 0; k < 6; k++)
				s += b[k][i] * db[k][j];
			ke[i][j] = vol * s;
		}
	return vol;
}

static void push(struct irdm_triplet *t, size_t *nt, const struct irdm_dofmap *map,
		 size_t gi, size_t gj, double v)
{
	int64_t i = map->free_of[gi], j = map->free_of[gj];

	if (i < 0 || j < 0 || v == 0.0)
		return;
	t[*nt].row = i;
	t[*nt].col = j;
	t[*nt].val = v;
	(*nt)++;
}

static void add_element(const struct irdm_mesh *mesh, size_t e, const double d[6][6],
			double rho, enum irdm_mass_kind mass, const struct irdm_dofmap *map,
			struct irdm_triplet *tk, size_t *nk, struct irdm_triplet *tm,
			size_t *nm, double *node_mass)
{
	const uint32_t *tet = &mesh->tets[4 * e];
	const double *p[4];
	double ke[12][12];

	for (int a = 0; a < 4; a++)
		p[a] = &mesh->pos_m[3 * tet[a]];
	double vol = tet_stiffness(p, d, ke);
	double me = rho * vol;

	for (int a = 0; a < 4; a++) {
		node_mass[tet[a]] += me / 4.0;
		for (int b = 0; b < 4; b++) {
			for (int i = 0; i < 3; i++) {
				size_t gi = 3 * (size_t)tet[a] + (size_t)i;
				for (int j = 0; j < 3; j++)
					push(tk, nk, map, gi, 3 * (size_t)tet[b] + (size_t)j,
					     ke[3 * a + i][3 * b + j]);
				/* consistent: rho V / 20 (1 + delta_ab) per axis */
				if (mass == IRDM_MASS_CONSISTENT)
					push(tm, nm, map, gi, 3 * (size_t)tet[b] + (size_t)i,
					     me / 20.0 * (a == b ? 2.0 : 1.0));
			}
		}
	}
}

int irdm_fem_assemble(const struct irdm_mesh *mesh, const struct irdm_material *mat,
		      enum irdm_mass_kind mass, const bool *fixed, struct irdm_fem *fem,
		      char *err, size_t errlen)
{
	struct irdm_triplet *tk = NULL, *tm = NULL;
	size_t nk = 0, nm = 0;
	double d[6][6];
	int ret;

	memset(fem, 0, sizeof(*fem));
	fem->mass_kind = mass;
	ret = irdm_material_check(mat, err, errlen);
	if (ret)
		return ret;
	ret = irdm_dofmap_init(&fem->map, mesh->n_nodes, fixed, err, errlen);
	if (ret)
		return ret;
	elasticity(mat, d);
	tk = malloc(mesh->n_tets * 144 * sizeof(*tk));
	tm = malloc((mass == IRDM_MASS_CONSISTENT ? mesh->n_tets * 48 : 0) * sizeof(*tm) + fem->map.n_free * sizeof(*tm));
	fem->lumped_mass_kg = calloc(mesh->n_nodes, sizeof(double));
	if (!tk || !tm || !fem->lumped_mass_kg)
		goto out_nomem;
	for (size_t e = 0; e < mesh->n_tets; e++)
		add_element(mesh, e, d, mat->density_kg_m3, mass, &fem->map, tk, &nk,
			    tm, &nm, fem->lumped_mass_kg);
	if (mass == IRDM_MASS_LUMPED)
		for (size_t f = 0; f < fem->map.n_free; f++) {
			size_t g = (size_t)fem->map.global_of[f];
			tm[nm].row = tm[nm].col = (int64_t)f;
			tm[nm++].val = fem->lumped_mass_kg[g / 3];
		}
	if (irdm_csc_from_triplets(fem->map.n_free, tk, nk, &fem->K) ||
	    irdm_csc_from_triplets(fem->map.n_free, tm, nm, &fem->M))
		goto out_nomem;
	free(tk);
	free(tm);
	return IRDM_OK;

out_nomem:
	free(tk);
	free(tm);
	irdm_fem_free(fem);
	snprintf(err, errlen, "FEM assembly: out of memory (%zu tets)", mesh->n_tets);
	return IRDM_ENOMEM;
}

void irdm_fem_free(struct irdm_fem *fem)
{
	irdm_dofmap_free(&fem->map);
	irdm_csc_free(&fem->K);
	irdm_csc_free(&fem->M);
	free(fem->lumped_mass_kg);
	memset(fem, 0, sizeof(*fem));
}

int irdm_rayleigh_from_ratios(double z1, double w1, double z2, double w2,
			      struct irdm_rayleigh *r, char *err, size_t errlen)
{
	/* z = a/(2w) + b w/2 at two frequencies: a 2x2 linear system. */
	if (!(w1 > 0) || !(w2 > 0) || fabs(w1 - w2) < 1e-9 * (w1 + w2) ||
	    !(z1 >= 0) || !(z2 >= 0) || !isfinite(z1 + z2 + w1 + w2)) {
		snprintf(err, errlen,
			 "damping: need two distinct positive frequencies and ratios >= 0 (got %g@%g rad/s, %g@%g rad/s)",
			 z1, w1, z2, w2);
		return IRDM_EINVAL;
	}
	r->b_s = 2.0 * (z2 * w2 - z1 * w1) / (w2 * w2 - w1 * w1);
	r->a_per_s = 2.0 * z1 * w1 - r->b_s * w1 * w1;
	if (r->a_per_s < 0 || r->b_s < 0) {
		snprintf(err, errlen,
			 "damping: ratios %g@%g rad/s and %g@%g rad/s need a negative Rayleigh coefficient (a=%g, b=%g)",
			 z1, w1, z2, w2, r->a_per_s, r->b_s);
		return IRDM_EINVAL;
	}
	return 0;
}

double irdm_rayleigh_ratio(const struct irdm_rayleigh *r, double w)
{
	return r->a_per_s / (2.0 * w) + r->b_s * w / 2.0;
}

void irdm_mass_properties(const struct irdm_mesh *mesh, const double *m_kg,
			  double *mass_kg, double com[3], double inertia[9])
{
	double m = 0, c[3] = { 0, 0, 0 };

	for (size_t i = 0; i < mesh->n_nodes; i++) {
		m += m_kg[i];
		for (int k = 0; k < 3; k++)
			c[k] += m_kg[i] * mesh->pos_m[3 * i + k];
	}
	for (int k = 0; k < 3; k++)
		com[k] = c[k] / m;
	memset(inertia, 0, 9 * sizeof(double));
	for (size_t i = 0; i < mesh->n_nodes; i++) {
		double r[3], r2 = 0;
		for (int k = 0; k < 3; k++) {
			r[k] = mesh->pos_m[3 * i + k] - com[k];
			r2 += r[k] * r[k];
		}
		for (int a = 0; a < 3; a++)
			for (int b = 0; b < 3; b++)
				inertia[3 * a + b] += m_kg[i] * ((a == b ? r2 : 0) - r[a] * r[b]);
	}
	*mass_kg = m;
}

int irdm_mass_properties_of_matrix(const struct irdm_mesh *mesh, const struct irdm_fem *fem,
				   double *mass_kg, double com_m[3], double inertia_kg_m2[9])
{
	const struct irdm_csc *M = &fem->M;
	const struct irdm_dofmap *map = &fem->map;
	double m = 0, s[3] = { 0, 0, 0 };

	if (map->n_free != 3 * mesh->n_nodes)
		return -1;
	/* x-x entries: free DoF 3 i (node i, axis 0) for every node */
	for (size_t j = 0; j < mesh->n_nodes; j++) {
		int64_t c = map->free_of[3 * j];
		for (int64_t p = M->colptr[c]; p < M->colptr[c + 1]; p++) {
			int64_t g = map->global_of[M->rowind[p]];
			if (g % 3)
				continue;
			m += M->val[p];
			for (int k = 0; k < 3; k++)
				s[k] += M->val[p] * mesh->pos_m[3 * j + k];
		}
	}
	for (int k = 0; k < 3; k++)
		com_m[k] = s[k] / m;
	memset(inertia_kg_m2, 0, 9 * sizeof(double));
	for (size_t j = 0; j < mesh->n_nodes; j++) {
		int64_t c = map->free_of[3 * j];
		double rj[3];

		for (int k = 0; k < 3; k++)
			rj[k] = mesh->pos_m[3 * j + k] - com_m[k];
		for (int64_t p = M->colptr[c]; p < M->colptr[c + 1]; p++) {
			int64_t g = map->global_of[M->rowind[p]];
			double ri[3], dot = 0;
			if (g % 3)
				continue;
			for (int k = 0; k < 3; k++) {
				ri[k] = mesh->pos_m[g + k] - com_m[k];
				dot += ri[k] * rj[k];
			}
			for (int a = 0; a < 3; a++)
				for (int b = 0; b < 3; b++)
					inertia_kg_m2[3 * a + b] += M->val[p] *
								    ((a == b ? dot : 0) - 0.5 * (ri[a] * rj[b] + rj[a] * ri[b]));
		}
	}
	*mass_kg = m;
	return 0;
}
