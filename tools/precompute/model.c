/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dist/dist.h"
#include "modal/symmetry.h"
#include "precompute/model.h"
#include "util/clock.h"
#include "util/memory.h"

/*
 * A mesh file; a surface is sized (target_nodes, max_tet_volume) unless the
 * scene gives tetgen switches, which win: then a note says the size keys
 * were overridden.
 */
static int read_file_mesh(const struct irdm_scene *sc, struct irdm_mesh *mesh, char note[256],
			  char *err, size_t errlen)
{
	struct irdm_mesh_sizing sz = { NULL, 0, 0, "" };
	bool sized = sc->target_nodes || sc->max_tet_volume_m3 > 0;

	if (sc->tetgen_given) {
		sz.switches = sc->tetgen;
	} else {
		sz.target_nodes = irdm_scene_target_nodes(sc);
		sz.max_tet_volume = sc->max_tet_volume_m3;
	}
	int ret = irdm_mesh_read_sized(sc->mesh, sc->mesh_scale, &sz, mesh, err, errlen);
	if (!ret && sc->tetgen_given && sized)
		snprintf(sz.note, sizeof(sz.note),
			 "mesh sizing: note: tetgen = %s given, it overrides target_nodes and "
			 "max_tet_volume",
			 sc->tetgen);
	memcpy(note, sz.note, sizeof(sz.note));
	return ret;
}

int irdm_model_mesh(const struct irdm_scene *sc, struct irdm_mesh *mesh, char note[256],
		    char *err, size_t errlen)
{
	unsigned r[3] = { sc->res[0], sc->res[1], sc->res[2] };
	double l[3];
	int ret;

	note[0] = '\0';
	if (irdm_dist_fault("mesh")) { /* the failure tests: one rank cannot read it */
		snprintf(err, errlen, "%s: cannot read the mesh (IRDM_TEST_FAULT)", sc->mesh);
		return IRDM_EIO;
	}
	if (!strcmp(sc->mesh, "cuboid")) {
		/* the paper's cuboid: 10 x 10 x 20 cm, 11 x 11 x 22 hexes of 5 tets */
		l[0] = l[1] = 0.1;
		l[2] = 0.2;
		if (!r[0])
			r[0] = 11, r[1] = 11, r[2] = 22;
	} else if (!strcmp(sc->mesh, "cube")) {
		l[0] = l[1] = l[2] = 0.12; /* the paper's 12 cm cube */
		if (!r[0])
			r[0] = r[1] = r[2] = 10;
	} else if (!strncmp(sc->mesh, "box:", 4)) {
		if (sscanf(sc->mesh + 4, "%lf,%lf,%lf", &l[0], &l[1], &l[2]) != 3 ||
		    !(l[0] > 0 && l[1] > 0 && l[2] > 0 && isfinite(l[0] + l[1] + l[2]))) {
			snprintf(err, errlen, "scene: mesh '%s': expected box:LX,LY,LZ in metres", sc->mesh);
			return IRDM_EINVAL;
		}
		if (!r[0])
			r[0] = r[1] = r[2] = 4;
	} else {
		return read_file_mesh(sc, mesh, note, err, errlen);
	}
	ret = irdm_mesh_gen_box(l[0], l[1], l[2], r[0], r[1], r[2], sc->tets_per_hex, mesh,
				err, errlen);
	if (!ret)
		snprintf(mesh->name, sizeof(mesh->name), "%.8s-%ux%ux%u-%ut",
			 sc->mesh[0] == 'b' ? "box" : sc->mesh, r[0], r[1], r[2], sc->tets_per_hex);
	return ret;
}

