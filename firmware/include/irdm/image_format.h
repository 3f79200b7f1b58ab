/* SPDX-License-Identifier: MIT */
/*
 * On-disk layout of an IRDM flash image.  Shared by the offline tools that
 * write images and the firmware that maps them; it holds no code.
 *
 * An image is: a 64-byte header at offset 0, a section table, and payloads.
 * Everything is little-endian, position independent (offsets from the file
 * start, never pointers) and every payload starts on an IRDM_IMAGE_ALIGN
 * boundary so it can be used in place from a read-only mapping.
 * See docs/image-format.md for the full description.
 */
#ifndef IRDM_IMAGE_FORMAT_H
#define IRDM_IMAGE_FORMAT_H

#include <stdint.h>

#define IRDM_IMAGE_MAGIC "IRDMIMG"  /* 7 chars + NUL = 8 bytes */
#define IRDM_IMAGE_VERSION_MAJOR 2u /* incompatible layout change */
#define IRDM_IMAGE_VERSION_MINOR 5u /* compatible additions: 2.1 STATIC_CORR_LOWRANK, EXACT_HEAD; 2.2 STATIC_CORR_CLUSTERS; 2.3 measured_error; 2.4 COLUMN_SCALE; 2.5 EXACT_HEAD_INDEX */
#define IRDM_IMAGE_ALIGN 64u        /* payload alignment, bytes */
#define IRDM_IMAGE_MAX_SECTIONS 32u

struct irdm_image_header { /* 64 bytes at offset 0 */
	uint8_t magic[8];  /* IRDM_IMAGE_MAGIC incl. NUL */
	uint16_t version_major;
	uint16_t version_minor;
	uint32_t header_size;          /* sizeof(struct irdm_image_header) */
	uint64_t file_size;            /* whole file, bytes */
	uint32_t section_count;        /* 1..IRDM_IMAGE_MAX_SECTIONS */
	uint32_t section_table_offset; /* bytes, multiple of IRDM_IMAGE_ALIGN */
	uint32_t flags;                /* reserved, 0 */
	uint32_t table_crc32c;         /* CRC-32C of the section table */
	uint8_t reserved[20];          /* 0 */
	uint32_t header_crc32c;        /* CRC-32C of bytes [0, 60) */
};

/* Element type of a section's payload (also the storage precision of
 * response data). */
enum irdm_elem {
	IRDM_ELEM_BYTES = 0, /* structs or text */
	IRDM_ELEM_F16 = 1,   /* IEEE 754 binary16 */
	IRDM_ELEM_F32 = 2,
	IRDM_ELEM_F64 = 3,
	IRDM_ELEM_U32 = 4,
};

struct irdm_image_section { /* 32 bytes each */
	uint32_t kind;      /* enum irdm_section_kind */
	uint32_t elem;      /* enum irdm_elem */
	uint64_t offset;    /* from file start, aligned */
	uint64_t size;      /* payload bytes */
	uint32_t crc32c;    /* CRC-32C of the payload */
	uint32_t reserved;  /* 0 */
};

enum irdm_section_kind {
	IRDM_SEC_META = 1,                  /* struct irdm_meta, always present */
	IRDM_SEC_PROVENANCE = 2,            /* UTF-8 "key=value\n" lines, always present */
	IRDM_SEC_NODES = 3,                 /* n_nodes x struct irdm_node (the rows) */
	IRDM_SEC_COLUMNS = 4,               /* n_cols x u32: node index of each touchable node */
	IRDM_SEC_SURFACE = 5,               /* n_tris x 3 u32 node indices, outward (CCW seen from outside) */
	IRDM_SEC_FIR = 6,                   /* FIR only: R[s] blocks [col][row][s][3][3], elem = precision */
	IRDM_SEC_MODES = 7,                 /* modal only: n_modes x struct irdm_mode */
	IRDM_SEC_MODE_SHAPES = 8,           /* modal only: [row][3][mode], elem = precision */
	IRDM_SEC_STATIC_CORR = 9,           /* modal, optional: kept residual-compliance blocks [k][3][3] */
	IRDM_SEC_RIGID = 10,                /* floating only: struct irdm_rigid */
	IRDM_SEC_STABILITY = 11,            /* n_cols x struct irdm_stability */
	IRDM_SEC_CONTACT_BVH = 12,          /* optional: contact BVH + adjacency, struct irdm_bvh_header */
	IRDM_SEC_STATIC_CORR_INDEX = 13,    /* with STATIC_CORR: u32 column starts + rows of its blocks */
	IRDM_SEC_STATIC_CORR_LOWRANK = 14,  /* optional, with STATIC_CORR: far field U diag(lambda) U^T */
	IRDM_SEC_EXACT_HEAD = 15,           /* modal, optional: [k][s][3][3] of the STATIC_CORR blocks, s < head_samples */
	IRDM_SEC_STATIC_CORR_CLUSTERS = 16, /* optional, with STATIC_CORR: every block, block low-rank over clusters */
	IRDM_SEC_COLUMN_SCALE = 17,         /* optional: n_cols x f32, a power of two per force column */
	IRDM_SEC_EXACT_HEAD_INDEX = 18,     /* with HEAD_PAIRS: u32 per STATIC_CORR block, its EXACT_HEAD run */
};

