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

#include "irdm/image_format.h"
#include "irdm/precision.h"

/* Errors (negative return values). */
enum irdm_image_error {
	IRDM_IMAGE_OK = 0,
	IRDM_IMAGE_EIO = -1,        /* cannot open, stat, map or lock the file */
	IRDM_IMAGE_ETRUNC = -2,     /* file shorter than its header says */
	IRDM_IMAGE_EMAGIC = -3,     /* not an IRDM image */
	IRDM_IMAGE_EVERSION = -4,   /* unsupported major version */
	IRDM_IMAGE_ECRC = -5,       /* header, table or section checksum mismatch */
	IRDM_IMAGE_ERANGE = -6,     /* offset/size/alignment out of range or overlapping */
	IRDM_IMAGE_EMISSING = -7,   /* a required section is absent or duplicated */
	IRDM_IMAGE_EINVAL = -8,     /* a field's value is invalid (counts, dt, indices, NaN) */
};

enum irdm_image_map_flags {
	IRDM_IMAGE_MAP_LOCK = 1u << 0,  /* mlock the mapping; fail if that is refused */
};

/* Typed views into a validated image.  Pointers point into the mapping. */
struct irdm_image {
	const uint8_t *base;                /* mapping (or caller's buffer) */
	size_t size;
	bool mapped;                        /* base came from mmap */
	bool locked;                        /* mlock succeeded */
	const struct irdm_meta *meta;
	const char *provenance;             /* not NUL-terminated: provenance_len bytes */
	size_t provenance_len;
	const struct irdm_node *nodes;      /* meta->n_nodes */
	const uint32_t *columns;            /* meta->n_cols */
	const uint32_t *tris;               /* 3 * meta->n_tris */
	const void *fir;                    /* FIR: n_cols*n_nodes*T*9 of precision */
	const struct irdm_mode *modes;      /* modal: n_modes */
	const void *mode_shapes;            /* modal: n_nodes*3*n_modes of precision */
	const void *static_corr;            /* modal, optional: n_cols*n_cols*9 */
	const struct irdm_rigid *rigid;     /* floating only, else NULL */
	const struct irdm_stability *stability; /* n_cols */
	/* optional CONTACT_BVH (NULL if absent): validated header, payload bytes */
	const struct irdm_bvh_header *contact_bvh;
	size_t contact_bvh_size;
};

/*
 * Map and validate the image at path.  Populates the mapping (no page fault
 * later) and, with IRDM_IMAGE_MAP_LOCK, locks it.  Returns IRDM_IMAGE_OK or a
 * negative enum irdm_image_error with a one-line reason in err.
 */
int irdm_image_map(const char *path, unsigned flags, struct irdm_image *img,
		   char *err, size_t errlen);

/* Validate an image already in memory (buf must stay valid; it must be
 * 8-byte aligned).  Same checks and errors as irdm_image_map(). */
int irdm_image_parse(const void *buf, size_t size, struct irdm_image *img,
		     char *err, size_t errlen);

void irdm_image_unmap(struct irdm_image *img);

/* Name of an error code, e.g. "bad checksum". */
const char *irdm_image_strerror(int code);

/* Section lookup (NULL if absent). */
const struct irdm_image_section *irdm_image_find(const struct irdm_image *img,
						 uint32_t kind);

/* CRC-32C (Castagnoli), reflected, init/xorout 0xFFFFFFFF. */
uint32_t irdm_crc32c(const void *data, size_t len);

#endif /* IRDM_IMAGE_H */
