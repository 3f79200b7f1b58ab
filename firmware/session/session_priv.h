/* SPDX-License-Identifier: MIT */
/* Internals of the session (firmware/session/). */
#ifndef IRDM_SESSION_PRIV_H
#define IRDM_SESSION_PRIV_H

#include <stdlib.h>

#include "irdm/session.h"

#define SESSION_ALIGN 64u

/*
 * Cache-line aligned memory for one part (the engine wants 16 bytes; 64
 * keeps a part's hot data off its neighbour's lines).  NULL for n == 0.
 */
static inline void *session_alloc(size_t n)
{
	return n ? aligned_alloc(SESSION_ALIGN, (n + SESSION_ALIGN - 1) &
						~(size_t)(SESSION_ALIGN - 1)) : NULL;
}

#endif
