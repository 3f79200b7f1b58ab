/* SPDX-License-Identifier: MIT */
/*
 * Checksum comparison, alone in its file on purpose: it is the seam the
 * semantic fuzzer (tests/fuzz/fuzz_image_semantic.c) replaces with one that
 * always matches.  A fuzzer almost never produces a matching CRC-32C, so
 * without that it would never get past the checksums to the code that
 * validates counts, sizes and indices.  The fuzzer's definition keeps the
 * linker from taking this file out of the library; nothing else may
 * replace it.
 */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "image_priv.h"

bool img_crc_matches(const void *data, uint64_t len, uint32_t stored,
		     uint32_t *computed)
{
	*computed = irdm_crc32c(data, (size_t)len);
	return *computed == stored;
}
