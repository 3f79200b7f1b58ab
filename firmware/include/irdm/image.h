/* SPDX-License-Identifier: MIT */
/*
 * Flash image loader: maps an image read-only, validates every header field,
 * offset, size and checksum, and hands out typed views of its sections.
 * Nothing here allocates after irdm_image_map() returns.
 */
#ifndef IRDM_IMAGE_H
#define IRDM_IMAGE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/error.h"
#include "irdm/image_format.h"
#include "irdm/precision.h"

enum irdm_image_map_flags {
	IRDM_IMAGE_MAP_LOCK = 1u << 0, /* mlock the mapping; fail if that is refused */
};

/* Typed views into a validated image.  Pointers point into the mapping. */
struct irdm_image {
	const uint8_t *base; /* mapping (or caller's buffer) */
	size_t size;
	bool mapped; /* base came from mmap */
	bool locked; /* mlock succeeded */
	const struct irdm_meta *meta;
	const char *provenance; /* not NUL-terminated: provenance_len bytes */
	size_t provenance_len;
	/* PROVENANCE two_contacts_error: the precompute's force error with two
	 * contacts at once (meta's measured_error is one contact's); -1 if the
	 * image does not say */
	double two_contacts_error;
	const struct irdm_node *nodes; /* meta->n_nodes */
	const uint32_t *columns;       /* meta->n_cols */
	const uint32_t *tris;          /* 3 * meta->n_tris */
	const void *fir;               /* FIR: n_cols*n_nodes*T*9 of precision */
	const struct irdm_mode *modes; /* modal: n_modes */
	const void *mode_shapes;       /* modal: n_nodes*3*n_modes of precision */
	/* modal, optional (all NULL if absent): the static correction's kept
	 * 3x3 blocks; column c's are k in [corr_start[c], corr_start[c+1]),
	 * block k displaces column corr_rows[k] (increasing; c always there) */
	const uint32_t *corr_start; /* n_cols + 1 */
	const uint32_t *corr_rows;  /* corr_start[n_cols] */
	const void *corr_blocks;    /* corr_start[n_cols] x 9 of precision */
	/* optional far field of the correction (STATIC_CORR_LOWRANK; rank 0
	 * and NULL if absent): every block gets U[c'] diag(lambda) U[c]^T */
	uint32_t corr_rank;
	const void *corr_lambda; /* corr_rank of precision */
	const void *corr_u;      /* 3 n_cols x corr_rank of precision */
	/* optional block low-rank correction (STATIC_CORR_CLUSTERS; all NULL
	 * if absent): every block adds its pair's value (image_format.h) */
	const struct irdm_corr_clusters_header *corr_clusters;
	const uint32_t *corr_cl_start;              /* n_clusters + 1 */
	const uint32_t *corr_cl_members;            /* n_cols */
	const uint32_t *corr_cl_pos;                /* n_cols */
	const struct irdm_corr_pair *corr_cl_pairs; /* n_clusters (n_clusters + 1) / 2 */
	const void *corr_cl_values;                 /* n_values of precision */
	/* modal, optional (NULL if absent): the dropped modes' response over
	 * meta->head_samples samples for each kept block k, [k][s][3][3] of
	 * precision (exact over the first half, tapered over the second); its
	 * samples sum to block k of corr_blocks */
	const void *exact_head;
	/* HEAD_PAIRS (NULL if not): block k's run in exact_head is
	 * head_index[k] (image_format.h); read it through irdm_image_head_run() */
	const uint32_t *head_index;
	/* optional COLUMN_SCALE (NULL if absent: every scale 1): FIR,
	 * corr_blocks and exact_head hold force column c's values divided
	 * by col_scale[c]; read them through irdm_image_value() */
	const float *col_scale;                 /* n_cols */
	const struct irdm_rigid *rigid;         /* floating only, else NULL */
	const struct irdm_stability *stability; /* n_cols */
	/* optional CONTACT_BVH (NULL if absent): validated header, payload bytes */
	const struct irdm_bvh_header *contact_bvh;
	size_t contact_bvh_size;
};

/*
 * Validate an image already in memory (buf must stay valid; it must be
 * 8-byte aligned).  The checks run in the order of docs/image-format.md
 * section 9 and the first failure is returned, with a one-line reason in
 * err; on failure img is zeroed.
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if buf is not 8-byte aligned (or NULL with size > 0);
 * IRDM_ENOMEM if the scratch memory of a check cannot be allocated;
 * IRDM_ETRUNC if the image is shorter than its header or its header says;
 * IRDM_EMAGIC if it is not an IRDM image;
 * IRDM_EVERSION if its major version is not IRDM_IMAGE_VERSION_MAJOR;
 * IRDM_ECRC if the header, table or a section checksum does not match;
 * IRDM_ERANGE if an offset, size or alignment is out of range, regions
 * overlap or bytes trail the image;
 * IRDM_EMISSING if a required section is absent or a kind appears twice;
 * IRDM_EFORMAT if a field's value is invalid (counts, dt, indices, NaN,
 * non-zero padding or reserved bytes, a section that must be absent).
 */
