// SPDX-License-Identifier: MIT
/*
 * libFuzzer target: TetGen .node/.ele reader plus validation.  The input
 * is split at the first "\n\0\n" into node and element text (or in half
 * if there is none); both halves stay unterminated heap slices.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mesh/mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static size_t split_at(const uint8_t *data, size_t size, size_t *skip)
{
	size_t i;

	for (i = 0; i + 3 <= size; i++) {
		if (data[i] == '\n' && data[i + 1] == '\0' && data[i + 2] == '\n') {
			*skip = 3;
			return i;
		}
	}
	*skip = 0;
	return size / 2;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct irdm_mesh m;
	char err[256];
	size_t skip, cut = split_at(data, size, &skip);
	size_t ele_len = size - cut - skip;
	/* separate allocations so ASan sees a read past either end */
	char *node = malloc(cut ? cut : 1);
	char *ele = malloc(ele_len ? ele_len : 1);

	if (!node || !ele)
		goto out;
	memcpy(node, data, cut);
	memcpy(ele, data + cut + skip, ele_len);
	if (!irdm_mesh_parse_tetgen(node, cut, ele, ele_len, "fuzz", &m, err,
				    sizeof(err)) &&
	    !irdm_mesh_finish(&m, "fuzz", err, sizeof(err)))
		(void)irdm_mesh_volume(&m);
	irdm_mesh_free(&m);
out:
	free(ele);
	free(node);
	return 0;
}
