/* SPDX-License-Identifier: MIT */
/*
 * The static correction between every pair of touchable nodes, block
 * low-rank over clusters of nearby columns (image section
 * STATIC_CORR_CLUSTERS): each pair of clusters is stored whole or as the
 * shortest product U V^T that leaves no 3x3 block off by more than tol
 * sqrt(|S_aa| |S_bb|).
 */
#ifndef IRDM_TOOLS_STATIC_CLUSTERS_H
#define IRDM_TOOLS_STATIC_CLUSTERS_H

#include <stdint.h>

#include "irdm/error.h"
#include "modal/modal.h"
#include "modal/static_sparse.h"

/* Scene key static_correction_cluster: nodes per cluster at most (0: the
 * blocks above static_correction_tol and the far field instead). */
#define IRDM_STATIC_CORR_CLUSTER_MIN 4
#define IRDM_STATIC_CORR_CLUSTER_MAX 1024

struct irdm_corr_clusters {
	size_t n_cols, n_clusters, n_pairs;
	uint32_t *start;   /* n_clusters + 1 */
	uint32_t *members; /* n_cols, cluster by cluster */
	uint32_t *col_pos; /* n_cols: column c is members[col_pos[c]] */
	uint32_t *rank;    /* n_pairs: IRDM_CORR_PAIR_DENSE or the rank */
	uint64_t *offset;  /* n_pairs: into values */
	double *values;    /* n_values, the pairs in table order */
	size_t n_values, max_rank, n_dense;
	/* the largest 3x3 block error the compression left, in units of
	 * sqrt(|S_aa| |S_bb|), measured on every pair (at most tol) */
	double max_err;
};

/*
 * The static correction of irdm_static_correction() between the columns
 * (col_dofs: 3 per column, free DoF or -1; col_pos_m: 3 per column, their
 * rest positions), clustered by recursive bisection of the positions into
 * clusters of at most cluster_nodes columns, solved a cluster's columns at
 * a time with one factor: the pairs with an earlier cluster are complete
 * then and are compressed at once (a truncated SVD of the block scaled by
 * the diagonal norms), so nothing of size n_cols^2 is held.  Self pairs
 * are dense and exactly symmetric.  kept gets the diagonal blocks, zero
 * (the clusters hold every value), for the image's STATIC_CORR index.
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_ENUMERIC (factor, solve, SVD);
 * IRDM_EINVAL (cluster_nodes out of range, more clusters than the image
 * holds).
 */
int irdm_static_correction_clusters(const struct irdm_fem *fem, const struct irdm_modes *m,
				    bool floating, const int64_t *col_dofs, const double *col_pos_m,
				    size_t n_cols, size_t cluster_nodes, double tol,
				    irdm_progress_fn progress, void *ctx,
				    struct irdm_corr_sparse *kept, struct irdm_corr_clusters *out,
				    char *err, size_t errlen);

/* Block (force at col_f, displacement at col_d), out[3i + j]: the same
 * sums in the same order as the firmware's read. */
void irdm_corr_clusters_block(const struct irdm_corr_clusters *cl, size_t col_f, size_t col_d,
			      double out[9]);

/* Free what irdm_static_correction_clusters() allocated and zero cl. */
void irdm_corr_clusters_free(struct irdm_corr_clusters *cl);

#endif