enum irdm_repr {
	IRDM_REPR_FIR = 1,
	IRDM_REPR_MODAL = 2,
};

enum irdm_meta_flags {
	IRDM_META_FLOATING = 1u << 0,    /* non-grounded: RIGID present */
	IRDM_META_STATIC_CORR = 1u << 1, /* STATIC_CORR present */
	IRDM_META_CONSISTENT_MASS = 1u << 2,
	IRDM_META_TIME_DOMAIN = 1u << 3, /* FIR computed by time integration */
	/* FIR: samples [fir_exact, fir_length) are the response tapered to
	 * zero, the taps' sum restored to the static compliance */
	IRDM_META_FIR_TAIL_WINDOW = 1u << 4,
	/* modal with STATIC_CORR: EXACT_HEAD present, head_samples samples */
	IRDM_META_EXACT_HEAD = 1u << 5,
	/* measured_error holds the precompute's measured force error */
	IRDM_META_ERROR_MEASURED = 1u << 6,
	/* COLUMN_SCALE present: FIR, STATIC_CORR and EXACT_HEAD hold each
	 * force column's values divided by its scale (2.4) */
	IRDM_META_COLUMN_SCALE = 1u << 7,
	/* with EXACT_HEAD, without COLUMN_SCALE: EXACT_HEAD holds each
	 * symmetric pair of blocks once, EXACT_HEAD_INDEX says where (2.5) */
	IRDM_META_HEAD_PAIRS = 1u << 8,
};

/*
 * EXACT_HEAD_INDEX entry of a block k: its run in EXACT_HEAD is
 * entry & IRDM_HEAD_RUN_MASK, read transposed if IRDM_HEAD_TRANSPOSED is
 * set.  R[s] is symmetric, so block (force c, displacement r) is block
 * (r, c) transposed: the blocks with r >= c are stored, in the order of
 * k, and those with r < c point at their mirror's run.
 */
#define IRDM_HEAD_TRANSPOSED 0x80000000u
#define IRDM_HEAD_RUN_MASK 0x7fffffffu

/* PROVENANCE key of the precompute's force error with two contacts at
 * once (a number >= 0; meta's measured_error is one contact's). */
#define IRDM_PROV_TWO_CONTACTS_ERROR "two_contacts_error"

/* Longest head (samples): the engine keeps a ring of that many ticks. */
#define IRDM_HEAD_SAMPLES_MAX 8192u

struct irdm_meta {               /* 256 bytes */
	uint32_t representation; /* enum irdm_repr */
	uint32_t precision;      /* enum irdm_elem of FIR/MODE_SHAPES/STATIC_CORR */
	uint32_t n_nodes;        /* rows: nodes the image holds */
	uint32_t n_cols;         /* touchable nodes (columns) */
	uint32_t n_tris;         /* surface triangles */
	uint32_t fir_length;     /* T, FIR only (else 0) */
	uint32_t n_modes;        /* modal only: modes stored (else 0) */
	uint32_t flags;          /* enum irdm_meta_flags */
	double dt_s;             /* sample period */
	double young_pa;
	double poisson;
	double density_kg_m3;
	double rayleigh_a_per_s; /* C = a M + b K */
	double rayleigh_b_s;
	double damping_ratio[2]; /* as requested; 0 when a, b given */
	double damping_freq_hz[2];
	double max_spectral_radius; /* max over STABILITY entries */
	double first_elastic_hz;    /* lowest elastic natural frequency */
	uint32_t mesh_nodes;        /* of the whole source mesh */
	uint32_t mesh_tets;
	uint32_t n_modes_total; /* elastic modes of the whole model */
	uint32_t fir_exact;     /* FIR_TAIL_WINDOW: samples kept exact, 1..T-1; else 0 */
	uint64_t mesh_hash;     /* FNV-1a 64 of positions and tets */
	char tool_version[32];  /* NUL-terminated */
	char mesh_name[64];     /* NUL-terminated */
	uint32_t head_samples;  /* EXACT_HEAD: samples stored, 1..IRDM_HEAD_SAMPLES_MAX; else 0 (2.1) */
	/* ERROR_MEASURED: relative RMS force error against the exact linear
	 * model, worst of the sampled columns' step and release (2.3); else 0 */
	float measured_error;
};

