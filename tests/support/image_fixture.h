/* SPDX-License-Identifier: MIT */
/*
 * Small, valid IRDM images for tests: a grid of nodes with deterministic
 * response values that are exact in every precision (k/1024, |k| <= 500),
 * so a test can compare what it maps with img_fixture_value() bit for bit.
 *
 *   struct img_fixture fx;
 *   img_fixture_fir(&fx, IRDM_ELEM_F32, 6, 2, 4);   (nodes, cols, T)
 *   fx.meta.dt_s = 0;                             (tamper if you like)
 *   img_fixture_write(&fx, path, err, sizeof(err));
 *   img_fixture_free(&fx);
 *
 * Every array is owned by the fixture and may be changed before writing;
 * changing a count in meta does not change what is written for the arrays.
 */
#ifndef IRDM_TESTS_IMAGE_FIXTURE_H
#define IRDM_TESTS_IMAGE_FIXTURE_H

#include <stddef.h>
#include <stdint.h>

#include "irdm/image.h"
#include "image/image_writer.h"

struct img_fixture {
	struct irdm_meta meta;
	char provenance[256];
	size_t provenance_len;
	struct irdm_node *nodes; /* n_nodes */
	uint32_t *columns;       /* n_cols */
	uint32_t *tris;          /* 3 * n_tris */
	void *fir;               /* FIR: fir_bytes */
	struct irdm_mode *modes; /* modal: n_modes */
	void *mode_shapes;       /* modal: shapes_bytes */
	void *static_corr;       /* modal + STATIC_CORR: corr_bytes */
	/* its STATIC_CORR_INDEX: every block kept (the layout of tol = 0):
	 * starts c n_cols, then rows 0..n_cols-1 for every column */
	uint32_t *corr_index;
	/* optional STATIC_CORR_LOWRANK (img_fixture_lowrank): header, then
	 * lambda and U of fixture values */
	void *corr_lowrank;
	/* optional STATIC_CORR_CLUSTERS (img_fixture_clusters): the payload
	 * as image_format.h lays it out */
	void *corr_clusters;
	struct irdm_rigid rigid;          /* written iff FLOATING */
	struct irdm_stability *stability; /* n_cols */
	/* Sizes of the arrays as built: what img_fixture_add() writes, so
	 * tampering with meta counts never makes it read past an array. */
	uint64_t nodes_bytes, columns_bytes, tris_bytes, stability_bytes;
	uint64_t fir_bytes, modes_bytes, shapes_bytes, corr_bytes, corr_index_bytes;
	uint64_t lowrank_bytes, clusters_bytes;
};

/* Grounded FIR image.  Returns 0, -1 when out of memory. */
int img_fixture_fir(struct img_fixture *fx, uint32_t precision,
		    uint32_t n_nodes, uint32_t n_cols, uint32_t fir_length);

/* Modal image; meta_flags may hold IRDM_META_FLOATING and
 * IRDM_META_STATIC_CORR.  Modes are exact ZOH discretisations. */
int img_fixture_modal(struct img_fixture *fx, uint32_t precision,
		      uint32_t n_nodes, uint32_t n_cols, uint32_t n_modes,
		      uint32_t meta_flags);

/* Add a valid STATIC_CORR_LOWRANK of the given rank to a modal fixture
 * (meta precision; lambda[k] is value k, U element i value rank + i of
 * the kind).  Returns 0, -1 when out of memory. */
int img_fixture_lowrank(struct img_fixture *fx, uint32_t rank);

/* Add a valid STATIC_CORR_CLUSTERS to a modal fixture with STATIC_CORR:
 * the columns in reverse order (members[i] = n_cols - 1 - i) split into
 * n_clusters clusters, cluster a from member a n_cols / n_clusters on;
 * self pairs dense, every cross pair of the given rank (at most
 * 3 x the smaller cluster's size; IRDM_CORR_PAIR_DENSE: dense).  The
 * section holds the symmetric 3 n_cols x 3 n_cols matrix S (row 3 c + x:
 * column c's axis x; displacement rows, force columns), written to s_out
 * row-major when not NULL: within a cluster S[r][c] is fixture value
 * min(r, c) 3 n_cols + max(r, c) of the kind; between r in a lower cluster
 * than c it is sum_t G[r][t] H[c][t] (G, H of fixture values), exact in
 * every precision.  Returns 0, -1 when out of memory or n_clusters is not
 * in 1..n_cols. */
int img_fixture_clusters(struct img_fixture *fx, uint32_t n_clusters, uint32_t rank,
			 double *s_out);

/* Bytes of STATIC_CORR_CLUSTERS' header and tables, padded to 8: where its
 * pair table starts (image_format.h). */
uint64_t img_fixture_clusters_tables(uint32_t n_clusters, uint32_t n_cols);

void img_fixture_free(struct img_fixture *fx);

/* Value stored at element i of section kind (FIR, MODE_SHAPES, STATIC_CORR,
 * STATIC_CORR_LOWRANK's values after the header). */
double img_fixture_value(uint32_t kind, uint64_t i);

/* Add every section the fixture holds (by meta) to w. */
void img_fixture_add(const struct img_fixture *fx, struct irdm_image_writer *w);

int img_fixture_buffer(const struct img_fixture *fx, void **buf, size_t *size);
int img_fixture_write(const struct img_fixture *fx, const char *path,
		      char *err, size_t errlen);

/* Recompute every checksum of an image in memory after tampering, so that a
 * test reaches the check it means to trigger.  Entries that point outside
 * the buffer are left alone. */
void img_fixture_reseal(void *buf, size_t size);

/* An 8-aligned malloc'd copy of len bytes (ASan sees any overread). */
void *img_fixture_copy(const void *buf, size_t len);

#endif /* IRDM_TESTS_IMAGE_FIXTURE_H */
