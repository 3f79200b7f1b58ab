/* SPDX-License-Identifier: MIT */
/* From a scene to a flash image. */
#ifndef IRDM_TOOLS_PRECOMPUTE_H
#define IRDM_TOOLS_PRECOMPUTE_H

#include <stdbool.h>
#include <stdint.h>

#include "irdm/version.h"
#include "precompute/model.h"

#define IRDM_TOOL_VERSION "irdm " IRDM_VERSION

struct irdm_precompute_opts {
	const char *out_path; /* image to write (NULL with part_out) */
	/* time-domain split: compute input DoFs [part_begin, part_end) of the
	 * scene's column DoFs into part_out instead of an image */
	const char *part_out;
	size_t part_begin, part_end;
	/* time-domain merge: take the responses from these part files */
	const char *const *merge;
	size_t n_merge;
	irdm_progress_fn progress;
	void *ctx;
};

struct irdm_precompute_report {
	double seconds_total, seconds_mesh, seconds_fem, seconds_eig;
	double seconds_responses, seconds_stability;
	/* blocks the eigensolve was split into by symmetry (1: whole; 0: none ran) */
	unsigned eig_blocks;
	size_t image_bytes;
	size_t mesh_nodes, mesh_tets, free_dofs, rows, cols, tris, modes, modes_total;
	double first_elastic_hz, max_spectral_radius;
	size_t unstable_cols;
	/* modal static correction: blocks kept of n_cols^2 (0: none) */
	size_t corr_blocks;
	double corr_tol, corr_max_dropped_rel;
	/* its far field: rank (0: none), and over the dropped blocks of
	 * corr_checked columns, without [0] and with [1] it, in units of
	 * sqrt(|S_aa| |S_bb|): the largest and the RMS error */
	size_t corr_rank, corr_checked;
	double corr_far_max[2], corr_far_rms[2];
	/* static_correction_cluster: clusters, dense pairs, largest rank,
	 * largest block error left (units of sqrt(|S_aa| |S_bb|)), values */
	size_t corr_clusters, corr_cluster_pairs_dense, corr_cluster_max_rank, corr_cluster_values;
	double corr_cluster_max_err;
	/* the force error against the exact model (accuracy/measure.h) */
	bool error_measured;
	double measured_error, seconds_error;
	uint32_t error_worst_node;
	const char *error_worst_run;
	/* the exact model it was measured against: "every mode" (this
	 * build's, or a precompute of its own), or "the kept modes and
	 * Chebyshev series" (a head without every mode: krylov_head.h) */
	const char *error_reference;
	size_t error_cols, error_ticks;
	/* every column measured (error_columns), their median and p90 */
	bool error_every_column;
	double error_median, error_p90;
	/* two contacts at once (accuracy/pairs.h): the worst of n pairs */
	bool pairs_measured;
	double pairs_error;
	uint32_t pairs_nodes[2];
	const char *pairs_run;
	size_t pairs_n;
	/* the representation written (representation = auto: the chosen one)
	 * and how many candidates auto built */
	char representation[64];
	size_t auto_tries;
	/* auto chose from the lowest modes of a Lanczos solve: every mode
	 * did not fit (lowest.h) */
	bool auto_lowest;
};

/*
 * Return: IRDM_OK; IRDM_EINVAL if the scene or a part/merge is inconsistent;
 * IRDM_ENOMEM; IRDM_EIO if a mesh, part or the image cannot be read or
 * written; IRDM_EFORMAT if an input file is malformed; IRDM_ECHILD if tetgen
 * fails; IRDM_ENUMERIC if a factorisation, eigensolve or stability
 * computation fails, if the image is not certified stable (unless the
 * scene's uncertified) or if its measured force error is above the
 * scene's max_error.  A one-line reason goes to err.
 */
int irdm_precompute(const struct irdm_scene *sc, const struct irdm_precompute_opts *o,
		    struct irdm_precompute_report *rep, char *err, size_t errlen);

/* Number of column DoFs the scene has (for splitting time-domain work).
 * Return: as irdm_model_build(). */
int irdm_precompute_count_inputs(const struct irdm_scene *sc, size_t *n_inputs,
				 char *err, size_t errlen);

#endif
