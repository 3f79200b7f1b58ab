/* SPDX-License-Identifier: MIT */
/*
 * The object a scene describes, built up to its modes: mesh, constraints,
 * FEM matrices, modes, damping, and the scene's rows and columns.
 */
#ifndef IRDM_TOOLS_MODEL_H
#define IRDM_TOOLS_MODEL_H

#include "fem/fem.h"
#include "mesh/mesh.h"
#include "modal/modal.h"
#include "scene/scene.h"

struct irdm_model {
	struct irdm_mesh mesh;
	bool *fixed;      /* per mesh node */
	bool *on_surface; /* per mesh node */
	struct irdm_fem fem;
	struct irdm_modes modes;
	struct irdm_rayleigh damping;
	/* selection */
	size_t n_rows;
	uint32_t *rows; /* mesh node of each image node, ascending */
	size_t n_cols;
	uint32_t *cols;    /* image node index of each column */
	int64_t *row_dofs; /* 3 * n_rows free DoF or -1 */
	int64_t *col_dofs; /* 3 * n_cols */
	size_t n_tris;
	uint32_t *tris; /* 3 * n_tris, image node indices */
	double seconds_mesh, seconds_fem, seconds_eig;
	/* representation = auto: every mode did not fit, the modes are the
	 * lowest of a Lanczos solve (precompute/lowest.h) */
	bool lowest_only;
};

/* The lowest modes auto solves first when every mode does not fit. */
#define IRDM_LOWEST_FIRST 16

/* Builtin or file mesh of the scene (validated, boundary computed); note:
 * what the sizing of a surface did, "" if nothing. */
int irdm_model_mesh(const struct irdm_scene *sc, struct irdm_mesh *mesh, char note[256],
		    char *err, size_t errlen);

/* Everything up to modes and selection.  n_modes_needed: modes to solve
 * (0: all; when they do not fit in memory and the scene is representation
 * = auto with max_error and eigensolver = auto in one process, the lowest
 * IRDM_LOWEST_FIRST from a Lanczos solve, m->lowest_only set).  Return: IRDM_OK; IRDM_EINVAL (scene, constraints, damping);
 * IRDM_ENOMEM; IRDM_EIO, IRDM_EFORMAT, IRDM_ECHILD (mesh file, as
 * irdm_mesh_read()); IRDM_ENUMERIC (factorisation, eigensolver). */
int irdm_model_build(const struct irdm_scene *sc, size_t n_modes_needed,
		     irdm_progress_fn progress, void *ctx, struct irdm_model *m,
		     char *err, size_t errlen);
void irdm_model_free(struct irdm_model *m);

/* m's modes solved again: the lowest n, by Lanczos, and the damping picked
 * from them.  Return: as irdm_model_build()'s eigensolve. */
int irdm_model_solve_lowest(const struct irdm_scene *sc, size_t n, irdm_progress_fn progress,
			    void *ctx, struct irdm_model *m, char *err, size_t errlen);

/* The scene's rows, columns and surface (select.c; part of irdm_model_build). */
int irdm_model_select(const struct irdm_scene *sc, struct irdm_model *m, char *err, size_t errlen);

#endif
