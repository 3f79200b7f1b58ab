// SPDX-License-Identifier: MIT
/* libFuzzer target: Gmsh .msh reader (2.2 and 4.1) plus validation. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mesh/mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct irdm_mesh m;
	char err[256];
	char *txt = malloc(size ? size : 1);

	if (!txt)
		return 0;
	memcpy(txt, data, size);
	if (!irdm_mesh_parse_gmsh(txt, size, "fuzz.msh", &m, err, sizeof(err)) &&
	    !irdm_mesh_finish(&m, "fuzz.msh", err, sizeof(err)))
		(void)irdm_mesh_hash(&m);
	irdm_mesh_free(&m);
	free(txt);
	return 0;
}
