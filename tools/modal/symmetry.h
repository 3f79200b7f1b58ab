/* SPDX-License-Identifier: MIT */
/*
 * A model's mirror and half-turn symmetries, and the basis that splits its
 * eigenproblem by them.
 *
 * A symmetry here is an orthogonal map Q of the cube's group (axes
 * permuted and reversed, about the centre of the nodes' bounding box)
 * with Q^2 = I that maps every node onto a node (to 1e-9 of the box),
 * fixed DoFs onto fixed DoFs, and K and M onto themselves (to rounding):
 * on the free DoFs it is a permutation with signs.  Up to three that
 * commute generate a group G of 2^g elements, each +-1 on every mode
 * (its character).  A mode of one character has no component along a
 * mode of another, so the n x n eigenproblem splits exactly into 2^g
 * independent ones of about n / 2^g each (a dense solve is O(n^3): the
 * paper's cuboid, with a half-turn and two diagonal mirrors, costs about
 * 1/16).
 *
 * The basis of character c: for each orbit of G on the DoFs, the
 * projection sum_q c(q) q e_d of one of its DoFs d, normalised, when it is
 * not zero; every DoF lies in exactly one orbit, so every DoF has at most
 * one basis vector per character, and the characters' bases together are
 * an orthonormal basis of all the DoFs.
 */
#ifndef IRDM_MODAL_SYMMETRY_H
#define IRDM_MODAL_SYMMETRY_H

#include <stddef.h>
#include <stdint.h>

#include "fem/fem.h"

#define IRDM_SYM_MAX_GENS 3

struct irdm_sym {
	size_t n;                             /* free DoFs */
	unsigned n_gens;                      /* 0: no symmetry found */
	int64_t *to[IRDM_SYM_MAX_GENS];       /* free DoF d -> its image under generator g */
	signed char *sign[IRDM_SYM_MAX_GENS]; /* and the sign it picks up */
	char what[128];                       /* the generators, readable: "x -> -x, y -> -y" */
	double mismatch;                      /* largest |K - Q K Q^T| relative to sqrt(K_ii K_jj) */
};

/* One character's basis: vector q has entries val[start[q] .. start[q+1])
 * at free DoFs dof[...]; local[d] is the vector at DoF d (-1: none),
 * at_val[d] its entry there. */
struct irdm_sym_class {
	size_t n;
	size_t *start;
	int64_t *dof;
	double *val;
	int64_t *local;
	double *at_val;
};

/*
 * The symmetries of the model: nodes pos_m (n_nodes x 3, the mesh's),
 * fem's DoF map, K and M (lumped or not).  No symmetry is not an error:
 * s->n_gens = 0.  Return: IRDM_OK; IRDM_ENOMEM.
 */
int irdm_sym_find(const double *pos_m, size_t n_nodes, const struct irdm_fem *fem,
		  struct irdm_sym *s, char *err, size_t errlen);
void irdm_sym_free(struct irdm_sym *s);

/* The 2^n_gens characters' bases into cls[].  IRDM_OK; IRDM_ENOMEM. */
int irdm_sym_classes(const struct irdm_sym *s, struct irdm_sym_class *cls);
void irdm_sym_class_free(struct irdm_sym_class *c);

/*
 * a (c->n x c->n, column-major, both triangles) = B^T D^-1/2 K D^-1/2 B,
 * B the class's basis, D the lumped mass (dsqrt its square root).
 */
void irdm_sym_block(const struct irdm_sym_class *c, const struct irdm_csc *K,
		    const double *dsqrt, double *a);

#endif
