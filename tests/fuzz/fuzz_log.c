// SPDX-License-Identifier: MIT
/*
 * libFuzzer target: run logs (docs/log-format.md).  The bytes are a file;
 * the reader opens it and reads every record.  A log it accepts whole has
 * exactly the records its header says, and irdm_log_size() of them is the
 * file's size.
 */
#define _GNU_SOURCE
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <unistd.h>

#include "irdm/error.h"
#include "irdm/posix/telemetry_log.h"
#include "irdm/telemetry.h"
#include "fuzz_memfile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct irdm_log_reader *r;
	struct irdm_tick_record rec;
	char err[512], path[64];
	uint64_t n = 0;
	int fd = memfile(data, size, path, sizeof(path)), got;

	if (fd < 0)
		return 0;
	if (!irdm_log_open(&r, path, err, sizeof(err))) {
		while ((got = irdm_log_next(r, &rec, err, sizeof(err))) == 1)
			n++;
		if (got == 0 && (n != irdm_log_header(r)->record_count ||
				 irdm_log_size(n) != size))
			abort(); /* accepted whole, yet not what it says */
		irdm_log_close(r);
	}
	close(fd);
	return 0;
}
