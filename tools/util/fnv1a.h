/* SPDX-License-Identifier: MIT */
/*
 * FNV-1a, 64 bit: the fingerprint of a mesh (image provenance) and of a
 * scene (time-domain parts).  Not cryptographic: it only has to tell two
 * inputs apart that a person could mix up.
 */
#ifndef IRDM_TOOLS_FNV1A_H
#define IRDM_TOOLS_FNV1A_H

#include <stddef.h>
#include <stdint.h>

#define IRDM_FNV1A_INIT 14695981039346656037ull

/* Continue hash h over n bytes at p (start with IRDM_FNV1A_INIT). */
static inline uint64_t irdm_fnv1a(uint64_t h, const void *p, size_t n)
{
	const unsigned char *b = p;

	for (size_t i = 0; i < n; i++) {
		h ^= b[i];
		h *= 1099511628211ull;
	}
	return h;
}

#endif /* IRDM_TOOLS_FNV1A_H */
