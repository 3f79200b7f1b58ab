/* SPDX-License-Identifier: MIT */
/*
 * Validating an image in memory (image_read.c reads it after).  An image
 * comes from a file that may be truncated, corrupted or hostile, so nothing
 * in it is trusted until checked: the header and section table are copied
 * out and validated (magic, version, sizes, checksums, offsets, alignment,
 * overlap, zero padding), then every known section is checked against the
 * meta data (counts, sizes, index ranges, finiteness) before a single view
 * is handed out.  No byte outside [base, base + size) is ever read.  See
 * docs/image-format.md.
 *
 * The checks run in a fixed order and the first failure wins, so an error
 * names the most basic thing that is wrong.  Nothing here touches the
 * platform: image_map_posix.c gets the bytes.
 */
#include <stdint.h>
#include <string.h>

#include "image_priv.h"

int irdm_image_parse(const void *buf, size_t size, struct irdm_image *img,
		     char *err, size_t errlen)
{
	struct parse p = { .base = buf, .size = size, .err = err, .errlen = errlen };
	int ret;

	memset(img, 0, sizeof(*img));
	if (err && errlen)
		err[0] = '\0';
	if ((!buf && size) || (uintptr_t)buf % 8)
		return img_fail(&p, IRDM_EINVAL,
				"image buffer %p is not 8-byte aligned", buf);
	ret = img_check_header(&p);
	if (!ret)
		ret = img_check_table(&p);
	if (!ret)
		ret = img_check_sections(&p);
	if (!ret)
		ret = img_check_contents(&p);
	if (ret)
		return ret;
	*img = p.img;
	img->base = buf;
	img->size = size;
	img->meta = img_payload(&p, IRDM_SEC_META);
	return IRDM_OK;
}