static int mark_nodes(const struct irdm_scene *sc, struct irdm_model *m, char *err, size_t errlen)
{
	size_t n = m->mesh.n_nodes, n_fixed = 0;

	m->fixed = calloc(n, sizeof(bool));
	m->on_surface = calloc(n, sizeof(bool));
	if (!m->fixed || !m->on_surface) {
		snprintf(err, errlen, "model: out of memory");
		return IRDM_ENOMEM;
	}
	for (size_t t = 0; t < 3 * m->mesh.n_tris; t++)
		m->on_surface[m->mesh.tris[t]] = true;
	for (size_t i = 0; i < n; i++) {
		m->fixed[i] = irdm_region_contains(&sc->fixed, (uint32_t)i, &m->mesh.pos_m[3 * i],
						   m->on_surface[i]);
		n_fixed += m->fixed[i];
	}
	if (sc->fixed.kind == IRDM_REGION_NODES)
		for (size_t k = 0; k < sc->fixed.n_nodes; k++)
			if (sc->fixed.nodes[k] >= n) {
				snprintf(err, errlen, "scene: fixed node %u does not exist (mesh has %zu nodes)",
					 sc->fixed.nodes[k], n);
				return IRDM_EINVAL;
			}
	if (!sc->floating && n_fixed == 0) {
		snprintf(err, errlen,
			 "scene: grounded object but 'fixed = %s' selects no node of mesh '%s'",
			 sc->fixed.text, m->mesh.name);
		return IRDM_EINVAL;
	}
	return 0;
}

static int pick_damping(const struct irdm_scene *sc, struct irdm_model *m, char *err, size_t errlen)
{
	if (sc->damping == IRDM_DAMP_RAYLEIGH) {
		m->damping = sc->rayleigh;
		return 0;
	}
	double w1 = sc->damp_hz[0] > 0 ? 2 * M_PI * sc->damp_hz[0] : sqrt(m->modes.omega2[0]);
	return irdm_rayleigh_from_ratios(sc->damp_ratio[0], w1, sc->damp_ratio[1],
					 2 * M_PI * sc->damp_hz[1], &m->damping, err, errlen);
}

/* The mesh's statistics and warnings, before the eigensolve spends on it. */
static void say_stats(const struct irdm_mesh *mesh, irdm_progress_fn progress, void *ctx)
{
	struct irdm_mesh_stats st;
	char lines[3][256];
	int n;

	if (!progress)
		return;
	irdm_mesh_stats(mesh, &st);
	n = irdm_mesh_stats_text(mesh, &st, lines);
	for (int i = 0; i < n; i++)
		progress(ctx, lines[i], -1.0);
}

/*
 * Where every mode is read: the columns (an auto hybrid's prediction, head
 * and static correction) and each vertex of a triangle that has a
 * touchable one (the rows of the error measurement's exact model, whose
 * columns are some of these columns).  Other rows: only of the modes an
 * image keeps, made whole on demand (irdm_modes_complete).
 */
static void every_mode_at(const struct irdm_model *m, bool *every)
{
	bool *is_col = calloc(m->n_rows ? m->n_rows : 1, sizeof(bool));

	for (size_t c = 0; c < 3 * m->n_cols; c++)
		if (m->col_dofs[c] >= 0)
			every[m->col_dofs[c]] = true;
	if (!is_col) /* only slower: every row's whole */
		return;
	for (size_t c = 0; c < m->n_cols; c++)
		is_col[m->cols[c]] = true;
	for (size_t t = 0; t < m->n_tris; t++) {
		const uint32_t *v = &m->tris[3 * t];

		if (!is_col[v[0]] && !is_col[v[1]] && !is_col[v[2]])
			continue;
		for (int k = 0; k < 3; k++)
			for (int a = 0; a < 3; a++)
				if (m->row_dofs[3 * (size_t)v[k] + (size_t)a] >= 0)
					every[m->row_dofs[3 * (size_t)v[k] + (size_t)a]] = true;
	}
	free(is_col);
}

/*
 * What the image reads of the modes: the free DoFs of the scene's rows and
 * columns (shapes, static correction, FIR from modes), the static
 * correction's unit loads, in its order (tools/modal/static.c), and
 * where every mode is read (every_mode_at).
 */
static int wanted_of_modes(const struct irdm_scene *sc, const struct irdm_model *m,
			   struct irdm_modes_want *w)
{
	bool *keep = calloc(m->fem.map.n_free ? m->fem.map.n_free : 1, sizeof(bool));
	bool *every = calloc(m->fem.map.n_free ? m->fem.map.n_free : 1, sizeof(bool));
	int64_t *loads = malloc((3 * m->n_cols + 1) * sizeof(int64_t));
	size_t n_loads = 0;

