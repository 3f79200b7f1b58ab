/* SPDX-License-Identifier: MIT */
/* Internals of the session (firmware/session/). */
#ifndef IRDM_SESSION_PRIV_H
#define IRDM_SESSION_PRIV_H

#include "irdm/session.h"

/*
 * Memory for one part of the session: *mem = n bytes, cache-line aligned
 * (the engine wants 16; 64 keeps a part's hot data off its neighbour's
 * lines).  n == 0 means the part's size call refused the image or the
 * configuration: nothing is allocated and IRDM_OK returned, so that the
 * part's init, given no memory, says why.
 *
 * Return: IRDM_OK; IRDM_ENOMEM (err says which part) if allocation failed.
 */
int session_part_mem(void **mem, size_t n, const char *part, char *err, size_t errlen);

#endif
