/* SPDX-License-Identifier: MIT */
/*
 * Internals of the image loader shared by its files.  One parse runs the
 * checks in this order, the first failure ending it:
 *
 *   image_header.c     header, section table
 *   image_sections.c   table entries, layout, payload checksums, kinds
 *   image_semantic.c   the order of the section checks below
 *   image_meta.c       META, PROVENANCE
 *   image_object.c     NODES, COLUMNS, SURFACE, RIGID
 *   image_responses.c  STABILITY, FIR or MODES / MODE_SHAPES / STATIC_CORR
 *                      (image_static_corr.c, its clusters and far field
 *                      image_corr_clusters.c, image_corr_lowrank.c,
 *                      image_exact_head.c)
 *   image_col_scale.c  COLUMN_SCALE
 *   image_bvh.c        CONTACT_BVH
 *
 * The calls go one way, down this list: image_parse.c (the entry point,
 * irdm_image_parse) calls the steps, image_semantic.c the section checks,
 * and every check the shared rules of image_rules.c and the messages of
 * image_check.c.  What the tick reads of a parsed image is image_read.c's,
 * beside the checks.  The platform's image_map_posix.c
 * (platform/posix/image/) is the only loader file that calls the operating
 * system.  Every check returns IRDM_OK or an irdm_err and leaves its reason
 * in the parse's err buffer (img_fail).
 * tools/scripts/include-cycles.py (run by make test) keeps the calls
 * between these files free of circles.
 */
#ifndef IRDM_IMAGE_PRIV_H
#define IRDM_IMAGE_PRIV_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/image.h"

/* Views are plain struct pointers into the file: only a little-endian host
 * can use them in place. */
#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__) && \
	__BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "IRDM images are little-endian and used in place"
#endif

#define KIND_MAX IRDM_SEC_EXACT_HEAD_INDEX
#define TABLE_ENTRY sizeof(struct irdm_image_section)
#define HEADER_SIZE sizeof(struct irdm_image_header)

/* Element type each known kind must declare; PRECISION means meta's. */
#define ELEM_PRECISION 0xfffffffeu
#define ELEM_ANY 0xffffffffu

/* State of one parse. */
struct parse {
	const uint8_t *base;
	uint64_t size;
	struct irdm_image_header hdr; /* copies: the mapping may change */
	struct irdm_image_section tab[IRDM_IMAGE_MAX_SECTIONS];
	unsigned n;
	bool strict; /* our minor: reserved must be 0 */
	const struct irdm_image_section *by_kind[KIND_MAX + 1];
	struct irdm_meta meta;
	size_t es; /* bytes per element of precision */
	struct irdm_image img;
	char *err;
	size_t errlen;
};

/* image_check.c: kind and element names for messages, the reason. */
const char *img_kind_name(uint32_t kind);
uint32_t img_kind_elem(uint32_t kind); /* kind <= KIND_MAX */
const char *img_elem_name(uint32_t elem);
/* Write a one-line reason into buf (if any) and return code. */
int img_report(char *buf, size_t len, int code, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
/* The same into the parse's err buffer. */
int img_fail(struct parse *p, int code, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));

/* image_crc.c: stored == computed CRC-32C of data (computed returned). */
bool img_crc_matches(const void *data, uint64_t len, uint32_t stored,
		     uint32_t *computed);

/* The steps of a parse, in their order. */
int img_check_header(struct parse *p);
int img_check_table(struct parse *p);
int img_check_sections(struct parse *p);
int img_check_contents(struct parse *p);

/* image_rules.c: the rules the section checks share. */
const void *img_payload(const struct parse *p, uint32_t kind);
int img_check_presence(struct parse *p, uint32_t kind, bool wanted,
		       const char *why);
int img_check_shape(struct parse *p, uint32_t kind, const uint64_t *f,
		    unsigned nf, const char *formula);
/* Every element of kind's array (meta precision) finite. */
int img_check_finite(struct parse *p, uint32_t kind, uint64_t count);

/* The section checks, run by img_check_contents in this order. */
int img_check_meta(struct parse *p);
int img_check_provenance(struct parse *p);
int img_check_nodes(struct parse *p);
int img_check_columns(struct parse *p);
int img_check_surface(struct parse *p);
int img_check_stability(struct parse *p);
int img_check_rigid(struct parse *p);
int img_check_fir(struct parse *p);
int img_check_modal(struct parse *p);
/* image_static_corr.c, for img_check_modal (both sections present). */
int img_check_static_corr(struct parse *p);
/* image_corr_lowrank.c: STATIC_CORR_LOWRANK, if present, after the above. */
int img_check_corr_lowrank(struct parse *p);
/* image_corr_clusters.c: STATIC_CORR_CLUSTERS, if present, after
 * STATIC_CORR. */
int img_check_corr_clusters(struct parse *p);
/* image_exact_head.c: EXACT_HEAD against the STATIC_CORR index (checked first) */
int img_check_exact_head(struct parse *p);
/* image_col_scale.c: COLUMN_SCALE iff its flag, after COLUMNS */
int img_check_col_scale(struct parse *p);
/* image_bvh.c */
int img_check_contact_bvh(struct parse *p);

static inline bool all_zero(const void *data, size_t len)
{
	const uint8_t *b = data;

	for (size_t i = 0; i < len; i++)
		if (b[i])
			return false;
	return true;
}

static inline bool f64_finite(double d)
{
	uint64_t x;

	memcpy(&x, &d, sizeof(x));
	return (x & 0x7ff0000000000000u) != 0x7ff0000000000000u;
}

static inline bool f32_finite(float f)
{
	uint32_t x;

	memcpy(&x, &f, sizeof(x));
	return (x & 0x7f800000u) != 0x7f800000u;
}

#endif /* IRDM_IMAGE_PRIV_H */
