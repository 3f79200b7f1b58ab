/* SPDX-License-Identifier: MIT */
/* Reading responses back out of a mapped image (FIR or modal alike). */
#ifndef IRDM_TOOLS_IMAGE_RESPONSE_H
#define IRDM_TOOLS_IMAGE_RESPONSE_H

#include <stddef.h>
#include <stdint.h>

#include "irdm/error.h"
#include "irdm/image.h"

/* Image node index of a mesh node, or -1. */
int64_t irdm_image_node_of(const struct irdm_image *img, uint32_t mesh_node);
/* Column index of an image node, or -1 if it is not touchable. */
int64_t irdm_image_col_of(const struct irdm_image *img, uint32_t image_node);

/*
 * R[s] for s < n_samples, column col, image row `row`: out[9 * s + 3 i + j]
 * (i: displacement axis at the row, j: force axis at the column).  FIR
 * images give zeros past T.  Return: IRDM_OK; IRDM_ENOMEM.
 */
int irdm_image_response(const struct irdm_image *img, uint32_t col, uint32_t row,
			size_t n_samples, double *out);

#endif