struct irdm_node {          /* 16 bytes */
	float pos_m[3];     /* rest position, object frame */
	uint32_t mesh_node; /* index in the source mesh (0-based) */
};

/*
 * One mode q'' + 2 zeta omega q' + omega^2 q = phi^T f, discretised exactly
 * under zero-order hold: x[t+1] = A x[t] + b g[t], x = (q, q'), g = phi^T f.
 * The displacement response of the mode is u[t] = phi x_q[t+1].
 */
struct irdm_mode { /* 64 bytes */
	double omega_rad_s;
	double zeta;
	double a[4]; /* row-major 2x2 */
	double b[2];
};

struct irdm_rigid { /* floating objects only */
	double mass_kg;
	double com_m[3];         /* rest centre of mass, object frame */
	double inertia_kg_m2[9]; /* about the COM, row-major */
	double reserved[3];
};

enum irdm_stability_flags {
	IRDM_STAB_STABLE = 1u << 0, /* spectral radius < 1 */
};

struct irdm_stability {        /* 8 bytes, one per column */
	float spectral_radius; /* of the single-contact force recursion */
	uint32_t flags;        /* enum irdm_stability_flags */
};

/*
 * CONTACT_BVH (kind 12, elem BYTES, optional): a bounding volume hierarchy
 * over the contactable SURFACE triangles (all three vertices are columns),
 * their edge adjacency and the row -> column map.  The payload is
 *
 *   struct irdm_bvh_header                        64 bytes at 0
 *   struct irdm_bvh_node[n_bvh_nodes]             at nodes_offset
 *   u32 index[n_contact_tris]                     at index_offset
 *   u32 adjacency[n_surface_tris][3]              at adj_offset
 *   u32 col_of_row[n_rows]                        at col_of_row_offset
 *
 * contiguous in that order (the offsets are exactly the running sums, the
 * payload ends after col_of_row).  Triangles are named by their SURFACE
 * index.  Nodes are numbered in depth-first preorder: node 0 is the root,
 * every child index is greater than its parent's.  adjacency[t][e] is the
 * contactable triangle across edge e = (v[e], v[(e + 1) % 3]) of t, or
 * IRDM_BVH_NONE at a boundary of the contactable region (or a non-manifold
 * edge); it is symmetric.  col_of_row[r] is the column of row r, or
 * IRDM_BVH_NONE.  Boxes are the exact float bounds of the REST positions.
 */
#define IRDM_BVH_NONE 0xffffffffu
#define IRDM_BVH_INTERNAL 0x80000000u /* in count_or_right: internal node */
#define IRDM_BVH_LEAF_MAX 4u          /* triangles per leaf */
#define IRDM_BVH_MAX_DEPTH 48u        /* levels, the root is level 1 */

struct irdm_bvh_header {         /* 64 bytes */
	uint32_t n_surface_tris; /* = meta n_tris */
	uint32_t n_rows;         /* = meta n_nodes */
	uint32_t n_contact_tris; /* contactable triangles = index entries */
	uint32_t n_bvh_nodes;    /* 0 iff n_contact_tris = 0 */
	uint32_t depth;          /* levels, 1..IRDM_BVH_MAX_DEPTH (0 if empty) */
	uint32_t leaf_max;       /* most triangles in a leaf, <= IRDM_BVH_LEAF_MAX */
	uint32_t nodes_offset;   /* bytes from the payload start */
	uint32_t index_offset;
	uint32_t adj_offset;
	uint32_t col_of_row_offset;
	uint32_t reserved[6]; /* 0 */
};

/*
 * Leaf: count_or_right = number of triangles (1..leaf_max), left_or_first =
 * first entry of index[].  Internal: count_or_right = IRDM_BVH_INTERNAL |
 * right child, left_or_first = left child.
 */
struct irdm_bvh_node { /* 32 bytes */
	float lo[3];   /* rest-position bounds, finite, lo <= hi */
	float hi[3];
	uint32_t left_or_first;
	uint32_t count_or_right;
};

/*
 * STATIC_CORR_LOWRANK (kind 14, elem BYTES, optional, only with STATIC_CORR,
 * since minor 1): the static correction's far field, the part of the
 * dropped blocks that is smooth, as a symmetric low-rank term added to
 * every block (kept or not): block (c, c') += U[c'] diag(lambda) U[c]^T.
 * The payload is, the values in the image's precision (as STATIC_CORR),
 *
 *   struct irdm_corr_lowrank_header            16 bytes at 0
 *   lambda[rank]                               at 16
 *   u[3 n_cols][rank]                          at 16 + rank x elem size
 *
 * u's row 3c + i is column c's axis i (a DoF of a fixed node is a row of
 * zeros), its rank values contiguous (one dot product per block entry).
 */
