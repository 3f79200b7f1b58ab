// SPDX-License-Identifier: MIT
/*
 * libFuzzer target: board files.  The bytes are parsed from memory (a NUL
 * ends the text there) and read as a file (where a NUL is an error with
 * its line), then a board that is accepted is mapped onto the controller's
 * arm: every accepted board must be one the device code can use.
 */
#define _GNU_SOURCE
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "irdm/board.h"
#include "irdm/device.h"
#include "irdm/error.h"
#include "irdm/posix/board_file.h"
#include "fuzz_memfile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void use(const struct irdm_board *b)
{
	struct irdm_device_config d;

	for (unsigned i = 0; i < b->devices; i++)
		if (irdm_board_device(b, i, &d) || irdm_device_config_check(&d))
			abort(); /* accepted, yet not an arm */
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct irdm_board b;
	char err[512], path[64];
	char *text = malloc(size + 1);
	int fd;

	if (!text)
		return 0;
	memcpy(text, data, size);
	text[size] = 0;
	if (!irdm_board_parse(&b, "fuzz.board", text, err, sizeof(err)))
		use(&b);
	free(text);
	fd = memfile(data, size, path, sizeof(path));
	if (fd < 0)
		return 0;
	if (!irdm_board_load(&b, path, err, sizeof(err)))
		use(&b);
	close(fd);
	return 0;
}
