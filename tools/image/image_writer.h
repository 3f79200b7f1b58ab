/* SPDX-License-Identifier: MIT */
/*
 * Image writer: collect sections, then write header + table + aligned
 * payloads with checksums to a temporary file beside the target, fsync it
 * and rename it into place.  On any failure the temporary file is removed
 * and the target is left untouched: no half-written image, ever.
 */
#ifndef IRDM_TOOLS_IMAGE_WRITER_H
#define IRDM_TOOLS_IMAGE_WRITER_H

#include <stddef.h>
#include <stdint.h>

#include "irdm/error.h"
#include "irdm/image_format.h"

struct irdm_image_writer {
	unsigned n;
	struct {
		uint32_t kind;
		uint32_t elem;
		const void *data; /* borrowed until irdm_iw_write() returns */
		uint64_t size;
	} sec[IRDM_IMAGE_MAX_SECTIONS];
};

void irdm_iw_init(struct irdm_image_writer *w);
/* Return: IRDM_OK; IRDM_EINVAL if the table is full, kind repeats, elem is
 * unknown or size bytes have no data. */
int irdm_iw_add(struct irdm_image_writer *w, uint32_t kind, uint32_t elem,
		const void *data, uint64_t size);
/* Return: IRDM_OK; IRDM_EINVAL if there are no sections; IRDM_ENOMEM;
 * IRDM_EIO if the file cannot be created, written, synced or renamed.  A
 * one-line reason naming path goes to err. */
int irdm_iw_write(const struct irdm_image_writer *w, const char *path,
		  char *err, size_t errlen);
/* Same layout into a malloc'd buffer (tests, fuzz seeds).
 * Return: IRDM_OK; IRDM_EINVAL if there are no sections; IRDM_ENOMEM. */
int irdm_iw_to_buffer(const struct irdm_image_writer *w, void **buf, size_t *size);

#endif /* IRDM_TOOLS_IMAGE_WRITER_H */
