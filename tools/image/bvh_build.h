/* SPDX-License-Identifier: MIT */
/*
 * Offline builder of the CONTACT_BVH section (image_format.h): a bounding
 * volume hierarchy over the contactable surface triangles (all three
 * vertices are columns), median split on the longest axis, <= 4 triangles a
 * leaf, plus the triangles' edge adjacency and the row -> column map.
 */
#ifndef IRDM_TOOLS_BVH_BUILD_H
#define IRDM_TOOLS_BVH_BUILD_H

#include <stddef.h>
#include <stdint.h>

#include "irdm/error.h"
#include "irdm/image_format.h"

/*
 * Build the payload for an image with these NODES (the float rest
 * positions the image stores: boxes bound them exactly), COLUMNS and
 * SURFACE.  *payload is malloc'd (free() it).  A one-line reason goes to err.
 * Return: IRDM_OK; IRDM_EINVAL if an index is out of range, the tree is
 * too deep or the section would exceed 4 GiB; IRDM_ENOMEM.
 */
int irdm_bvh_build(const struct irdm_node *nodes, uint32_t n_nodes,
		   const uint32_t *columns, uint32_t n_cols,
		   const uint32_t *tris, uint32_t n_tris,
		   void **payload, size_t *size, char *err, size_t errlen);

#endif /* IRDM_TOOLS_BVH_BUILD_H */
