/* SPDX-License-Identifier: MIT */
/* A session on an image file: the core's session on this platform's mapping. */
#include <stddef.h>

#include "irdm/image.h"
#include "irdm/posix/image_map.h"
#include "irdm/posix/session.h"

int irdm_session_open(struct irdm_session **sp, const char *path,
		      const struct irdm_session_config *cfg, char *err, size_t errlen)
{
	return irdm_session_open_with(sp, path, cfg, irdm_image_map, irdm_image_unmap, err, errlen);
}
