// SPDX-License-Identifier: MIT
/*
 * libFuzzer target: OBJ, OFF and STL surface readers on the same input.
 * tetgen is not run (a process per input would be far too slow).
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mesh/mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* A parsed surface must be safe to index. */
static void touch(const struct irdm_surface *s)
{
	volatile double sum = 0.0;
	size_t i;

	for (i = 0; i < 3 * s->n_tris; i++)
		sum += s->pos_m[3 * s->tris[i]];
	(void)sum;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct irdm_surface s;
	char err[256];
	char *txt = malloc(size ? size : 1);

	if (!txt)
		return 0;
	memcpy(txt, data, size);
	if (!irdm_surface_parse_obj(txt, size, "fuzz.obj", &s, err, sizeof(err)))
		touch(&s);
	irdm_surface_free(&s);
	if (!irdm_surface_parse_off(txt, size, "fuzz.off", &s, err, sizeof(err)))
		touch(&s);
	irdm_surface_free(&s);
	if (!irdm_surface_parse_stl(txt, size, "fuzz.stl", &s, err, sizeof(err)))
		touch(&s);
	irdm_surface_free(&s);
	free(txt);
	return 0;
}
