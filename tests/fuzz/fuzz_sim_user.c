// SPDX-License-Identifier: MIT
/*
 * libFuzzer target: virtual user scripts, parsed from memory (a NUL ends
 * the text) and read as a file (a NUL is an error with its line).  An
 * accepted script is one whose every number is finite and whose end is
 * not before its start.
 */
#define _GNU_SOURCE
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "irdm/error.h"
#include "irdm/sim/sim_user.h"
#include "fuzz_memfile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void use(const struct irdm_sim_user *u)
{
	if (!isfinite(u->end_s) || u->end_s < 0 || u->hands > IRDM_SIM_USER_HANDS)
		abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct irdm_sim_user u;
	char err[512], path[64];
	char *text = malloc(size + 1);
	int fd;

	if (!text)
		return 0;
	memcpy(text, data, size);
	text[size] = 0;
	if (!irdm_sim_user_parse(&u, "fuzz.user", text, err, sizeof(err)))
		use(&u);
	free(text);
	fd = memfile(data, size, path, sizeof(path));
	if (fd < 0)
		return 0;
	if (!irdm_sim_user_load(&u, path, err, sizeof(err)))
		use(&u);
	close(fd);
	return 0;
}
