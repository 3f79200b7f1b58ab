// SPDX-License-Identifier: MIT
/*
 * libFuzzer target: scene files, read as a file (a NUL or a key twice is
 * an error with its line), then checked as a whole.  No mesh is built: the
 * reader and the checks are what takes outside text.
 */
#define _GNU_SOURCE
#include <stddef.h>
#include <stdint.h>
#include <unistd.h>

#include "irdm/error.h"
#include "scene/scene.h"
#include "fuzz_memfile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct irdm_scene sc;
	char err[512], path[64];
	int fd = memfile(data, size, path, sizeof(path));

	if (fd < 0)
		return 0;
	irdm_scene_defaults(&sc);
	if (!irdm_scene_load(&sc, path, err, sizeof(err)))
		(void)irdm_scene_check(&sc, err, sizeof(err));
	close(fd);
	return 0;
}
