/* SPDX-License-Identifier: MIT */
/*
 * An image's force error at every touchable column, not a sample: the
 * measurement's two runs (measure.h) at each column, the image run by
 * the force engine on its stored values, the exact model's forces by
 * direct convolution in double of the column's exact response to itself,
 * summed from every elastic mode (col_resp.h).  A contact at one column
 * reads only that column's own block, so the exact model needs no other.
 * For a grounded object whose every elastic mode was solved.
 */
#ifndef IRDM_TOOLS_ACCURACY_SCAN_H
#define IRDM_TOOLS_ACCURACY_SCAN_H

#include <stddef.h>
#include <stdint.h>

#include "irdm/error.h"
#include "irdm/image.h"
#include "modal/modal.h"

struct irdm_scan {
	size_t n_cols;         /* columns measured: every one */
	double worst;          /* the largest error ... */
	uint32_t worst_node;   /* ... at this mesh node */
	const char *worst_run; /* "step" or "release" */
	double median, p90;    /* of the columns' errors (each the larger run's) */
	size_t ticks;          /* of each run */
	double seconds;
};

/*
 * Scan img against m (every elastic mode, zoh: them discretised), whose
 * columns are img's: col_dofs (3 free DoFs or -1 each) and mesh_nodes of
 * n_cols columns, in img's order.
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_EINVAL if the columns are not img's
 * or img is of a floating object; the engine's errors.  A one-line reason
 * goes to err.
 */
int irdm_scan_every_column(const struct irdm_image *img, const struct irdm_modes *m,
			   const struct irdm_mode *zoh, const int64_t *col_dofs,
			   const uint32_t *mesh_nodes, size_t n_cols,
			   irdm_progress_fn fn, void *ctx, struct irdm_scan *res, char *err,
			   size_t errlen);

#endif