	if (!keep || !every || !loads) {
		free(keep);
		free(every);
		free(loads);
		return IRDM_ENOMEM;
	}
	for (size_t r = 0; r < 3 * m->n_rows; r++)
		if (m->row_dofs[r] >= 0)
			keep[m->row_dofs[r]] = true;
	for (size_t c = 0; c < 3 * m->n_cols; c++)
		if (m->col_dofs[c] >= 0) {
			keep[m->col_dofs[c]] = true;
			loads[n_loads++] = m->col_dofs[c];
		}
	every_mode_at(m, every);
	*w = (struct irdm_modes_want){ keep, loads, n_loads, every, NULL };
	if (!sc->static_correction || sc->method == IRDM_METHOD_TIME_DOMAIN)
		w->n_loads = 0;
	return IRDM_OK;
}

/*
 * The model's symmetries, which split a dense all-modes solve into
 * independent blocks (modal/symmetry.h), and a line saying so.  Only a
 * saving: without the memory to look, the solve is whole.
 */
static void find_symmetry(const struct irdm_model *m, struct irdm_sym *sym,
			  irdm_progress_fn progress, void *ctx)
{
	char line[256], err[128];

	if (irdm_sym_find(m->mesh.pos_m, m->mesh.n_nodes, &m->fem, sym, err, sizeof(err)))
		return; /* irdm_sym_find() left no generator */
	if (!sym->n_gens || !progress)
		return;
	snprintf(line, sizeof(line), "symmetry: %s (to %.1e): a dense solve splits into %u blocks",
		 sym->what, sym->mismatch, 1u << sym->n_gens);
	progress(ctx, line, -1.0);
}

/* Why every mode was wanted, and what wants fewer, after err. */
static void say_all_modes(const struct irdm_scene *sc, char *err, size_t errlen)
{
	size_t len = strlen(err);

	if (sc->repr_auto && sc->max_error > 0)
		snprintf(err + len, errlen - len, "; representation = auto chooses from the lowest modes of a Lanczos solve instead on a grounded object with lumped mass, contacts = 1, eigensolver = auto, error_columns not every and no static_correction_cluster, in one process; or a coarser mesh");
	else if (sc->exact_head)
		snprintf(err + len, errlen - len, "; exact_head from every mode needs them all: eigensolver = lanczos needs K (a Lanczos solve) and builds the head from Chebyshev series in the stiffness");
	else
		snprintf(err + len, errlen - len, "; every mode was asked for: modal:K needs K (a Lanczos solve)");
}

/*
 * Solve the model's modes (n: how many, the lowest; 0: every one) with
 * method, and pick the damping from them.  Every mode's solve may split
 * by the mesh's symmetries (only the lumped-mass dense one does).
 */
static int solve_modes(const struct irdm_scene *sc, struct irdm_model *m, size_t n,
		       enum irdm_eig_method method, irdm_progress_fn progress, void *ctx,
		       char *err, size_t errlen)
{
	double t0 = irdm_now_s();
	struct irdm_modes_want want;
	/* only a slepc run has ranks (irdm_dist_begin started them) */
	struct irdm_eig_dist dist = { .rank = 0, .solve = irdm_eig_slepc };
	struct irdm_sym sym = { 0 };
	int ret;

	ret = wanted_of_modes(sc, m, &want);
	if (ret) {
		snprintf(err, errlen, "model: out of memory");
		return ret;
	}
	if (method == IRDM_EIG_SLEPC)
		dist.rank = irdm_dist_rank();
	if (n == 0 && method != IRDM_EIG_SLEPC && sc->mass == IRDM_MASS_LUMPED && sc->symmetry)
		find_symmetry(m, &sym, progress, ctx);
	want.sym = &sym;
	irdm_memory_cap(sc->max_memory_mib * (1 << 20)); /* the scene's, for this solve only */
	ret = irdm_modes_solve_kept(&m->fem, n, sc->floating, method, &dist, &want, progress, ctx,
				    &m->modes, err, errlen);
	irdm_memory_cap(0);
	irdm_sym_free(&sym);
	free((void *)want.keep);
	free((void *)want.every);
	free((void *)want.load_dofs);
	if (ret)
		return ret;
	m->seconds_eig += irdm_now_s() - t0;
	return pick_damping(sc, m, err, errlen);
}

