/* SPDX-License-Identifier: MIT */
/*
 * Linear-elastic FEM on 4-node tetrahedra: material, constraints, sparse
 * assembly of the stiffness and mass matrices over the free DoFs, Rayleigh
 * damping.  Offline only (double precision, allocates).
 *
 * DoF numbering: global DoF = 3 * node + axis.  The assembled matrices are
 * over the free DoFs only; struct irdm_dofmap translates.
 */
#ifndef IRDM_TOOLS_FEM_H
#define IRDM_TOOLS_FEM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/error.h"
#include "mesh/mesh.h"

struct irdm_material {
	double young_pa;
	double poisson;
	double density_kg_m3;
};

/* Symmetric sparse matrix, compressed sparse column, BOTH triangles stored,
 * row indices sorted within each column. */
struct irdm_csc {
	size_t n;
	size_t nnz;
	int64_t *colptr; /* n + 1 */
	int64_t *rowind; /* nnz */
	double *val;     /* nnz */
};

struct irdm_dofmap {
	size_t n_dof;       /* 3 * mesh nodes */
	size_t n_free;      /* free DoFs */
	int64_t *free_of;   /* n_dof: free index or -1 if fixed */
	int64_t *global_of; /* n_free: global DoF */
};

enum irdm_mass_kind { IRDM_MASS_LUMPED = 0,
		      IRDM_MASS_CONSISTENT = 1 };

struct irdm_fem {
	struct irdm_dofmap map;
	struct irdm_csc K;      /* stiffness over free DoFs, N/m */
	struct irdm_csc M;      /* mass over free DoFs, kg */
	double *lumped_mass_kg; /* per mesh node (always computed; for rigid fits) */
	enum irdm_mass_kind mass_kind;
};

/* Check E > 0, -1 < nu < 0.5, rho > 0, all finite.  -1 and a message. */
int irdm_material_check(const struct irdm_material *mat, char *err, size_t errlen);

/* fixed: per mesh node, true if all three DoFs are fixed (NULL: none). */
int irdm_dofmap_init(struct irdm_dofmap *map, size_t n_nodes, const bool *fixed,
		     char *err, size_t errlen);
void irdm_dofmap_free(struct irdm_dofmap *map);

int irdm_fem_assemble(const struct irdm_mesh *mesh, const struct irdm_material *mat,
		      enum irdm_mass_kind mass, const bool *fixed, struct irdm_fem *fem,
		      char *err, size_t errlen);
void irdm_fem_free(struct irdm_fem *fem);

void irdm_csc_free(struct irdm_csc *a);
/* y = A x */
void irdm_csc_matvec(const struct irdm_csc *a, const double *x, double *y);
/* Dense copy, column-major n x n (caller frees). NULL on allocation failure. */
double *irdm_csc_to_dense(const struct irdm_csc *a);

/* Rayleigh damping C = a M + b K. */
struct irdm_rayleigh {
	double a_per_s;
	double b_s;
};
/* a, b giving damping ratio z1 at w1 and z2 at w2 (rad/s, w1 != w2). */
int irdm_rayleigh_from_ratios(double z1, double w1_rad_s, double z2, double w2_rad_s,
			      struct irdm_rayleigh *r, char *err, size_t errlen);
/* Damping ratio of a mode at w (rad/s > 0). */
double irdm_rayleigh_ratio(const struct irdm_rayleigh *r, double w_rad_s);

/* Mass properties from the lumped node masses. */
void irdm_mass_properties(const struct irdm_mesh *mesh, const double *node_mass_kg,
			  double *mass_kg, double com_m[3], double inertia_kg_m2[9]);

/*
 * Mass properties of the mass matrix the model uses (fem->M, lumped or
 * consistent; every node free: a floating object): with m_ij its x-x
 * entry between nodes i and j (M is isotropic per node pair),
 *   m = sum m_ij,  m c = sum m_ij x_j,  I = sum m_ij ((r_i . r_j) 1 - r_i r_j^T)
 * (r = x - c, symmetrised), the rigid body's kinetic energy under the
 * same M the modes are separated with; for a consistent M of linear tets
 * the continuum's exact values.  Return: 0; -1 if a node is fixed.
 */
int irdm_mass_properties_of_matrix(const struct irdm_mesh *mesh, const struct irdm_fem *fem,
				   double *mass_kg, double com_m[3], double inertia_kg_m2[9]);

#endif /* IRDM_TOOLS_FEM_H */
