/* SPDX-License-Identifier: MIT */
/* An image file brought into memory and parsed (the parser: irdm/image.h). */
#ifndef IRDM_POSIX_IMAGE_MAP_H
#define IRDM_POSIX_IMAGE_MAP_H

#include <stddef.h>

#include "irdm/image.h"

/*
 * Copy the image at path into private memory, read-only, and validate it.
 * A copy, not a mapping of the file: the bytes a running loop reads cannot
 * change or vanish when the file is truncated or replaced.  Populates the
 * copy (no page fault later) and, with IRDM_IMAGE_MAP_LOCK, locks it.  On failure img is zeroed,
 * nothing stays mapped, and err holds "path: reason" on one line.
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if flags has a bit other than IRDM_IMAGE_MAP_LOCK;
 * IRDM_EIO if the file cannot be opened, stat'ed, read, copied or locked, is
 * not a regular file, is too large to map or grew while it was read;
 * IRDM_ETRUNC if it is shorter than an image header or shrank while read;
 * otherwise any error of irdm_image_parse().
 */
int irdm_image_map(const char *path, unsigned flags, struct irdm_image *img,
		   char *err, size_t errlen);

/* Unmap an image from irdm_image_map() (no-op for irdm_image_parse's) and
 * zero img.  Cannot fail. */
void irdm_image_unmap(struct irdm_image *img);

#endif /* IRDM_POSIX_IMAGE_MAP_H */