int irdm_image_parse(const void *buf, size_t size, struct irdm_image *img,
		     char *err, size_t errlen);

/* STATIC_CORR_CLUSTERS (img->corr_clusters non-NULL): the cluster of
 * column col, and its index among the cluster's members into *local
 * (O(log n_clusters)); the pair table entry of clusters a and b in either
 * order (stored once, for min, max).  Tick-safe. */
uint32_t irdm_image_corr_cluster(const struct irdm_image *img, uint32_t col, uint32_t *local);

/* Entry (i, j), i <= j, of an n x n upper triangle stored row by row:
 * both the pair table (n = n_clusters) and a self pair's values (n = 3|a|)
 * are laid out so. */
static inline size_t irdm_upper_index(size_t n, size_t i, size_t j)
{
	return i * n - i * (i ? i - 1 : 0) / 2 + (j - i);
}

const struct irdm_corr_pair *irdm_image_corr_pair(const struct irdm_image *img, uint32_t a,
						  uint32_t b);

/* Force column col's storage scale: a power of two, 1 without COLUMN_SCALE. */
static inline double irdm_image_col_scale(const struct irdm_image *img, uint32_t col)
{
	return img->col_scale ? (double)img->col_scale[col] : 1.0;
}

/*
 * Element i of data, a response array in the image's precision (FIR,
 * corr_blocks or exact_head) whose element i belongs to force column col:
 * the value as stored times the column's scale, i.e. what it means.  The
 * one way to read those arrays outside the tick's sums, which instead
 * fold the scale into the force history they keep (engine_fir.c).
 */
static inline double irdm_image_value(const struct irdm_image *img, const void *data, uint32_t col,
				      size_t i)
{
	return irdm_elem_get(data, img->meta->precision, i) * irdm_image_col_scale(img, col);
}

/*
 * Block k's run in exact_head ([s][3][3], head_samples samples), and
 * whether it is stored transposed (HEAD_PAIRS: block (c, r) is block
 * (r, c) transposed); k itself, not transposed, without HEAD_PAIRS.
 */
static inline size_t irdm_image_head_run(const struct irdm_image *img, size_t k, bool *transposed)
{
	uint32_t v;

	if (!img->head_index) {
		*transposed = false;
		return k;
	}
	v = img->head_index[k];
	*transposed = v & IRDM_HEAD_TRANSPOSED;
	return v & IRDM_HEAD_RUN_MASK;
}

/* Element i (row-major 3x3) of a block read transposed or not: the
 * element of its run to read. */
static inline size_t irdm_head_elem(bool transposed, size_t i)
{
	return transposed ? 3 * (i % 3) + i / 3 : i;
}

/* A section kind's name as docs/image-format.md gives it ("META", ...),
 * "unknown kind" for one this build does not know. */
const char *irdm_image_kind_name(uint32_t kind);

/* Section lookup in a validated image: the table entry of kind, or NULL if
 * absent (or img holds no image).  Cannot fail otherwise. */
const struct irdm_image_section *irdm_image_find(const struct irdm_image *img,
						 uint32_t kind);

/* Index k of the static-correction block for a force at column col_force
 * and the displacement of column col_disp (corr_blocks[9k..9k+8]), or -1 if
 * the block was dropped or the image has no correction.  Binary search in
 * the column's rows: O(log kept), no allocation (tick-safe). */
long irdm_image_corr_block(const struct irdm_image *img, uint32_t col_force,
			   uint32_t col_disp);

/* The static correction's block for a force at column col_force and the
 * displacement of column col_disp, entry [i][j] = displacement along i per
 * unit force along j, into blk: the kept block (zero where dropped) plus
 * the low-rank far field plus the clusters' value.  Zeros if the image has
 * no correction.  O(log kept + 9 corr_rank + log n_clusters + 9 rank of
 * the clusters' pair), no allocation (tick-safe). */
void irdm_image_corr_value(const struct irdm_image *img, uint32_t col_force,
			   uint32_t col_disp, double blk[9]);

/* The largest spectral radius of the STABILITY table (0 with no column),
 * which the loader has checked meta->max_spectral_radius repeats. */
double irdm_image_max_radius(const struct irdm_image *img);

/* CRC-32C (Castagnoli), reflected, init/xorout 0xFFFFFFFF. */
uint32_t irdm_crc32c(const void *data, size_t len);

/* The CRC-32C of a stream in pieces: crc is the previous pieces' (0 before
 * the first); irdm_crc32c_update(irdm_crc32c(a), b) is the CRC of a then b. */
uint32_t irdm_crc32c_update(uint32_t crc, const void *data, size_t len);

#endif /* IRDM_IMAGE_H */