#define IRDM_CORR_LOWRANK_MAX 1024u /* rank bound: the tick's cost per block */

struct irdm_corr_lowrank_header { /* 16 bytes */
	uint32_t rank;            /* 1..min(3 n_cols, IRDM_CORR_LOWRANK_MAX) */
	uint32_t reserved[3];     /* 0 */
};

/*
 * STATIC_CORR_CLUSTERS (kind 16, elem BYTES, optional, only with STATIC_CORR,
 * since minor 2): the static correction between every pair of touchable
 * nodes, block low-rank.  The columns are split into clusters of nearby
 * nodes; the correction between two clusters far apart is smooth enough
 * for a low-rank product, between near ones it is stored whole.  Every
 * block (kept or not) adds its value from here.  The payload is
 *
 *   struct irdm_corr_clusters_header     32 bytes at 0
 *   u32 start[n_clusters + 1]            at 32: cluster a is members
 *                                        [start[a], start[a + 1])
 *   u32 members[n_cols]                  the columns, cluster by cluster
 *   u32 col_pos[n_cols]                  column c is members[col_pos[c]]
 *   zero bytes up to a multiple of 8
 *   struct irdm_corr_pair pairs[n_clusters (n_clusters + 1) / 2]
 *   values[n_values]                     the image's precision
 *
 * Pair (a, b) with a <= b is entry a n_clusters - a (a - 1) / 2 + b - a:
 * the matrix from a force at cluster b's members to the displacement of
 * cluster a's, row (col) 3 i + x being the i-th member's axis x.  At
 * values[offset] it is, for rank IRDM_CORR_PAIR_DENSE, the 3|a| x 3|b|
 * matrix row-major; else U[3|a|][rank] then V[3|b|][rank], the matrix
 * U V^T (rank 0: zero).  Pair (b, a) is pair (a, b) transposed, so every
 * block (c, c') is block (c', c) transposed to the bit.  A self pair
 * (a, a) has rank IRDM_CORR_PAIR_DENSE and holds only its upper triangle,
 * row by row (n = 3|a|: entry (i, j), i <= j, at i n - i (i - 1) / 2 +
 * j - i; n (n + 1) / 2 values), so it is symmetric by construction.  The
 * pairs' values follow each other in table order, with no gaps.
 */
#define IRDM_CORR_CLUSTERS_MAX 4096u     /* clusters: bounds the pair table */
#define IRDM_CORR_PAIR_DENSE 0xffffffffu /* irdm_corr_pair.rank of a dense pair */

struct irdm_corr_clusters_header { /* 32 bytes */
	uint32_t n_clusters;       /* 1..min(n_cols, IRDM_CORR_CLUSTERS_MAX) */
	uint32_t max_rank;         /* largest low-rank pair's rank, <= IRDM_CORR_LOWRANK_MAX */
	uint64_t n_values;         /* elements of values[] */
	uint32_t reserved[4];      /* 0 */
};

struct irdm_corr_pair {    /* 16 bytes */
	uint64_t offset;   /* element index into values[] */
	uint32_t rank;     /* IRDM_CORR_PAIR_DENSE, or 0..min(3|a|, 3|b|, max_rank) */
	uint32_t reserved; /* 0 */
};

_Static_assert(sizeof(struct irdm_image_header) == 64, "header size");
_Static_assert(sizeof(struct irdm_image_section) == 32, "section size");
_Static_assert(sizeof(struct irdm_meta) == 256, "meta size");
_Static_assert(sizeof(struct irdm_node) == 16, "node size");
_Static_assert(sizeof(struct irdm_mode) == 64, "mode size");
_Static_assert(sizeof(struct irdm_rigid) == 128, "rigid size");
_Static_assert(sizeof(struct irdm_stability) == 8, "stability size");
_Static_assert(sizeof(struct irdm_bvh_header) == 64, "bvh header size");
_Static_assert(sizeof(struct irdm_bvh_node) == 32, "bvh node size");
_Static_assert(sizeof(struct irdm_corr_lowrank_header) == 16, "lowrank header size");
_Static_assert(sizeof(struct irdm_corr_clusters_header) == 32, "clusters header size");
_Static_assert(sizeof(struct irdm_corr_pair) == 16, "cluster pair size");

#endif /* IRDM_IMAGE_FORMAT_H */
