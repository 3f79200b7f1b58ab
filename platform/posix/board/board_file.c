/* SPDX-License-Identifier: MIT */
/*
 * A board file read from disk, line by line through the core's board
 * reader (irdm/board.h); the file access is the platform's (textfile.c).
 */
#include <stddef.h>
#include <string.h>

#include "irdm/board.h"
#include "irdm/error.h"
#include "irdm/posix/board_file.h"
#include "irdm/posix/textfile.h"

int irdm_board_load(struct irdm_board *b, const char *path, char *err, size_t errlen)
{
	char buf[IRDM_BOARD_LINE_MAX];
	struct irdm_text_file t;
	struct irdm_opt_file f;
	int ret;

	irdm_board_read_begin(&f, b, path);
	ret = irdm_text_open(&t, path, IRDM_TEXT_MAX_BYTES, err, errlen);
	if (ret)
		return ret;
	while ((ret = irdm_text_line(&t, buf, IRDM_BOARD_LINE_MAX, err, errlen)) > 0) {
		ret = irdm_board_read_line(&f, buf, strlen(buf), err, errlen);
		if (ret)
			break;
	}
	irdm_text_close(&t);
	if (!ret)
		ret = irdm_board_finish(b, &f, err, errlen);
	return ret;
}
