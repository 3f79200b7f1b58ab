/* SPDX-License-Identifier: MIT */
/*
 * A session (irdm/session.h) on an image file, and its deformation worker:
 * the parts of a session that need the platform (the image's mapping;
 * BLAS and a thread).
 */
#ifndef IRDM_POSIX_SESSION_H
#define IRDM_POSIX_SESSION_H

#include <stddef.h>

#include "irdm/session.h"

/*
 * Map and validate the image at path, then set up as
 * irdm_session_open_image() does.  The session unmaps it on close.
 *
 * Return: IRDM_OK;
 * any error of irdm_image_map() (IRDM_EIO, IRDM_ETRUNC, IRDM_EMAGIC,
 * IRDM_EVERSION, IRDM_ECRC, IRDM_ERANGE, IRDM_EMISSING, IRDM_EFORMAT);
 * otherwise as irdm_session_open_image().
 * On error *s is NULL, nothing is left mapped or allocated, and err says why.
 */
int irdm_session_open(struct irdm_session **s, const char *path,
		      const struct irdm_session_config *cfg, char *err, size_t errlen);

/*
 * The deformation worker (irdm/posix/deform_worker.h) on the session's channel,
 * in memory the session frees on close.  Its own object file: calling it
 * links BLAS and threads.  A deformation thread started on s->worker must
 * be stopped before irdm_session_close().
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if the session has no deformation channel (config.deform was
 * false) or its image is not one the update can read;
 * IRDM_EBUSY if the session already has a worker;
 * IRDM_ENOMEM if the allocation failed.
 */
int irdm_session_deform_open(struct irdm_session *s, char *err, size_t errlen);

#endif /* IRDM_POSIX_SESSION_H */
