/* SPDX-License-Identifier: MIT */
/*
 * The session's deformation worker.  Apart from the core's session.c so
 * that only a program that asks for the worker links BLAS and threads
 * (the static library pulls this object in only then); session.c frees
 * its memory with the rest and never calls into the worker.
 */
#include <stdio.h>
#include <stdlib.h>

#include "irdm/posix/deform_worker.h"
#include "irdm/posix/session.h"

int irdm_session_deform_open(struct irdm_session *s, char *err, size_t errlen)
{
	size_t n;
	int rc;

	if (!s->deform) {
		snprintf(err, errlen, "session: opened without the deformation channel");
		return IRDM_EINVAL;
	}
	if (s->worker) {
		snprintf(err, errlen, "session: the deformation worker is already open");
		return IRDM_EBUSY;
	}
	n = irdm_deform_worker_mem_size(s->img);
	rc = irdm_session_part_mem(&s->worker_mem, n, "deform worker", err, errlen);
	if (!rc)
		rc = irdm_deform_worker_init(&s->worker, s->deform, s->worker_mem, n, err, errlen);
	if (rc) {
		free(s->worker_mem);
		s->worker_mem = NULL;
	}
	return rc;
}
