/* SPDX-License-Identifier: MIT */
/* Board files read from disk (the parser: irdm/board.h). */
#ifndef IRDM_POSIX_BOARD_FILE_H
#define IRDM_POSIX_BOARD_FILE_H

#include <stddef.h>

#include "irdm/board.h"

/*
 * The same from a file (messages name it by path).
 * Return: as irdm_board_parse(); IRDM_EIO if the file cannot be read.
 */
int irdm_board_load(struct irdm_board *b, const char *path, char *err, size_t errlen);

#endif /* IRDM_POSIX_BOARD_FILE_H */
