/* SPDX-License-Identifier: MIT */
/* The report's images: scene keys in, a mapped image in a scratch file out. */
#ifndef IRDM_TOOLS_REPORT_IMAGE_H
#define IRDM_TOOLS_REPORT_IMAGE_H

#include <stddef.h>

#include "irdm/image.h"
#include "modal/modal.h"

struct irdm_report_image {
	struct irdm_image img;
	char path[512];
	size_t bytes; /* the file's size */
};

/*
 * Precompute the scene of the key strings (each "key=value ...", NULL
 * ends the list) into dir/name.img and map it.  Progress goes to fn.
 * Return: IRDM_OK; IRDM_EINVAL for a bad key string; any error of
 * irdm_precompute() or irdm_image_map().
 */
int irdm_report_image_build(struct irdm_report_image *ri, const char *dir, const char *name,
			    const char *const *keys, irdm_progress_fn fn, void *ctx,
			    char *err, size_t errlen);
/* Unmap, and remove the file unless keep. */
void irdm_report_image_drop(struct irdm_report_image *ri, int keep);

#endif