/*
 * representation = auto with max_error wants every mode, to choose and to
 * measure; when they do not fit in memory it chooses from the lowest
 * modes of a Lanczos solve instead (precompute/lowest.h), beginning with
 * IRDM_LOWEST_FIRST of them, where the head from Chebyshev series can be
 * built (modal/krylov_head.h: grounded, lumped mass, its blocks not
 * clustered) and measured (one contact at a sample of nodes: two at once
 * and every node are measured on every mode only).
 */
static bool lowest_instead(const struct irdm_scene *sc, size_t n_modes_needed, int ret)
{
	return ret == IRDM_ENOMEM && n_modes_needed == 0 && sc->repr_auto && sc->max_error > 0 &&
	       sc->eigensolver == IRDM_EIG_AUTO && irdm_dist_size() == 1 &&
	       sc->mass == IRDM_MASS_LUMPED && !sc->floating && sc->contacts == 1 &&
	       !sc->static_corr_cluster && sc->error_columns != IRDM_ERROR_COLUMNS_EVERY;
}

int irdm_model_build(const struct irdm_scene *sc, size_t n_modes_needed,
		     irdm_progress_fn progress, void *ctx, struct irdm_model *m,
		     char *err, size_t errlen)
{
	double t0 = irdm_now_s();
	int ret;

	memset(m, 0, sizeof(*m));
	ret = irdm_scene_check(sc, err, errlen);
	if (ret)
		return ret;
	if (progress)
		progress(ctx, "mesh", 0.0);
	char note[256] = "";
	ret = irdm_model_mesh(sc, &m->mesh, note, err, errlen);
	if (ret)
		goto out_fail;
	if (progress)
		progress(ctx, "mesh", 1.0);
	if (progress && note[0])
		progress(ctx, note, -1.0);
	ret = mark_nodes(sc, m, err, errlen);
	if (ret)
		goto out_fail;
	ret = irdm_mesh_check_rigidity(&m->mesh, m->fixed, sc->floating, err, errlen) ? IRDM_EINVAL : IRDM_OK;
	if (ret)
		goto out_fail;
	say_stats(&m->mesh, progress, ctx);
	m->seconds_mesh = irdm_now_s() - t0;
	t0 = irdm_now_s();
	if (progress)
		progress(ctx, "FEM assembly", 0.0);
	ret = irdm_fem_assemble(&m->mesh, &sc->mat, sc->mass, m->fixed, &m->fem, err, errlen);
	if (ret)
		goto out_fail;
	if (progress)
		progress(ctx, "FEM assembly", 1.0);
	m->seconds_fem = irdm_now_s() - t0;
	/* the scene's rows and columns before the eigensolve: over MPI only
	 * their eigenvector entries cross the network */
	ret = irdm_model_select(sc, m, err, errlen);
	if (ret)
		goto out_fail;
	ret = solve_modes(sc, m, n_modes_needed, sc->eigensolver, progress, ctx, err, errlen);
	if (lowest_instead(sc, n_modes_needed, ret)) {
		char line[512];

		snprintf(line, sizeof(line), "auto: every mode does not fit (%.300s): the lowest modes from a Lanczos solve instead, the head from Chebyshev series",
			 err);
		if (progress)
			progress(ctx, line, -1.0);
		m->lowest_only = true;
		ret = solve_modes(sc, m, IRDM_LOWEST_FIRST, IRDM_EIG_LANCZOS, progress, ctx, err,
				  errlen);
	} else if (ret == IRDM_ENOMEM && n_modes_needed == 0) {
		say_all_modes(sc, err, errlen);
	}
	if (ret)
		goto out_fail;
	return IRDM_OK;
out_fail:
	irdm_model_free(m);
	return ret;
}

int irdm_model_solve_lowest(const struct irdm_scene *sc, size_t n, irdm_progress_fn progress,
			    void *ctx, struct irdm_model *m, char *err, size_t errlen)
{
	irdm_modes_free(&m->modes);
	return solve_modes(sc, m, n, IRDM_EIG_LANCZOS, progress, ctx, err, errlen);
}

void irdm_model_free(struct irdm_model *m)
{
	irdm_mesh_free(&m->mesh);
	free(m->fixed);
	free(m->on_surface);
	irdm_fem_free(&m->fem);
	irdm_modes_free(&m->modes);
	free(m->rows);
	free(m->cols);
	free(m->row_dofs);
	free(m->col_dofs);
	free(m->tris);
	memset(m, 0, sizeof(*m));
}
