/* SPDX-License-Identifier: MIT */
/*
 * The first checks of a parse: the header and the section table.  Both are
 * copied out of the image before they are checked, so that what is checked
 * is what is used even if the mapping changes underneath.
 */
#include <stdint.h>
#include <string.h>

#include "image_priv.h"

#define HEADER_CRC_LEN offsetof(struct irdm_image_header, header_crc32c)

int img_check_header(struct parse *p)
{
	const struct irdm_image_header *h = &p->hdr;
	uint32_t crc;

	if (p->size < HEADER_SIZE)
		return img_fail(p, IRDM_ETRUNC,
				"image is truncated: file has %llu bytes, the header alone needs %zu",
				(unsigned long long)p->size, HEADER_SIZE);
	memcpy(&p->hdr, p->base, HEADER_SIZE);
	if (memcmp(h->magic, IRDM_IMAGE_MAGIC, sizeof(h->magic)))
		return img_fail(p, IRDM_EMAGIC,
				"not an IRDM image: magic bytes are %02x %02x %02x %02x %02x %02x %02x %02x, expected \"IRDMIMG\\0\"",
				h->magic[0], h->magic[1], h->magic[2], h->magic[3],
				h->magic[4], h->magic[5], h->magic[6], h->magic[7]);
	if (h->version_major != IRDM_IMAGE_VERSION_MAJOR)
		return img_fail(p, IRDM_EVERSION,
				"image format version %u.%u is not supported: this loader reads %u.x%s",
				h->version_major, h->version_minor,
				IRDM_IMAGE_VERSION_MAJOR,
				h->version_major == 1 ?
					" (1.x kept the static correction dense; re-run irdm precompute)" :
					"");
	if (h->header_size != HEADER_SIZE)
		return img_fail(p, IRDM_ERANGE,
				"header_size is %u, version 1 headers are %zu bytes",
				h->header_size, HEADER_SIZE);
	/* Checksum the copies: what is checked is exactly what was summed. */
	if (!img_crc_matches(&p->hdr, HEADER_CRC_LEN, h->header_crc32c, &crc))
		return img_fail(p, IRDM_ECRC,
				"header checksum mismatch: stored 0x%08x, computed 0x%08x",
				h->header_crc32c, crc);
	if (h->file_size > p->size)
		return img_fail(p, IRDM_ETRUNC,
				"image is truncated: header says %llu bytes, file has %llu",
				(unsigned long long)h->file_size,
				(unsigned long long)p->size);
	if (h->file_size < p->size)
		return img_fail(p, IRDM_ERANGE,
				"image has %llu trailing bytes: header says %llu bytes, file has %llu",
				(unsigned long long)(p->size - h->file_size),
				(unsigned long long)h->file_size,
				(unsigned long long)p->size);
	/* A newer minor version may give meaning to reserved fields. */
	p->strict = h->version_minor <= IRDM_IMAGE_VERSION_MINOR;
	if (p->strict && (h->flags || !all_zero(h->reserved, sizeof(h->reserved))))
		return img_fail(p, IRDM_EFORMAT,
				"header flags (0x%08x) or reserved bytes are not zero in a version %u.%u image",
				h->flags, h->version_major, h->version_minor);
	return IRDM_OK;
}

int img_check_table(struct parse *p)
{
	const struct irdm_image_header *h = &p->hdr;
	uint64_t off = h->section_table_offset;
	uint64_t len;
	uint32_t crc;

	if (h->section_count < 1 || h->section_count > IRDM_IMAGE_MAX_SECTIONS)
		return img_fail(p, IRDM_EFORMAT,
				"section_count is %u, must be 1..%u",
				h->section_count, IRDM_IMAGE_MAX_SECTIONS);
	p->n = h->section_count;
	len = (uint64_t)p->n * TABLE_ENTRY;
	if (off % IRDM_IMAGE_ALIGN || off < HEADER_SIZE)
		return img_fail(p, IRDM_ERANGE,
				"section table offset %llu is not a multiple of %u past the header",
				(unsigned long long)off, IRDM_IMAGE_ALIGN);
	if (off > p->size || len > p->size - off)
		return img_fail(p, IRDM_ERANGE,
				"section table [%llu, %llu) lies outside the %llu-byte file",
				(unsigned long long)off,
				(unsigned long long)(off + len),
				(unsigned long long)p->size);
	memcpy(p->tab, p->base + off, (size_t)len);
	if (!img_crc_matches(p->tab, len, h->table_crc32c, &crc))
		return img_fail(p, IRDM_ECRC,
				"section table checksum mismatch: stored 0x%08x, computed 0x%08x",
				h->table_crc32c, crc);
	return IRDM_OK;
}
